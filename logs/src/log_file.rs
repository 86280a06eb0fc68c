//! A robot's log file as a whole: which format its name says it is in, read into a
//! recording, and what was read, as `hilsim import` reports it.

use std::io::{self, Write};
use std::path::Path;

use hilsim_recording::Recording;

use crate::{
    read_carmen, read_coreslam, read_text, CarmenOptions, CoreSlamOptions, LogError, Poses,
};

/// The formats of robot log read, by the file's name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogKind {
    /// CARMEN's `.log` or `.clf` (or any gzipped file: CARMEN's logger is the one that
    /// writes them).
    Carmen,
    /// CoreSLAM's `.dat`.
    CoreSlam,
}

impl LogKind {
    /// The format `path`'s name says, `None` for a name of no robot log (a ROS bag's, say).
    #[must_use]
    pub fn of(path: &Path) -> Option<Self> {
        let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
        let name = name.strip_suffix(".gz").unwrap_or(&name);
        if name.ends_with(".log") || name.ends_with(".clf") {
            Some(Self::Carmen)
        } else if name.ends_with(".dat") {
            Some(Self::CoreSlam)
        } else if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("gz"))
        {
            Some(Self::Carmen)
        } else {
            None
        }
    }
}

/// A log read into a recording, with its notes for people.
pub struct LogImport {
    /// The recording.
    pub recording: Recording,
    /// What was assumed, skipped or repaired.
    pub notes: Vec<String>,
}

/// Imports the log at `path`, of format `kind`, as the recording directory `out` (the log must
/// not be inside it): a CARMEN log's poses are `poses` (`odometry`; anything else, the
/// default, truth).
///
/// # Errors
/// Poses asked of a CoreSLAM log; as [`read_log`]; the recording cannot be written.
pub fn import_log(
    path: &Path,
    kind: LogKind,
    poses: Option<&str>,
    out: &Path,
) -> Result<LogImport, LogError> {
    if kind == LogKind::CoreSlam && poses.is_some() {
        return Err(LogError::PosesOfCoreSlam);
    }
    let carmen = CarmenOptions {
        poses: match poses {
            Some("odometry") => Poses::Odometry,
            _ => Poses::Truth,
        },
        ..CarmenOptions::default()
    };
    hilsim_recording::check_input_outside(path, out)?;
    let log = read_log(path, kind, &carmen)?;
    hilsim_recording::tidy_after_killed_writers(out)?;
    log.recording.write_dir(out)?;
    Ok(log)
}

/// Reads the log at `path`, of format `kind` (a CARMEN log's poses as `carmen` says).
///
/// # Errors
/// The file cannot be read, or is not a log of its format.
pub fn read_log(path: &Path, kind: LogKind, carmen: &CarmenOptions) -> Result<LogImport, LogError> {
    let text = read_text(path)?;
    let origin = path.display().to_string();
    let (recording, notes) = match kind {
        LogKind::CoreSlam => {
            let options = CoreSlamOptions::default();
            (read_coreslam(&text, &origin, &options)?, Vec::new())
        }
        LogKind::Carmen => read_carmen(&text, &origin, carmen)?,
    };
    Ok(LogImport { recording, notes })
}

impl LogImport {
    /// What was read: the scans and each table's rows, then the notes.
    ///
    /// # Errors
    /// Writing to `w` failed.
    pub fn write_summary(&self, w: &mut dyn Write) -> io::Result<()> {
        let rec = &self.recording;
        let lidar = rec.lidar.as_deref().unwrap_or_default();
        let scans = lidar.last().map_or(0, |s| s.rev + 1);
        writeln!(w, "lidar     {scans} scans: {} rows", lidar.len())?;
        for (name, rows) in [
            ("odometry", rec.odometry.as_ref().map(Vec::len)),
            ("truth", rec.truth.as_ref().map(Vec::len)),
        ] {
            if let Some(rows) = rows {
                writeln!(w, "{name:<9} {rows} rows")?;
            }
        }
        for note in &self.notes {
            writeln!(w, "note: {note}")?;
        }
        Ok(())
    }
}
