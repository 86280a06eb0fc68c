//! Bad input to the EM calibrator, the ground-truth baseline and the smoother gives
//! the right `CalibrationError` with a message a user can act on, never a panic or a NaN.

use std::sync::OnceLock;

use hilsim_calibrator::em::{self, EmOptions};
use hilsim_calibrator::{groundtruth, smoothing, CalibrationError, Sensor, SensorModel};
use hilsim_fixtures::em_experiment::Run;
use hilsim_recording::{CommandSample, Recording};

/// A good recording (0.3 m/s: 13.7 s, 68 revolutions), simulated once for every test.
fn good() -> Recording {
    static REC: OnceLock<Recording> = OnceLock::new();
    REC.get_or_init(|| {
        Run {
            speed_mps: 0.3,
            ..Run::default()
        }
        .record()
    })
    .clone()
}

fn em_err(rec: &Recording) -> CalibrationError {
    em::calibrate(rec, &EmOptions::default()).expect_err("must fail")
}

fn gt_err(rec: &Recording) -> CalibrationError {
    groundtruth::calibrate(rec, &groundtruth::Options::default()).expect_err("must fail")
}

#[test]
fn the_good_recording_calibrates() {
    em::calibrate(&good(), &EmOptions::default()).expect("calibrates");
    groundtruth::calibrate(&good(), &groundtruth::Options::default()).expect("calibrates");
}

#[test]
fn no_lidar_is_missing() {
    let mut rec = good();
    rec.lidar = None;
    for err in [em_err(&rec), gt_err(&rec)] {
        assert!(matches!(err, CalibrationError::Missing(_)), "{err}");
        assert!(err.to_string().contains("lidar.csv"), "{err}");
    }
}

#[test]
fn no_commands_are_missing() {
    let mut rec = good();
    rec.commands.clear();
    let err = em_err(&rec);
    assert!(matches!(err, CalibrationError::Missing(_)), "{err}");
    assert!(err.to_string().contains("commands.csv"), "{err}");
}

#[test]
fn a_nan_is_invalid() {
    let mut rec = good();
    let lidar = rec.lidar.as_mut().unwrap();
    let row = lidar
        .iter_mut()
        .find(|s| s.angle_deg == 0.0 && s.rev == 20)
        .unwrap();
    row.range_m = f64::NAN;
    let err = em_err(&rec);
    assert!(matches!(err, CalibrationError::Invalid(_)), "{err}");
    assert!(err.to_string().contains("non-finite"), "{err}");

    let mut rec = good();
    rec.commands[1].left_mps = f64::INFINITY;
    assert!(matches!(em_err(&rec), CalibrationError::Invalid(_)));

    let mut rec = good();
    rec.sonar.as_mut().unwrap()[3].range_m = f64::NAN;
    assert!(matches!(em_err(&rec), CalibrationError::Invalid(_)));

    let mut rec = good();
    rec.truth.as_mut().unwrap()[3].x_m = f64::NAN;
    assert!(matches!(gt_err(&rec), CalibrationError::Invalid(_)));
}

#[test]
fn too_few_samples() {
    let mut rec = good();
    // Keep 8 revolutions: fewer than the 10 valid readings EM needs.
    rec.lidar.as_mut().unwrap().retain(|s| s.rev < 8);
    let err = em_err(&rec);
    assert!(matches!(err, CalibrationError::TooFewSamples(_)), "{err}");
    assert!(err.to_string().contains("8 valid lidar readings"), "{err}");
    assert!(matches!(gt_err(&rec), CalibrationError::TooFewSamples(_)));
}

#[test]
fn no_motion_is_unidentifiable() {
    let mut rec = good();
    rec.commands = vec![CommandSample {
        t_s: 0.0,
        left_mps: 0.0,
        right_mps: 0.0,
    }];
    let err = em_err(&rec);
    assert!(matches!(err, CalibrationError::Unidentifiable(_)), "{err}");
    assert!(err.to_string().contains("no motion"), "{err}");
}

