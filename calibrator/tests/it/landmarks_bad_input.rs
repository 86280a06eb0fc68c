//! Bad input to the landmark calibrator gives a clear error or a named warning, never
//! a NaN: too few stops, no landmark, a landmark seen from one stop, colinear bearings, missing
//! or disordered data, nonsense options.

use hilsim_calibrator::landmarks::regression::horner;
use hilsim_calibrator::landmarks::{calibrate, Options};
use hilsim_calibrator::{Calibration, CalibrationError};
use hilsim_fixtures::landmark_study::PAPER_ALPHA;
use hilsim_recording::{CommandSample, LidarSample, Meta, Mount, Recording};

/// A cylinder of radius 0.12 m, visible only during the stops listed (all when `None`).
struct Cylinder {
    centre: [f64; 2],
    only_at: Option<Vec<usize>>,
}

fn cyl(x: f64, y: f64) -> Cylinder {
    Cylinder {
        centre: [x, y],
        only_at: None,
    }
}

const RADIUS: f64 = 0.12;
const STOP_S: f64 = 2.0;
const MOVE_S: f64 = 3.0;
const SPEED: f64 = 0.1;

/// A noise-free synthetic recording: `stops` stand-still stops 0.3 m apart along x (2 s each,
/// five 360-reading revolutions per second, the paper's mean reading f(d)), moves between them.
fn synthetic(stops: usize, cylinders: &[Cylinder]) -> Recording {
    let mut meta = Meta {
        lidar: Some(Mount {
            x_m: 0.0,
            y_m: 0.0,
            yaw_deg: 0.0,
        }),
        ..Meta::default()
    };
    meta.world.landmark_radius_m = Some(RADIUS);
    let mut rec = Recording::new(meta);
    let mut lidar = Vec::new();
    let mut t = 0.0;
    let mut rev = 0;
    for k in 0..stops {
        rec.commands.push(CommandSample {
            t_s: t,
            left_mps: 0.0,
            right_mps: 0.0,
        });
        let x = SPEED * MOVE_S * k as f64;
        for r in 0..(STOP_S * 5.0) as u64 {
            for a in 0..360u16 {
                let t_s = t + (r as f64 * 360.0 + f64::from(a)) / 1800.0;
                let beam = f64::from(a).to_radians();
                let hit = cylinders
                    .iter()
                    .filter(|c| c.only_at.as_ref().is_none_or(|v| v.contains(&k)))
                    .filter_map(|c| ray_circle([x, 0.0], beam, c.centre, RADIUS))
                    .fold(f64::INFINITY, f64::min);
                let valid = hit.is_finite();
                lidar.push(LidarSample {
                    t_s,
                    rev,
                    angle_deg: f64::from(a),
                    range_m: if valid {
                        (horner(&PAPER_ALPHA, hit) * 1000.0).round() / 1000.0
                    } else {
                        0.0
                    },
                    strength: if valid { 300 } else { 0 },
                    invalid: !valid,
                    warning: false,
                    true_range_m: None,
                });
            }
            rev += 1;
        }
        t += STOP_S;
        if k + 1 < stops {
            rec.commands.push(CommandSample {
                t_s: t,
                left_mps: SPEED,
                right_mps: SPEED,
            });
            t += MOVE_S;
        }
    }
    rec.lidar = Some(lidar);
    rec
}

/// Distance along the ray from `p` at angle `a` to the circle, when it hits.
fn ray_circle(p: [f64; 2], a: f64, c: [f64; 2], r: f64) -> Option<f64> {
    let (ux, uy) = (a.cos(), a.sin());
    let (dx, dy) = (c[0] - p[0], c[1] - p[1]);
    let along = ux * dx + uy * dy;
    let perp2 = dx * dx + dy * dy - along * along;
    (perp2 <= r * r && along > 0.0).then(|| along - (r * r - perp2).sqrt())
}

fn assert_finite(cal: &Calibration) {
    for m in cal.sensors.values() {
        assert!(
            m.alpha.iter().chain(&m.beta).all(|v| v.is_finite()),
            "{m:?}"
        );
    }
    for p in cal.landmarks.iter().flatten() {
        assert!(p[0].is_finite() && p[1].is_finite());
    }
    assert!(!cal.to_json().to_string().contains("null"));
}

fn good_world() -> Vec<Cylinder> {
    vec![cyl(1.0, 1.2), cyl(2.0, -1.1), cyl(0.3, -1.4)]
}

#[test]
fn the_synthetic_world_calibrates() {
    let cal = calibrate(&synthetic(6, &good_world()), &Options::default()).expect("calibrates");
    assert_eq!(cal.landmarks.as_ref().map(Vec::len), Some(3));
    assert_finite(&cal);
}

