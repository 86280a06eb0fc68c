//! One entry point for every method: what `hilsim calibrate` and a scenario's
//! `[calibration] methods` call.

use hilsim_recording::Recording;

use crate::target_samples::SampleOptions;
use crate::{em, groundtruth, landmarks, Calibration, CalibrationError, Method};

/// What a user sets of the methods (the rest is each method's default).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Settings {
    /// The beam facing the target and its start distance (EM, ground truth).
    pub target: SampleOptions,
    /// Finding the stand-still stops (landmarks).
    pub stops: landmarks::StopOptions,
    /// Priors on bias coefficients (EM).
    pub priors: em::Priors,
    /// Scan matching and intervals (odometry).
    pub odometry: crate::odometry::RecordingOptions,
}

/// Calibrates `rec` with `method`, each method with its default options but the target (the beam
/// facing it and its start distance, for the methods that follow one: EM, ground truth).
///
/// # Errors
/// The method's [`CalibrationError`].
pub fn calibrate(
    rec: &Recording,
    method: Method,
    target: SampleOptions,
) -> Result<Calibration, CalibrationError> {
    calibrate_with(
        rec,
        method,
        &Settings {
            target,
            ..Settings::default()
        },
    )
}

/// Calibrates `rec` with `method` and the user's `settings`.
///
/// # Errors
/// The method's [`CalibrationError`].
pub fn calibrate_with(
    rec: &Recording,
    method: Method,
    settings: &Settings,
) -> Result<Calibration, CalibrationError> {
    let target = settings.target;
    match method {
        Method::Em => em::calibrate(
            rec,
            &em::EmOptions {
                priors: settings.priors,
                ..em_options(target)
            },
        ),
        Method::Groundtruth => groundtruth::calibrate(
            rec,
            &groundtruth::Options {
                beam_deg: target.beam_deg,
                start_distance_m: target.start_distance_m,
                ..groundtruth::Options::default()
            },
        ),
        Method::Landmarks => landmarks::calibrate(
            rec,
            &landmarks::Options {
                stops: settings.stops,
                ..landmarks::Options::default()
            },
        ),
        Method::Odometry => crate::odometry::calibrate(rec, &settings.odometry),
    }
}

/// EM's default options with the target's beam and start distance.
#[must_use]
pub fn em_options(target: SampleOptions) -> em::EmOptions {
    em::EmOptions {
        beam_deg: target.beam_deg,
        start_distance_m: target.start_distance_m,
        ..em::EmOptions::default()
    }
}
