//! One entry point for every method: what `hilsim calibrate` and a scenario's
//! `[calibration] methods` call.

use hilsim_recording::Recording;

use crate::{em, groundtruth, landmarks, Calibration, CalibrationError, Method};

/// Where the target is, for the methods that need one (EM, ground truth).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TargetOptions {
    /// The beam facing the target, degrees from the robot's heading.
    pub beam_deg: f64,
    /// The target's distance at the start, metres (default: from the recording's metadata).
    pub start_distance_m: Option<f64>,
}

/// Calibrates `rec` with `method`, each method with its default options but the target.
///
/// # Errors
/// The method's [`CalibrationError`].
pub fn calibrate(
    rec: &Recording,
    method: Method,
    target: TargetOptions,
) -> Result<Calibration, CalibrationError> {
    match method {
        Method::Em => em::calibrate(rec, &em_options(target)),
        Method::Groundtruth => groundtruth::calibrate(
            rec,
            &groundtruth::Options {
                beam_deg: target.beam_deg,
                start_distance_m: target.start_distance_m,
                ..groundtruth::Options::default()
            },
        ),
        Method::Landmarks => landmarks::calibrate(rec, &landmarks::Options::default()),
    }
}

/// EM's default options with the target's beam and start distance.
#[must_use]
pub fn em_options(target: TargetOptions) -> em::EmOptions {
    em::EmOptions {
        beam_deg: target.beam_deg,
        start_distance_m: target.start_distance_m,
        ..em::EmOptions::default()
    }
}
