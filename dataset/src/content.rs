//! What the manifest says about a run directory, computed from its files alone (so a rescan
//! after an interruption gives exactly the row that was, or would have been, written): the
//! content hash, the recording's length and the samples per sensor.
//!
//! The content hash is SHA-256 over the `sha256sum` listing of the run's files in byte order of
//! their names: for each file, the hex SHA-256 of its bytes, two spaces, its name and a newline.
//! The shell computes the same: `cd DIR/run-000042 && LC_ALL=C sha256sum * | sha256sum`.

use std::fs;
use std::path::Path;

use sha2::{Digest, Sha256};

use crate::dataset::hex;
use crate::Error;

/// A run directory's manifest fields.
#[derive(Debug, Clone, PartialEq)]
pub struct RunContent {
    /// The content hash (see the module docs), lowercase hex.
    pub sha256: String,
    /// The recording's length: its latest timestamp, seconds.
    pub recorded_s: f64,
    /// Rows of `lidar.csv` (`None`: no such file, the robot has no lidar).
    pub lidar_samples: Option<u64>,
    /// Rows of `sonar.csv`.
    pub sonar_samples: Option<u64>,
    /// Rows of `odometry.csv`.
    pub odometry_samples: Option<u64>,
}

/// The recording's CSV tables (each with `t_s` first).
const TABLES: [&str; 5] = [
    "commands.csv",
    "odometry.csv",
    "lidar.csv",
    "sonar.csv",
    "truth.csv",
];

/// Reads a run directory and computes its manifest fields.
///
/// # Errors
/// The directory cannot be read, holds something other than files, has no `meta.toml`, or a
/// table's last row has no timestamp.
pub fn scan_run(dir: &Path) -> Result<RunContent, Error> {
    let mut names = Vec::new();
    for entry in fs::read_dir(dir).map_err(|err| Error::io(dir, err))? {
        let entry = entry.map_err(|err| Error::io(dir, err))?;
        let kind = entry
            .file_type()
            .map_err(|err| Error::io(&entry.path(), err))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !kind.is_file() {
            return Err(Error::corrupt(
                dir,
                format!("`{name}` is not a file: a run directory holds only files"),
            ));
        }
        names.push(name);
    }
    names.sort();
    if !names.iter().any(|n| n == "meta.toml") {
        return Err(Error::corrupt(
            dir,
            "not a complete run (no meta.toml): delete it to have it made again",
        ));
    }
    let mut listing = String::new();
    let mut content = RunContent {
        sha256: String::new(),
        recorded_s: 0.0,
        lidar_samples: None,
        sonar_samples: None,
        odometry_samples: None,
    };
    for name in &names {
        let path = dir.join(name);
        let bytes = fs::read(&path).map_err(|err| Error::io(&path, err))?;
        listing.push_str(&hex(&Sha256::digest(&bytes)));
        listing.push_str("  ");
        listing.push_str(name);
        listing.push('\n');
        if !TABLES.contains(&name.as_str()) {
            continue;
        }
        let (rows, last_t) = table_stats(&bytes).map_err(|m| Error::corrupt(&path, m))?;
        if let Some(t) = last_t {
            content.recorded_s = content.recorded_s.max(t);
        }
        match name.as_str() {
            "lidar.csv" => content.lidar_samples = Some(rows),
            "sonar.csv" => content.sonar_samples = Some(rows),
            "odometry.csv" => content.odometry_samples = Some(rows),
            _ => {}
        }
    }
    content.sha256 = hex(&Sha256::digest(listing.as_bytes()));
    Ok(content)
}

/// Rows after the header, and the last row's first field (`t_s`).
fn table_stats(bytes: &[u8]) -> Result<(u64, Option<f64>), String> {
    let text = bytes.strip_suffix(b"\n").unwrap_or(bytes);
    let lines = 1 + text.iter().filter(|&&b| b == b'\n').count() as u64;
    if text.is_empty() {
        return Err("empty: expected a header row".to_string());
    }
    let rows = lines - 1;
    if rows == 0 {
        return Ok((0, None));
    }
    let last = text
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(text, |i| &text[i + 1..]);
    let first = last.split(|&b| b == b',').next().unwrap_or_default();
    let t = std::str::from_utf8(first)
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|t| t.is_finite())
        .ok_or_else(|| format!("line {lines}: expected a time in seconds first"))?;
    Ok((rows, Some(t)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_stats_count_rows_and_read_the_last_time() {
        assert_eq!(table_stats(b"t_s,x\n"), Ok((0, None)));
        assert_eq!(table_stats(b"t_s,x\n0,1\n2.5,3\n"), Ok((2, Some(2.5))));
        assert_eq!(table_stats(b"t_s,x\n0,1\n7,3"), Ok((2, Some(7.0))));
        assert!(table_stats(b"").is_err());
        assert!(table_stats(b"t_s,x\nnope,1\n").is_err());
    }
}
