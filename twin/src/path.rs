//! The path a log's robot took: its truth when the recording has one; otherwise its wheels'
//! dead reckoning corrected by matching each scan of its lidar to the last key scan
//! (point-to-line ICP, `hilsim_calibrator::scan_match`).

use hilsim_calibrator::scan_match::{match_scans, MatchOptions, Scan as Points};
use hilsim_recording::{Mount, Pose, RecordingDir};
use hilsim_sim::recorded_path::RecordedPath;

use crate::error::TwinError;
use crate::scans::{for_each_scan, LogScan};

/// Where the path comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PoseSource {
    /// The recording's `truth.csv` when it has one, else [`PoseSource::Odometry`].
    #[default]
    Auto,
    /// `truth.csv` (a corrected log's poses, a motion capture's).
    Truth,
    /// The wheels' travel (`odometry.csv`) dead-reckoned, each scan matched to the last key scan.
    Odometry,
}

/// A path and how it was found.
#[derive(Debug, Clone)]
pub struct FoundPath {
    /// The robot's poses.
    pub path: RecordedPath,
    /// Which source gave it (never `Auto`).
    pub source: PoseSource,
    /// Scans matched to their key scan, and scans whose match failed or strayed from the
    /// wheels' guess (then the wheels' guess was taken): for an odometry path.
    pub matched: usize,
    /// See `matched`.
    pub unmatched: usize,
    /// Rows left out (a time not after the one before).
    pub skipped_rows: usize,
}

/// A key scan is replaced once the lidar has moved this far from it, metres: ICP's guess stays
/// well inside its 0.3 m first gate, and the scans still overlap mostly.
const KEY_SCAN_DISTANCE_M: f64 = 0.3;
/// … or turned this far, degrees (a tenth of a SICK's 180° field of view).
const KEY_SCAN_TURN_DEG: f64 = 15.0;
/// A match further than this from the wheels' guess is a false one, metres: the wheels err by
/// a few percent of the ≤ 0.3 m since the key scan.
const MATCH_GATE_M: f64 = 0.15;
/// See `MATCH_GATE_M`, degrees.
const MATCH_GATE_DEG: f64 = 8.0;

/// The path of the robot of the recording at `dir`.
///
/// # Errors
/// The chosen source is missing (no `truth.csv` for `Truth`; no `odometry.csv` for `Odometry`)
/// or a table cannot be read.
pub fn find_path(
    dir: &RecordingDir,
    source: PoseSource,
    max_range_m: f64,
) -> Result<FoundPath, TwinError> {
    let has_truth = dir.tables().truth;
    match source {
        PoseSource::Truth | PoseSource::Auto if has_truth => truth_path(dir),
        PoseSource::Truth => Err(TwinError::Input(format!(
            "{}: the recording has no truth.csv; use the odometry's path",
            dir.path().display()
        ))),
        PoseSource::Odometry | PoseSource::Auto => odometry_path(dir, max_range_m),
    }
}

fn truth_path(dir: &RecordingDir) -> Result<FoundPath, TwinError> {
    let rows = dir.truth()?.into_iter().flatten();
    let mut points = Vec::new();
    let mut skipped_rows = 0;
    for row in rows {
        let row = row?;
        if points.last().is_some_and(|&(t, _)| row.t_s <= t) {
            skipped_rows += 1;
            continue;
        }
        points.push((row.t_s, Pose::new(row.x_m, row.y_m, row.yaw_rad)));
    }
    let path = RecordedPath::new(points)
        .map_err(|e| TwinError::Input(format!("{}: truth.csv: {e}", dir.path().display())))?;
    Ok(FoundPath {
        path,
        source: PoseSource::Truth,
        matched: 0,
        unmatched: 0,
        skipped_rows,
    })
}

/// The wheels' dead reckoning at the odometer's times.
fn dead_reckoning(dir: &RecordingDir) -> Result<(RecordedPath, usize), TwinError> {
    let missing = || {
        TwinError::Input(format!(
            "{}: the recording has neither truth.csv nor odometry.csv: no path to build a \
             world along",
            dir.path().display()
        ))
    };
    let rows = dir.odometry()?.ok_or_else(missing)?;
    let base = dir.meta().robot.wheel_base_m;
    let mut points: Vec<(f64, Pose)> = Vec::new();
    let mut wheels: Option<[f64; 2]> = None;
    let mut skipped = 0;
    for row in rows {
        let row = row?;
        let pose = match (points.last(), wheels) {
            (Some(&(t, _)), _) if row.t_s <= t => {
                skipped += 1;
                continue;
            }
            (Some(&(_, pose)), Some([l, r])) => pose.drive(row.left_m - l, row.right_m - r, base),
            _ => Pose::default(),
        };
        wheels = Some([row.left_m, row.right_m]);
        points.push((row.t_s, pose));
    }
    let path = RecordedPath::new(points).map_err(|_| missing())?;
    Ok((path, skipped))
}

