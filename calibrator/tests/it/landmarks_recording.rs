//! The landmark calibrator on simulated recordings, from the raw scans: the detector
//! finds the cylinders and nothing else, the landmarks land where they are, and the calibration
//! recovers the configured range model.

use std::sync::OnceLock;

use hilsim_calibrator::landmarks::regression::horner;
use hilsim_calibrator::landmarks::{analyse, Analysis, Nominal, Options};
use hilsim_fixtures::landmark_study::PAPER_ALPHA;
use hilsim_recording::Pose;
use hilsim_recording::Recording;
use hilsim_sim::Scenario;

const LANDMARKS_5: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/landmarks-5.toml");

fn scenario() -> &'static Scenario {
    static S: OnceLock<Scenario> = OnceLock::new();
    S.get_or_init(|| Scenario::load(LANDMARKS_5.as_ref()).expect("landmarks-5.toml loads"))
}

/// The landmarks-5 run at the scenario's own seed, emulated once per test binary.
fn recording() -> &'static Recording {
    static R: OnceLock<Recording> = OnceLock::new();
    R.get_or_init(|| {
        let s = scenario();
        hilsim_lidar_emulator::Emulation::new(s, s.seed)
            .expect("sensors build")
            .run()
            .recording
    })
}

fn analysis() -> &'static Analysis {
    static A: OnceLock<Analysis> = OnceLock::new();
    A.get_or_init(|| analyse(recording(), &Options::default()).expect("calibrates"))
}

/// The scenario's cylinders in the frame of the robot's start pose.
fn true_landmarks() -> Vec<[f64; 2]> {
    let s = scenario();
    let start = Pose::new(
        s.robot.start.x,
        s.robot.start.y,
        s.robot.start.yaw_deg.to_radians(),
    );
    s.world
        .cylinders
        .iter()
        .map(|c| start.inverse_transform(c.center))
        .collect()
}

/// The true pose of the lidar during a stop, start-pose frame (the mount is at the robot's
/// centre in landmarks-5).
fn true_pose(rec: &Recording, t0: f64) -> Pose {
    let truth = rec.truth.as_ref().expect("the emulator records truth");
    let first = Pose::new(truth[0].x_m, truth[0].y_m, truth[0].yaw_rad);
    let t = truth
        .iter()
        .find(|t| t.t_s >= t0)
        .expect("truth covers the stop");
    Pose::new(t.x_m, t.y_m, t.yaw_rad).relative_to(&first)
}

