//! The odometry method's estimator on tuples made here from a known robot (a Khepera-sized
//! one, as in Censi et al. 2013): it recovers the geometry, its covariance is honest, and drives
//! that do not inform a parameter are refused or fail a check.

use hilsim_calibrator::odometry::{calibrate_tuples, parse_tuples, Geometry, Tuple};
use hilsim_calibrator::CalibrationError;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use rand_xoshiro::Xoshiro256PlusPlus;

/// The paper's configuration A, about: radii 20.9 mm, axle 89 mm, the lidar 6 mm behind the
/// axle turned by 10 mrad.
const TRUTH: Geometry = Geometry {
    left_radius_m: 0.020_86,
    right_radius_m: 0.020_92,
    wheel_base_m: 0.089,
    lidar: [-0.0058, 0.0002, 0.0095],
};

/// The scan matcher's error: about the paper's data's (sd 0.75 mm, 0.5 mm, 1.8 mrad).
const NOISE: [f64; 3] = [0.0008, 0.0005, 0.0018];

/// A drive of `n` intervals of 0.8 s: straight runs and turns in place both ways, the wheels'
/// speeds drawn around each kind's; the lidar's motion the truth's plus noise.
fn drive(n: usize, seed: u64, turns: &[f64]) -> Vec<Tuple> {
    drive_of(&TRUTH, n, seed, turns)
}

/// [`drive`] of another robot.
fn drive_of(truth: &Geometry, n: usize, seed: u64, turns: &[f64]) -> Vec<Tuple> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let noise: Vec<Normal<f64>> = NOISE
        .iter()
        .map(|&s| Normal::new(0.0, s).unwrap())
        .collect();
    (0..n)
        .map(|k| {
            let turn = turns[k % turns.len()];
            let forward = if turn == 0.0 { 0.5 } else { 0.0 };
            let left = forward - turn + rng.random_range(-0.02..0.02);
            let right = forward + turn + rng.random_range(-0.02..0.02);
            let duration_s = 0.8;
            let robot = truth.robot_motion(&[[left * duration_s, right * duration_s]]);
            let s = truth.lidar_motion(robot);
            Tuple {
                duration_s,
                left_rad_s: left,
                right_rad_s: right,
                lidar_motion: std::array::from_fn(|i| s[i] + noise[i].sample(&mut rng)),
            }
        })
        .collect()
}

const BOTH_WAYS: [f64; 4] = [0.0, 1.5, 0.0, -1.5];

#[test]
fn noiseless_tuples_give_the_geometry_back() {
    let tuples: Vec<Tuple> = drive(200, 1, &BOTH_WAYS)
        .into_iter()
        .map(|mut t| {
            let r = TRUTH.robot_motion(&[[t.left_rad_s * 0.8, t.right_rad_s * 0.8]]);
            t.lidar_motion = TRUTH.lidar_motion(r);
            // A trace of noise keeps the residuals' covariance invertible.
            t.lidar_motion[0] += 1e-9 * (t.left_rad_s * 1e3).sin();
            t.lidar_motion[1] += 1e-9 * (t.right_rad_s * 1e3).cos();
            t.lidar_motion[2] += 1e-9 * (t.left_rad_s * 7e2).sin();
            t
        })
        .collect();
    let model = calibrate_tuples(&tuples, 0).unwrap().odometry.unwrap();
    let truth = TRUTH.to_array();
    for (i, v) in model.parameters().iter().enumerate() {
        assert!(
            (v - truth[i]).abs() < 1e-6,
            "parameter {i}: {v} against {}",
            truth[i]
        );
    }
}

/// Over 50 seeded drives each parameter's error is within two of its stated standard
/// deviations in at least 43 of them: with a true 95 %, fewer than 43 of 50 happens with
/// probability about 0.01 per parameter.
#[test]
fn the_stated_covariance_covers_the_error() {
    let truth = TRUTH.to_array();
    let mut within = [0usize; 6];
    let runs = 50;
    for seed in 0..runs {
        let cal = calibrate_tuples(&drive(1200, seed, &BOTH_WAYS), 0).unwrap();
        assert!(cal.failed_checks().next().is_none(), "{:?}", cal.checks);
        let model = cal.odometry.unwrap();
        let (v, sd) = (model.parameters(), model.standard_deviations());
        for i in 0..6 {
            if (v[i] - truth[i]).abs() <= 2.0 * sd[i] {
                within[i] += 1;
            }
        }
    }
    for (i, n) in within.iter().enumerate() {
        assert!(*n >= 43, "parameter {i}: within 2 sd in {n} of {runs}");
    }
}

