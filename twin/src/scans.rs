//! A recording's lidar as scans: each revolution's readings with the geometry a scan schedule
//! needs (first angle, step, beam period), read one revolution at a time.

use std::path::Path;

use hilsim_recording::{wrap_angle, LidarSample, RecordingDir};
use hilsim_sim::scan_schedule::{Scan, MAX_BEAMS_PER_SCAN};

use crate::error::TwinError;

/// How far a reading's angle may be from its scan's regular grid, degrees: a log writes angles
/// to 10⁻⁴° (the recording's decimals), so a regular scan is regular far within this.
const ANGLE_TOLERANCE_DEG: f64 = 0.01;

/// One revolution of the log's lidar.
#[derive(Debug, Clone, PartialEq)]
pub struct LogScan {
    /// Its timing and beam angles.
    pub scan: Scan,
    /// Its readings in the file's order (beam `i` is `readings[i]`).
    pub readings: Vec<LidarSample>,
}

/// What reading the scans met that a schedule cannot hold.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ScanCounts {
    /// Revolutions read.
    pub scans: usize,
    /// Revolutions whose angles are not a regular grid (left out).
    pub irregular: usize,
    /// Revolutions starting before the one before (left out).
    pub out_of_order: usize,
}

/// Hands every revolution of the recording's lidar to `each`, in the file's order; revolutions
/// a schedule cannot hold (angles not on a regular grid, more than
/// [`MAX_BEAMS_PER_SCAN`] beams, a start before the previous one's) are counted and left out.
///
/// # Errors
/// The recording has no lidar, or its `lidar.csv` cannot be read.
pub fn for_each_scan(
    dir: &RecordingDir,
    mut each: impl FnMut(LogScan) -> Result<(), TwinError>,
) -> Result<ScanCounts, TwinError> {
    let rows = dir.lidar()?.ok_or_else(|| {
        TwinError::Input(format!(
            "{}: the recording has no lidar.csv: a world is built from a lidar's scans",
            dir.path().display()
        ))
    })?;
    let mut counts = ScanCounts::default();
    let mut current: Vec<LidarSample> = Vec::new();
    let mut last: Option<(f64, u64)> = None;
    let mut flush =
        |readings: &mut Vec<LidarSample>, counts: &mut ScanCounts| -> Result<(), TwinError> {
            if readings.is_empty() {
                return Ok(());
            }
            counts.scans += 1;
            let taken = std::mem::take(readings);
            match scan_of(&taken) {
                Some(scan) if last.is_none_or(|(t, rev)| scan.t_s >= t && scan.rev > rev) => {
                    last = Some((scan.t_s, scan.rev));
                    each(LogScan {
                        scan,
                        readings: taken,
                    })
                }
                Some(_) => {
                    counts.out_of_order += 1;
                    Ok(())
                }
                None => {
                    counts.irregular += 1;
                    Ok(())
                }
            }
        };
    for row in rows {
        let row = row?;
        if current.first().is_some_and(|first| first.rev != row.rev) {
            flush(&mut current, &mut counts)?;
        }
        if current.len() <= MAX_BEAMS_PER_SCAN as usize {
            current.push(row);
        }
    }
    flush(&mut current, &mut counts)?;
    Ok(counts)
}

/// The schedule row of one revolution's readings, when they lie on a regular grid of angles.
#[must_use]
pub fn scan_of(readings: &[LidarSample]) -> Option<Scan> {
    let first = readings.first()?;
    let n = readings.len();
    if n > MAX_BEAMS_PER_SCAN as usize {
        return None;
    }
    // The angles unwrapped from the first, beam after beam (a scan may cross 0°).
    let mut unwrapped = Vec::with_capacity(n);
    let mut angle = 0.0;
    let mut previous = first.angle_deg;
    for r in readings {
        angle += wrap_angle((r.angle_deg - previous).to_radians()).to_degrees();
        previous = r.angle_deg;
        unwrapped.push(angle);
    }
    let beams = u32::try_from(n).ok()?;
    let (step_deg, beam_period_s) = if n > 1 {
        let span = (n - 1) as f64;
        (
            unwrapped[n - 1] / span,
            (readings[n - 1].t_s - first.t_s).max(0.0) / span,
        )
    } else {
        (0.0, 0.0)
    };
    let regular = unwrapped
        .iter()
        .enumerate()
        .all(|(i, a)| (a - i as f64 * step_deg).abs() <= ANGLE_TOLERANCE_DEG);
    let scan = Scan {
        t_s: first.t_s,
        rev: first.rev,
        beams,
        first_deg: first.angle_deg,
        step_deg,
        beam_period_s,
    };
    (regular && (step_deg != 0.0 || n == 1)).then_some(scan)
}

/// The recording at `dir`, opened; a clear error when it is not one.
///
/// # Errors
/// Not a recording directory.
pub fn open(dir: &Path) -> Result<RecordingDir, TwinError> {
    Ok(RecordingDir::open(dir)?)
}