#[test]
fn a_beam_that_never_sees_the_target_is_invalid() {
    let mut rec = good();
    for s in rec.lidar.as_mut().unwrap() {
        s.invalid = true;
        s.range_m = 0.0;
    }
    let err = em_err(&rec);
    assert!(matches!(err, CalibrationError::Invalid(_)), "{err}");
    assert!(err.to_string().contains("never sees a target"), "{err}");
    assert!(matches!(gt_err(&rec), CalibrationError::Invalid(_)));
}

#[test]
fn a_beam_across_the_motion_is_unidentifiable() {
    let opts = EmOptions {
        beam_deg: 90.0,
        ..EmOptions::default()
    };
    let err = em::calibrate(&good(), &opts).expect_err("must fail");
    assert!(matches!(err, CalibrationError::Unidentifiable(_)), "{err}");
    assert!(err.to_string().contains("perpendicular"), "{err}");
}

#[test]
fn no_start_distance_is_missing() {
    let mut rec = good();
    rec.meta.world.target_start_distance_m = None;
    for err in [em_err(&rec), gt_err(&rec)] {
        assert!(matches!(err, CalibrationError::Missing(_)), "{err}");
        assert!(err.to_string().contains("start distance"), "{err}");
    }
    // Given on the command line instead, it works.
    let opts = EmOptions {
        start_distance_m: Some(0.5),
        ..EmOptions::default()
    };
    em::calibrate(&rec, &opts).expect("calibrates");
    // A nonsense one is invalid.
    let opts = EmOptions {
        start_distance_m: Some(-1.0),
        ..EmOptions::default()
    };
    let err = em::calibrate(&rec, &opts).expect_err("must fail");
    assert!(matches!(err, CalibrationError::Invalid(_)), "{err}");
}

#[test]
fn no_truth_is_missing_for_the_baseline_only() {
    let mut rec = good();
    rec.truth = None;
    let err = gt_err(&rec);
    assert!(matches!(err, CalibrationError::Missing(_)), "{err}");
    assert!(err.to_string().contains("truth.csv"), "{err}");
    let cal = em::calibrate(&rec, &EmOptions::default()).expect("EM needs no truth");
    assert!(cal.metrics.is_none(), "no truth, no metrics");
}

#[test]
fn nonsense_options_are_invalid() {
    for opts in [
        EmOptions {
            tolerance: 0.0,
            ..EmOptions::default()
        },
        EmOptions {
            max_iterations: 0,
            ..EmOptions::default()
        },
        EmOptions {
            process_noise_rel: f64::NAN,
            ..EmOptions::default()
        },
        EmOptions {
            beam_deg: f64::INFINITY,
            ..EmOptions::default()
        },
    ] {
        let err = em::calibrate(&good(), &opts).expect_err("must fail");
        assert!(matches!(err, CalibrationError::Invalid(_)), "{err}");
    }
}

#[test]
fn smoothing_rejects_calibrations_it_cannot_use() {
    let rec = good();
    let mut trained = em::calibrate(&rec, &EmOptions::default()).expect("calibrates");
    let mut no_lidar = trained.clone();
    no_lidar.sensors.remove(&Sensor::Lidar);
    let err = smoothing::smooth(&rec, &no_lidar, &EmOptions::default()).expect_err("fails");
    assert!(matches!(err, CalibrationError::Missing(_)), "{err}");

    let mut quartic = trained.clone();
    quartic.sensors.insert(
        Sensor::Lidar,
        SensorModel::without_sd(vec![0.05, 0.9, 0.05, 0.001, 0.0001], vec![0.0, 0.0, 0.004]),
    );
    let err = smoothing::smooth(&rec, &quartic, &EmOptions::default()).expect_err("fails");
    assert!(matches!(err, CalibrationError::Invalid(_)), "{err}");

    // Coefficients so large that the filter overflows: an error, not a NaN distance.
    trained.sensors.get_mut(&Sensor::Lidar).unwrap().alpha = vec![0.0, 1e300, 1e300];
    let opts = EmOptions {
        use_odometer: false,
        use_sonar: false,
        ..EmOptions::default()
    };
    let err = smoothing::smooth(&rec, &trained, &opts).expect_err("fails");
    assert!(matches!(err, CalibrationError::Diverged(_)), "{err}");
}
