//! A calibration file: the JSON `hilsim calibrate --json` printed (read by `smooth`, `export`
//! and `report`), or a run's `results.json` (`report`).

use std::io::Read;
use std::path::Path;

use anyhow::{bail, Context, Result};
use hilsim_calibrator::Calibration;

/// Reads the JSON that `hilsim calibrate --json` printed.
pub fn read_calibration(path: &Path) -> Result<Calibration> {
    let text = read_calibration_text(path)?;
    Ok(Calibration::from_json(&text, &path.display().to_string())?)
}

/// Every calibration in a file: one `hilsim calibrate --json` object, or a run's `results.json`.
pub fn read_calibrations(path: &Path) -> Result<Vec<Calibration>> {
    let text = read_calibration_text(path)?;
    Ok(Calibration::all_from_json(
        &text,
        &path.display().to_string(),
    )?)
}

/// The text of a calibration file, read within a bound whatever the path is.
fn read_calibration_text(path: &Path) -> Result<String> {
    // A calibration is a few hundred bytes and a run's results a few kilobytes.
    const MAX_CALIBRATION_BYTES: u64 = 1 << 20;
    let file =
        std::fs::File::open(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let mut text = String::new();
    file.take(MAX_CALIBRATION_BYTES + 1)
        .read_to_string(&mut text)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    if text.len() as u64 > MAX_CALIBRATION_BYTES {
        bail!("{}: larger than 1 MiB; not a calibration", path.display());
    }
    Ok(text)
}