/// The paper's other configurations: the lidar turned a quarter, and mounted off the robot's
/// centre; and one turned half-way round, whose yaw wraps.
#[test]
fn a_lidar_turned_or_off_centre_is_found_where_it_is() {
    for (k, lidar) in [
        [0.0, 0.0, std::f64::consts::FRAC_PI_2],
        [0.045, -0.03, 0.2],
        [-0.02, 0.01, 3.1],
    ]
    .into_iter()
    .enumerate()
    {
        let truth = Geometry { lidar, ..TRUTH };
        let cal = calibrate_tuples(&drive_of(&truth, 1200, 20 + k as u64, &BOTH_WAYS), 0).unwrap();
        assert!(cal.failed_checks().next().is_none(), "{:?}", cal.checks);
        let model = cal.odometry.unwrap();
        let (v, sd) = (model.parameters(), model.standard_deviations());
        let want = truth.to_array();
        for i in 0..6 {
            // 4 sd: three layouts × six parameters, none may fail by chance.
            assert!(
                hilsim_recording::wrap_angle(v[i] - want[i]).abs() <= 4.0 * sd[i],
                "layout {k}, parameter {i}: {} against {} ± {}",
                v[i],
                want[i],
                sd[i]
            );
        }
    }
}

#[test]
fn gross_scan_match_failures_are_left_out_and_counted() {
    let mut tuples = drive(400, 3, &BOTH_WAYS);
    // One in forty matches slid along a wall by 5 cm.
    for t in tuples.iter_mut().step_by(40) {
        t.lidar_motion[1] += 0.05;
    }
    let cal = calibrate_tuples(&tuples, 0).unwrap();
    let model = cal.odometry.unwrap();
    assert!(
        (model.wheel_base_m - TRUTH.wheel_base_m).abs() < 3.0 * model.standard_deviations()[2],
        "{model:?}"
    );
    assert!(
        cal.notes
            .iter()
            .any(|n| n.contains("10 left out as outliers")),
        "{:?}",
        cal.notes
    );
}

#[test]
fn a_drive_that_never_turns_is_refused_or_fails_its_checks() {
    // Exactly straight: the turn gains are singular.
    let straight: Vec<Tuple> = drive(100, 4, &[0.0])
        .into_iter()
        .map(|t| Tuple {
            right_rad_s: t.left_rad_s,
            ..t
        })
        .collect();
    let err = calibrate_tuples(&straight, 0).unwrap_err();
    assert!(matches!(err, CalibrationError::Unidentifiable(_)), "{err}");
    // Wavering a little: an answer, with the turning and the precision checks failed.
    let cal = calibrate_tuples(&drive(100, 4, &[0.0]), 0).unwrap();
    let failed: Vec<&str> = cal.failed_checks().map(|c| c.name.as_str()).collect();
    for name in [
        "odometry.turned_left_deg",
        "odometry.turned_right_deg",
        "odometry.wheels_sd",
    ] {
        assert!(failed.contains(&name), "{name} passed: {failed:?}");
    }
}

#[test]
fn a_drive_that_turns_one_way_only_fails_its_check() {
    let cal = calibrate_tuples(&drive(400, 5, &[0.0, 1.5]), 0).unwrap();
    let failed: Vec<&str> = cal.failed_checks().map(|c| c.name.as_str()).collect();
    assert!(failed.contains(&"odometry.turned_right_deg"), "{failed:?}");
}

#[test]
fn a_drive_that_only_turns_in_place_fails_its_straight_check() {
    let cal = calibrate_tuples(&drive(400, 6, &[1.5, -1.5]), 0);
    // Turning alone cannot set the scale: refused, or a failed check.
    if let Ok(cal) = cal {
        let failed: Vec<&str> = cal.failed_checks().map(|c| c.name.as_str()).collect();
        assert!(
            failed.contains(&"odometry.straight_wheel_bases"),
            "{failed:?}"
        );
    }
}

#[test]
fn too_few_tuples_are_refused() {
    let err = calibrate_tuples(&drive(11, 7, &BOTH_WAYS), 0).unwrap_err();
    assert!(matches!(err, CalibrationError::TooFewSamples(_)), "{err}");
}

#[test]
fn the_file_format_round_trips_through_the_parser() {
    let text: String = drive(30, 8, &BOTH_WAYS)
        .iter()
        .map(|t| {
            format!(
                "{{ \"T\": {:e}, \"phi_l\": {:e}, \"phi_r\": {:e}, \"sm\": [ {:e}, {:e}, {:e} ] }}\n",
                t.duration_s,
                t.left_rad_s,
                t.right_rad_s,
                t.lidar_motion[0],
                t.lidar_motion[1],
                t.lidar_motion[2]
            )
        })
        .collect();
    let (parsed, unsound) = parse_tuples(&text, "drive.tuple").unwrap();
    assert_eq!(unsound, 0);
    let made = drive(30, 8, &BOTH_WAYS);
    assert_eq!(parsed.len(), made.len());
    // The decimal's nearest double, to the last bit or so.
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-15 * a.abs().max(1e-300);
    for (p, m) in parsed.iter().zip(&made) {
        assert!(close(p.duration_s, m.duration_s) && close(p.left_rad_s, m.left_rad_s));
        assert!(close(p.right_rad_s, m.right_rad_s));
        assert!((0..3).all(|i| close(p.lidar_motion[i], m.lidar_motion[i])));
    }
}
