//! A recording's drive as tuples: the lidar's revolutions matched scan to scan, the encoders'
//! travel over the same intervals.

use hilsim_recording::Recording;

use crate::{Calibration, CalibrationError};

/// What a user sets of the calibration of a recording.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RecordingOptions {}

/// Calibrates the wheels and the lidar's mount from `rec`'s encoders and lidar.
///
/// # Errors
/// A table the method needs is missing, or the estimate's errors.
pub fn calibrate(rec: &Recording, options: &RecordingOptions) -> Result<Calibration, CalibrationError> {
    let _ = (rec, options);
    Err(CalibrationError::Missing("odometry from a recording: scan matching not yet wired".into()))
}