fn odometry_path(dir: &RecordingDir, max_range_m: f64) -> Result<FoundPath, TwinError> {
    let (wheels, skipped_rows) = dead_reckoning(dir)?;
    let mount = dir.meta().lidar.unwrap_or_default();
    let options = MatchOptions::default();
    let mut points: Vec<(f64, Pose)> = Vec::new();
    // The key scan: its points in its lidar's frame and that lidar's pose in the world.
    let mut key: Option<(Points, Pose)> = None;
    // The last scan's time and the robot's pose then, as found.
    let mut last: Option<(f64, Pose)> = None;
    let (mut matched, mut unmatched) = (0, 0);
    for_each_scan(dir, |log: LogScan| {
        let t = mid_time_s(&log);
        if last.is_some_and(|(t0, _)| t <= t0) {
            return Ok(());
        }
        // The wheels' guess: the last pose moved as the wheels moved since.
        let guess = match last {
            Some((t0, pose)) => {
                let moved = wheels.pose_at(t).relative_to(&wheels.pose_at(t0));
                pose.compose(moved.x, moved.y, moved.yaw)
            }
            None => wheels.pose_at(t),
        };
        let current = deskewed_points(&log, max_range_m, &wheels, &mount, t);
        let found = match &key {
            Some((reference, key_lidar)) => {
                let guess_lidar = in_world(&mount, &guess).relative_to(key_lidar);
                let guess_motion = [guess_lidar.x, guess_lidar.y, guess_lidar.yaw];
                match match_scans(reference, &current, guess_motion, &options) {
                    Ok(m) if near(&m.pose(), &guess_lidar) => {
                        matched += 1;
                        let p = m.pose();
                        Some(robot_of(&mount, &key_lidar.compose(p.x, p.y, p.yaw)))
                    }
                    _ => {
                        unmatched += 1;
                        None
                    }
                }
            }
            None => None,
        };
        let pose = found.unwrap_or(guess);
        let lidar = in_world(&mount, &pose);
        let replace = match &key {
            None => true,
            Some((_, key_lidar)) => {
                let d = lidar.relative_to(key_lidar);
                found.is_none()
                    || d.x.hypot(d.y) > KEY_SCAN_DISTANCE_M
                    || d.yaw.abs().to_degrees() > KEY_SCAN_TURN_DEG
            }
        };
        if replace && current.points.len() >= options.min_points {
            key = Some((current, lidar));
        }
        last = Some((t, pose));
        points.push((t, pose));
        Ok(())
    })?;
    let path = if points.is_empty() {
        wheels
    } else {
        RecordedPath::new(points).map_err(TwinError::Input)?
    };
    Ok(FoundPath {
        path,
        source: PoseSource::Odometry,
        matched,
        unmatched,
        skipped_rows,
    })
}

/// The middle of a scan's readings in time: the instant its points are taken at when the scan
/// is matched as one rigid set.
fn mid_time_s(log: &LogScan) -> f64 {
    log.scan.beam_time_s(log.scan.beams.saturating_sub(1) / 2)
}

/// A scan's valid readings within `max_range_m`, as points in the lidar's frame.
#[must_use]
pub fn scan_points(log: &LogScan, max_range_m: f64) -> Points {
    Points::from_polar(
        log.readings
            .iter()
            .filter(|r| !r.invalid && r.range_m > 0.0 && r.range_m <= max_range_m)
            .map(|r| (r.angle_deg.to_radians(), r.range_m)),
    )
}

/// A scan's points as the lidar would have seen them all at `t`: each reading moved by the
/// lidar's motion between its own instant and `t`, as the wheels tell it (a lidar turning at
/// 5 Hz on a robot at 0.3 m/s moves 6 cm within one scan).
fn deskewed_points(
    log: &LogScan,
    max_range_m: f64,
    wheels: &RecordedPath,
    mount: &Mount,
    t: f64,
) -> Points {
    let at_t = in_world(mount, &wheels.pose_at(t));
    let points = log
        .readings
        .iter()
        .enumerate()
        .filter(|(_, r)| !r.invalid && r.range_m > 0.0 && r.range_m <= max_range_m)
        .map(|(i, r)| {
            let a = r.angle_deg.to_radians();
            let (x, y) = (r.range_m * a.cos(), r.range_m * a.sin());
            let beam_t = log.scan.beam_time_s(u32::try_from(i).unwrap_or(u32::MAX));
            if beam_t == t {
                return [x, y];
            }
            let lidar = in_world(mount, &wheels.pose_at(beam_t)).relative_to(&at_t);
            let (sin, cos) = lidar.yaw.sin_cos();
            [lidar.x + cos * x - sin * y, lidar.y + sin * x + cos * y]
        })
        .collect();
    Points { points }
}

fn near(found: &Pose, guess: &Pose) -> bool {
    (found.x - guess.x).hypot(found.y - guess.y) <= MATCH_GATE_M
        && hilsim_recording::wrap_angle(found.yaw - guess.yaw)
            .abs()
            .to_degrees()
            <= MATCH_GATE_DEG
}

/// The lidar's pose in the world for the robot at `robot`.
fn in_world(mount: &Mount, robot: &Pose) -> Pose {
    mount.in_world(robot)
}

/// The robot's pose for its lidar at `lidar`: the mount undone.
fn robot_of(mount: &Mount, lidar: &Pose) -> Pose {
    let yaw = lidar.yaw - mount.yaw_rad();
    let (sin, cos) = yaw.sin_cos();
    Pose::new(
        lidar.x - (cos * mount.x_m - sin * mount.y_m),
        lidar.y - (sin * mount.x_m + cos * mount.y_m),
        yaw,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mount_undone_gives_the_robot_back() {
        let mount = Mount {
            x_m: 0.145,
            y_m: -0.02,
            yaw_deg: 3.0,
        };
        let robot = Pose::new(1.0, -2.0, 2.5);
        let back = robot_of(&mount, &in_world(&mount, &robot));
        assert!((back.x - robot.x).abs() < 1e-12 && (back.y - robot.y).abs() < 1e-12);
        assert!(hilsim_recording::wrap_angle(back.yaw - robot.yaw).abs() < 1e-12);
    }
}
