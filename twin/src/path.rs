//! The path a log's robot took: its truth when the recording has one; otherwise its wheels'
//! dead reckoning corrected by matching each scan of its lidar to the map the scans before it
//! built (point-to-line ICP, `hilsim_calibrator::scan_match`, against [`LocalMap`]'s view).

use hilsim_calibrator::scan_match::{match_scans, MatchOptions, Scan as Points, ScanMatch};
use hilsim_recording::{Mount, Pose, RecordingDir};
use hilsim_sim::recorded_path::RecordedPath;

use crate::error::TwinError;
use crate::local_map::LocalMap;
use crate::scans::{for_each_scan, LogScan};

/// Where the path comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PoseSource {
    /// The recording's `truth.csv` when it has one, else [`PoseSource::Odometry`].
    #[default]
    Auto,
    /// `truth.csv` (a corrected log's poses, a motion capture's).
    Truth,
    /// The wheels' travel (`odometry.csv`) dead-reckoned, each scan matched to the map the
    /// scans before it built.
    Odometry,
}

/// A path and how it was found.
#[derive(Debug, Clone)]
pub struct FoundPath {
    /// The robot's poses.
    pub path: RecordedPath,
    /// Which source gave it (never `Auto`).
    pub source: PoseSource,
    /// Scans matched to the map, and scans whose match failed or strayed from the
    /// wheels' guess (then the wheels' guess was taken): for an odometry path.
    pub matched: usize,
    /// See `matched`.
    pub unmatched: usize,
    /// Rows left out (a time not after the one before).
    pub skipped_rows: usize,
}

/// A scan is added to the map once the lidar has moved this far from where the last one added
/// was taken, metres: the map then holds a scan every 0.3 m (enough to see every surface from
/// two places), not the same view ten times a second.
const MAP_SCAN_DISTANCE_M: f64 = 0.3;
/// … or turned this far, degrees (a tenth of a SICK's 180° field of view).
const MAP_SCAN_TURN_DEG: f64 = 15.0;
/// A match further than this from the wheels' guess is a false one, metres: the wheels err by
/// a few percent of the 0.1–0.3 m since the scan before.
const MATCH_GATE_M: f64 = 0.15;
/// See `MATCH_GATE_M`, degrees.
const MATCH_GATE_DEG: f64 = 8.0;
/// The wider gate of a match that lies on the map ([`taken`]), metres and degrees: a lidar
/// stamped up to 0.3 s apart from the wheels (the diagnosis's latency range) on a robot
/// turning at 1.5 rad/s and driving at 1 m/s.
const WIDE_GATE_M: f64 = 0.4;
/// See `WIDE_GATE_M`.
const WIDE_GATE_DEG: f64 = 25.0;
/// Share of a scan's points a match must pair with the map's surfaces to be taken in the wide
/// gate: ICP keeps 90 % after its trim, so three quarters leaves room for what the map has not
/// seen yet, while a match that slid along a false surface pairs far fewer.
const ON_THE_MAP_SHARE: f64 = 0.75;
/// … and the largest root mean square of those pairs' distances, metres: a few times a URG's or
/// a SICK's range noise (1–3 cm).
const ON_THE_MAP_RMS_M: f64 = 0.04;

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
    // What the scans matched so far have seen, and where the lidar was when the last of them
    // was added.
    let mut map = LocalMap::default();
    let mut last_added: Option<Pose> = None;
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
        let guess_lidar = in_world(&mount, &guess);
        let view = map.view(&guess_lidar, max_range_m);
        let new_ground = view.points.len() < options.min_points;
        let found = if new_ground {
            None
        } else {
            match match_scans(&view, &current, [0.0; 3], &options) {
                Ok(m) if taken(&m, current.points.len()) => {
                    matched += 1;
                    let p = m.pose();
                    Some(robot_of(&mount, &guess_lidar.compose(p.x, p.y, p.yaw)))
                }
                _ => {
                    unmatched += 1;
                    None
                }
            }
        };
        let pose = found.unwrap_or(guess);
        let lidar = in_world(&mount, &pose);
        // A scan is added once the lidar has moved on from the last added one, matched (or
        // where the map has too little to match it to: the first scan, new ground).
        let moved_on = last_added.is_none_or(|added| {
            let d = lidar.relative_to(&added);
            d.x.hypot(d.y) > MAP_SCAN_DISTANCE_M || d.yaw.abs().to_degrees() > MAP_SCAN_TURN_DEG
        });
        if (found.is_some() || new_ground) && moved_on && current.points.len() >= options.min_points
        {
            map.add(&current, &lidar);
            last_added = Some(lidar);
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

/// Whether a scan's match to the map is taken: near the wheels' guess, or farther (within a
/// wider gate) when most of the scan lies on the map's surfaces. Wheels stamped apart from the
/// scans put a turning robot where it was a little before or after: on the CoreSLAM rover's
/// 75 s log, whose scans lag its encoders by about 0.15 s, turns of 1–2 rad/s move the guess
/// 8–17° from matches that put 80–90 % of the scan on the map within 2–5 cm.
fn taken(m: &ScanMatch, points: usize) -> bool {
    let on_the_map = m.correspondences as f64 >= ON_THE_MAP_SHARE * points as f64
        && m.rms_residual_m <= ON_THE_MAP_RMS_M;
    moved_within(&m.pose(), MATCH_GATE_M, MATCH_GATE_DEG)
        || (on_the_map && moved_within(&m.pose(), WIDE_GATE_M, WIDE_GATE_DEG))
}

/// Whether a match's correction `p` from the guess is within `gate_m` and `gate_deg`.
fn moved_within(p: &Pose, gate_m: f64, gate_deg: f64) -> bool {
    p.x.hypot(p.y) <= gate_m && hilsim_recording::wrap_angle(p.yaw).abs().to_degrees() <= gate_deg
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
