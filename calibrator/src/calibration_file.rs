//! A calibration file: the JSON `hilsim calibrate --json` printed, or a run's `results.json`,
//! read within a bound whatever the path is.

use std::io::Read;
use std::path::Path;

use crate::{Calibration, CalibrationError};

/// Most bytes of a calibration file: a calibration is a few hundred bytes and a run's results
/// a few kilobytes.
const MAX_CALIBRATION_BYTES: u64 = 1 << 20;

impl Calibration {
    /// Reads the JSON that `hilsim calibrate --json` printed, from the file at `path`.
    ///
    /// # Errors
    /// The file cannot be read, is larger than 1 MiB, or holds no calibration.
    pub fn read(path: &Path) -> Result<Self, CalibrationError> {
        Self::from_json(&read_text(path)?, &path.display().to_string())
    }

    /// Every calibration in the file at `path`: one `hilsim calibrate --json` object, or a
    /// run's `results.json`.
    ///
    /// # Errors
    /// As [`Calibration::read`].
    pub fn read_all(path: &Path) -> Result<Vec<Self>, CalibrationError> {
        Self::all_from_json(&read_text(path)?, &path.display().to_string())
    }
}

fn read_text(path: &Path) -> Result<String, CalibrationError> {
    let cannot_read =
        |err| CalibrationError::Invalid(format!("{}: cannot read: {err}", path.display()));
    let file = std::fs::File::open(path).map_err(cannot_read)?;
    let mut text = String::new();
    file.take(MAX_CALIBRATION_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(cannot_read)?;
    if text.len() as u64 > MAX_CALIBRATION_BYTES {
        let why = format!("{}: larger than 1 MiB; not a calibration", path.display());
        return Err(CalibrationError::Invalid(why));
    }
    Ok(text)
}
