//! A calibration file as `hilsim calibrate --json` printed it (read by `smooth` and `export`).

use std::io::Read;
use std::path::Path;

use anyhow::{bail, Context, Result};
use hilsim_calibrator::Calibration;

/// Reads the JSON that `hilsim calibrate --json` printed.
pub fn read_calibration(path: &Path) -> Result<Calibration> {
    // A calibration is a few hundred bytes; read at most this much of whatever the path is.
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
    Ok(Calibration::from_json(&text, &path.display().to_string())?)
}