#[test]
fn fewer_than_two_stops() {
    // Moving from the start to the end: no stop at all.
    let mut rec = synthetic(3, &good_world());
    rec.commands = vec![CommandSample {
        t_s: 0.0,
        left_mps: SPEED,
        right_mps: SPEED,
    }];
    let err = calibrate(&rec, &Options::default()).expect_err("no stops");
    assert!(
        matches!(&err, CalibrationError::TooFewSamples(m) if m.contains("found 0 stand-still stop")),
        "{err}"
    );
    // One stop, then motion to the end.
    rec.commands = vec![
        CommandSample {
            t_s: 0.0,
            left_mps: 0.0,
            right_mps: 0.0,
        },
        CommandSample {
            t_s: STOP_S,
            left_mps: SPEED,
            right_mps: SPEED,
        },
    ];
    let err = calibrate(&rec, &Options::default()).expect_err("one stop");
    assert!(
        matches!(&err, CalibrationError::TooFewSamples(m) if m.contains("found 1 stand-still stop")),
        "{err}"
    );
}

#[test]
fn no_landmark_detected() {
    let err = calibrate(&synthetic(4, &[]), &Options::default()).expect_err("nothing to see");
    assert!(
        matches!(&err, CalibrationError::TooFewSamples(m) if m.contains("no landmark")),
        "{err}"
    );
}

#[test]
fn a_landmark_seen_from_one_stop_only() {
    let lonely = || Cylinder {
        centre: [1.5, 1.5],
        only_at: Some(vec![2]),
    };
    // Alone: an error.
    let err = calibrate(&synthetic(5, &[lonely()]), &Options::default()).expect_err("one stop");
    assert!(
        matches!(&err, CalibrationError::TooFewSamples(m) if m.contains("fewer than 2 stops")),
        "{err}"
    );
    // Among others: dropped, with a named warning.
    let mut world = good_world();
    world.push(lonely());
    let cal = calibrate(&synthetic(5, &world), &Options::default()).expect("calibrates");
    assert_eq!(cal.landmarks.as_ref().map(Vec::len), Some(3));
    assert!(
        cal.notes
            .iter()
            .any(|n| n.starts_with("warning: landmark near") && n.contains("1 stop(s) only")),
        "{:#?}",
        cal.notes
    );
    assert_finite(&cal);
}

#[test]
fn colinear_bearings() {
    // A cylinder straight ahead on the path is seen under the same bearing from every stop.
    let ahead = || cyl(3.5, 0.0);
    let err = calibrate(&synthetic(5, &[ahead()]), &Options::default()).expect_err("colinear");
    assert!(
        matches!(&err, CalibrationError::Unidentifiable(m) if m.contains("colinear")),
        "{err}"
    );
    let mut world = good_world();
    world.push(ahead());
    let cal = calibrate(&synthetic(5, &world), &Options::default()).expect("calibrates");
    assert_eq!(cal.landmarks.as_ref().map(Vec::len), Some(3));
    assert!(
        cal.notes
            .iter()
            .any(|n| n.starts_with("warning: landmark") && n.contains("colinear")),
        "{:#?}",
        cal.notes
    );
    assert_finite(&cal);
}

#[test]
fn missing_or_disordered_data() {
    let mut rec = synthetic(3, &good_world());
    rec.lidar = None;
    assert!(matches!(
        calibrate(&rec, &Options::default()),
        Err(CalibrationError::Missing(_))
    ));
    let mut rec = synthetic(3, &good_world());
    rec.lidar.as_mut().expect("lidar").swap(10, 2000);
    assert!(matches!(
        calibrate(&rec, &Options::default()),
        Err(CalibrationError::Invalid(m)) if m.contains("back in time")
    ));
    let mut rec = synthetic(3, &good_world());
    rec.commands.clear();
    rec.odometry = None;
    assert!(matches!(
        calibrate(&rec, &Options::default()),
        Err(CalibrationError::Missing(m)) if m.contains("neither")
    ));
}

#[test]
fn nonsense_options() {
    let rec = synthetic(3, &good_world());
    for opts in [
        Options {
            landmark_radius_m: Some(f64::NAN),
            ..Options::default()
        },
        Options {
            max_order: 12,
            ..Options::default()
        },
        Options {
            sigma_s_m: Some(-1.0),
            ..Options::default()
        },
    ] {
        assert!(
            matches!(calibrate(&rec, &opts), Err(CalibrationError::Invalid(_))),
            "{opts:?}"
        );
    }
}