#[test]
fn detects_exactly_the_five_cylinders_and_no_wall() {
    let a = analysis();
    let rec = recording();
    let cylinders = true_landmarks();
    let alpha = &scenario().sensors.lidar.as_ref().expect("a lidar").bias;
    // Eleven stops: the start and ten 0.3 m moves.
    assert_eq!(a.stops.len(), 11);
    for d in &a.detections {
        let p = true_pose(rec, a.stops[d.stop].t_start_s);
        // The nearest cylinder by bearing.
        let (err, dist) = cylinders
            .iter()
            .map(|c| {
                let (dx, dy) = (c[0] - p.x, c[1] - p.y);
                let b = hilsim_recording::wrap_angle(dy.atan2(dx) - p.yaw - d.bearing_rad);
                (b.abs(), dx.hypot(dy) - a.radius_m)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .expect("five cylinders");
        // Bearings: 0.16° rms over this run, up to ~1.5° when the edges are unclear and the
        // circle fit measures it; a wall segment's centre lies at least the cylinder's
        // half-width plus its own away from any cylinder centre, well beyond 2°.
        assert!(err.to_degrees() < 2.0, "detection {d:?} is {err} rad off");
        // Range: r̃ estimates the mean reading at the true distance, f(d), to within its standard
        // error σ(d)/√n = 0.05 f(d)/√n (β = 0.05 α) — 5 of them — plus 1 cm for the beam jitter
        // (0.5°), which lengthens the true ranges of the central beams by up to ~6 mm at 4.2 m.
        let mean = horner(alpha, dist);
        let tol = 5.0 * 0.05 * mean / (d.count as f64).sqrt() + 0.01;
        assert!(
            (d.range_m - mean).abs() < tol,
            "range {} vs mean reading {mean} at {dist} m (tol {tol})",
            d.range_m
        );
    }
    // Every cylinder is within 5 m of every stop and unoccluded most of the time: seen at
    // nearly every stop, in one track each.
    assert!(
        a.detections.len() >= 50,
        "{} detections",
        a.detections.len()
    );
    assert_eq!(a.tracks.len(), 5);
    assert_eq!(a.calibration.landmarks.as_ref().map(Vec::len), Some(5));
    let walls = a.rejected.too_long + a.rejected.straight + a.rejected.occluded;
    assert!(
        walls > 0,
        "the walls were seen and rejected: {:?}",
        a.rejected
    );
}

#[test]
fn landmark_positions_match_the_truth() {
    let a = analysis();
    let joint = a
        .estimate
        .refined
        .as_ref()
        .and_then(|r| r.joint.as_ref())
        .expect("the joint refinement ran");
    let estimated = a.calibration.landmarks.as_ref().expect("landmarks");
    for (p, cov) in estimated.iter().zip(&joint.landmark_cov) {
        let (err, c) = true_landmarks()
            .into_iter()
            .map(|c| ((p[0] - c[0]).hypot(p[1] - c[1]), c))
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .expect("five cylinders");
        // Random error: the joint solution's covariance, whose largest standard deviation is
        // 1.5–6 mm here; 5 of them. Systematic: the bearings' residual quantisation and the
        // range's depth correction add at most ~5 mm.
        let tr = cov[0][0] + cov[1][1];
        let det = cov[0][0] * cov[1][1] - cov[0][1] * cov[1][0];
        let lmax = tr / 2.0 + (tr * tr / 4.0 - det).max(0.0).sqrt();
        let tol = 5.0 * lmax.sqrt() + 0.005;
        assert!(
            err < tol,
            "landmark {p:?} is {err} m from {c:?} (tol {tol})"
        );
    }
}

#[test]
fn calibration_recovers_the_configured_model() {
    let a = analysis();
    let cal = &a.calibration;
    let m = cal.metrics.expect("truth is known");
    // The raw readings' MSE is the bias's (f(4) − 4 = 0.52 m at the far landmark); the
    // calibrated one is the averaged readings' own noise. The paper's field test gained ×10.
    assert!(m.mse_ratio() > 10.0, "MSE ratio {}", m.mse_ratio());
    assert!(m.mse_raw.is_finite() && m.nmse_calibrated.is_finite());
    assert_eq!(cal.order, Some(2));
    assert!(cal.converged && cal.iterations >= 1);
    let model = &cal.sensors.values().next().expect("the lidar").alpha;
    // Over the distances observed, the fitted mean reading must match the configured one to
    // within the fit's uncertainty: ~54 averaged ranges with standard errors 0.7–7 cm pooled by
    // a three-parameter fit leave 1–2 cm at the ends of the range; 5 cm is ≥ 2.5 of them, and a
    // tenth of the raw bias at the far end.
    let est = a.estimate.refined.as_ref().expect("refined");
    let lo = est.distances.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = est.distances.iter().copied().fold(0.0, f64::max);
    for i in 0..=20 {
        let d = lo + (hi - lo) * f64::from(i) / 20.0;
        let err = horner(model, d) - horner(&PAPER_ALPHA, d);
        assert!(err.abs() < 0.05, "f̂({d:.2}) − f = {err:.3} ({model:?})");
    }
    let beta = &cal.sensors.values().next().expect("the lidar").beta;
    assert!(beta.iter().all(|b| b.is_finite() && *b >= 0.0));
    // β = 0.05 α: σ(2 m) = 0.1009 m. The stops' own scatter (~1,500 readings) pins it to ~5 %.
    let s2 = horner(beta, 2.0);
    assert!((s2 - 0.1009).abs() < 0.02, "σ(2 m) = {s2}");
    let json = cal.to_json();
    assert_eq!(json["order"], 2);
    assert_eq!(json["landmarks"].as_array().map(Vec::len), Some(5));
    assert_eq!(json["method"], "landmarks");
}

#[test]
fn notes_report_both_order_selections_and_both_estimators() {
    let notes = &analysis().calibration.notes;
    let has = |s: &str| notes.iter().any(|n| n.contains(s));
    assert!(has("AIC picks order"), "{notes:#?}");
    assert!(has("cross-validation picks"), "{notes:#?}");
    assert!(has("MSE ratio (eq. 31): paper estimator"), "{notes:#?}");
    assert!(!has("warning"), "{notes:#?}");
}

#[test]
fn unknown_radius_is_estimated() {
    let mut rec = recording().clone();
    rec.meta.world.landmark_radius_m = None;
    let a = analyse(&rec, &Options::default()).expect("calibrates");
    // Free circle fits in raw reading space: the local slope f′ ≈ 0.9–1.2 distorts the arcs, and
    // 1–2 cm of averaged range noise moves each fit; the median of dozens is within 2 cm.
    assert!((a.radius_m - 0.12).abs() < 0.02, "radius {}", a.radius_m);
    assert_eq!(a.tracks.len(), 5);
    assert!(a.calibration.metrics.expect("truth").mse_ratio() > 10.0);
}

#[test]
fn odometry_can_give_the_nominal_stops() {
    let mut opts = Options::default();
    opts.stops.nominal = Nominal::Odometry;
    let a = analyse(recording(), &opts).expect("calibrates");
    // The encoders are noisy (2 mm) but unbiased here (no slip): the stops move by ~1 mm.
    for (s, t) in a
        .stops
        .iter()
        .zip(a.stops.iter().map(|s| true_pose(recording(), s.t_start_s)))
    {
        assert!(
            (s.pose.x - t.x).hypot(s.pose.y - t.y) < 0.005,
            "{:?} vs {t:?}",
            s.pose
        );
    }
    assert_eq!(a.tracks.len(), 5);
    assert!(a.calibration.metrics.expect("truth").mse_ratio() > 10.0);
}

const CLUTTER: &str = r#"
name = "clutter"
description = "three landmarks among walls, a board, a pole and a column"
[world]
cylinders = [
    { center = [1.2, 1.0], radius = 0.12 },
    { center = [2.2, -1.2], radius = 0.12 },
    { center = [0.4, -1.4], radius = 0.12 },
    { center = [2.0, 1.3], radius = 0.03 },
    { center = [-0.6, 1.2], radius = 0.35 },
]
boards = [{ center = [3.2, 0.9], length = 0.6, yaw_deg = 60.0 }]
walls = [
    { from = [-1.5, -2.5], to = [4.5, -2.5] },
    { from = [4.5, -2.5], to = [4.5, 2.5] },
    { from = [4.5, 2.5], to = [-1.5, 2.5] },
    { from = [-1.5, 2.5], to = [-1.5, -2.5] },
    { from = [3.0, -1.0], to = [3.6, -1.6] },
]
[robot]
start = { x = 0.0, y = 0.0 }
wheel_base_m = 0.23
[[drive]]
stop_s = 1.5
[[drive]]
speed_mps = 0.1
distance_m = 0.3
[[drive]]
stop_s = 1.5
[[drive]]
speed_mps = 0.1
distance_m = 0.3
[[drive]]
stop_s = 1.5
[[drive]]
speed_mps = 0.1
distance_m = 0.3
[[drive]]
stop_s = 1.5
[[drive]]
speed_mps = 0.1
distance_m = 0.3
[[drive]]
stop_s = 1.5
[sensors.lidar]
bias = [0.0525, 0.8838, 0.0584]
noise = [0.002625, 0.04419, 0.00292]
angle_noise_deg = 0.5
"#;

#[test]
fn walls_boards_poles_and_columns_are_not_landmarks() {
    let scenario = Scenario::from_toml(CLUTTER, "clutter.toml".as_ref()).expect("parses");
    let mut rec = hilsim_lidar_emulator::Emulation::new(&scenario, 1)
        .expect("sensors build")
        .run()
        .recording;
    // Several radii: the emulator leaves the radius out of meta.toml; the landmarks' is known.
    assert_eq!(rec.meta.world.landmark_radius_m, None);
    rec.meta.world.landmark_radius_m = Some(0.12);
    let a = analyse(&rec, &Options::default()).expect("calibrates");
    let landmarks = &scenario.world.cylinders[..3];
    for d in &a.detections {
        let p = true_pose(&rec, a.stops[d.stop].t_start_s);
        let near = landmarks.iter().any(|c| {
            let b = (c.center[1] - p.y).atan2(c.center[0] - p.x);
            hilsim_recording::wrap_angle(b - d.bearing_rad).abs() < 2f64.to_radians()
        });
        assert!(
            near,
            "a detection at {:.1}° is no landmark",
            d.bearing_rad.to_degrees()
        );
    }
    // Five stops × three landmarks, nothing else.
    assert_eq!(a.detections.len(), 15);
    assert_eq!(a.tracks.len(), 3);
    assert!(a.rejected.too_long > 0 && a.rejected.occluded > 0);
}
