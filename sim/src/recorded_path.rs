//! A robot's path as a log recorded it, for a scenario that replays the log's run (`[robot]
//! path`): the robot is where the log says it was at every instant, not where a drive program
//! would take it.
//!
//! The file is a CSV `t_s,x_m,y_m,yaw_deg`, times strictly increasing; between two rows the pose
//! is interpolated linearly (the heading along the shorter arc), before the first row it is the
//! first row's and after the last the last's.

use std::path::Path;

use hilsim_recording::pose::Pose;
use hilsim_recording::TimedPath;

use crate::numeric_csv::read_rows;
use crate::scenario::ScenarioError;

/// The header of a path file.
pub const PATH_HEADER: [&str; 4] = ["t_s", "x_m", "y_m", "yaw_deg"];

/// The most rows a path file holds: a day at 20 Hz (48 MB in memory).
pub const MAX_PATH_ROWS: usize = 1_728_000;

/// A recorded path: poses at increasing times.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedPath {
    path: TimedPath,
}

impl RecordedPath {
    /// A path from `(t_s, pose)` pairs.
    ///
    /// # Errors
    /// No pose, a time not after the one before, or a pose that is not finite.
    pub fn new(points: impl IntoIterator<Item = (f64, Pose)>) -> Result<Self, String> {
        let mut path = Self {
            path: TimedPath::new(),
        };
        for (t, pose) in points {
            path.push(t, pose)?;
        }
        if path.is_empty() {
            return Err("no pose".to_string());
        }
        Ok(path)
    }

    fn push(&mut self, t_s: f64, pose: Pose) -> Result<(), String> {
        if ![t_s, pose.x, pose.y, pose.yaw]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err("a pose or time that is not a finite number".to_string());
        }
        if let Some(&last) = self.path.times().last() {
            if t_s <= last {
                return Err(format!(
                    "t_s {t_s} is not after the row before ({last}); a path's times increase"
                ));
            }
        }
        self.path.push(t_s, pose);
        Ok(())
    }

    /// Reads a path file (see the module's documentation).
    ///
    /// # Errors
    /// The file cannot be read or is not a path: the error names the file and the line.
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        let mut recorded = Self {
            path: TimedPath::new(),
        };
        read_rows(path, PATH_HEADER, MAX_PATH_ROWS, |[t, x, y, yaw_deg]| {
            recorded.push(t, Pose::new(x, y, yaw_deg.to_radians()))
        })?;
        if recorded.is_empty() {
            return Err(ScenarioError {
                file: path.to_path_buf(),
                line: None,
                message: "no pose: a path needs at least one row".to_string(),
            });
        }
        Ok(recorded)
    }

    /// The path as the CSV text [`RecordedPath::load`] reads (times to the microsecond,
    /// positions to the micrometre, headings to 10⁻⁶°).
    #[must_use]
    pub fn to_csv(&self) -> String {
        let mut text = PATH_HEADER.join(",");
        text.push('\n');
        for (t, p) in self.iter() {
            text.push_str(&format!(
                "{t:.6},{:.6},{:.6},{:.6}\n",
                p.x,
                p.y,
                p.yaw.to_degrees()
            ));
        }
        text
    }

    /// The first recorded time, seconds.
    #[must_use]
    pub fn start_s(&self) -> f64 {
        self.path.times().first().copied().unwrap_or(0.0)
    }

    /// The last recorded time, seconds.
    #[must_use]
    pub fn end_s(&self) -> f64 {
        self.path.times().last().copied().unwrap_or(0.0)
    }

    /// The first pose.
    #[must_use]
    pub fn first(&self) -> Pose {
        self.path.first().map(|(_, p)| p).unwrap_or_default()
    }

    /// The number of recorded poses.
    #[must_use]
    pub fn len(&self) -> usize {
        self.path.len()
    }

    /// Whether the path has no pose (never, for a loaded one).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.path.is_empty()
    }

    /// The recorded `(t_s, pose)` pairs.
    pub fn iter(&self) -> impl Iterator<Item = (f64, Pose)> + '_ {
        self.path.iter()
    }

    /// The pose at `t_s` (held at the ends, [`hilsim_recording::Ends::Held`]).
    #[must_use]
    pub fn pose_at(&self, t_s: f64) -> Pose {
        self.path.pose_at(t_s).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poses_between_rows_are_interpolated_and_held_at_the_ends() {
        let path = RecordedPath::new([
            (1.0, Pose::new(0.0, 0.0, 3.0)),
            (2.0, Pose::new(1.0, 2.0, -3.0)),
        ])
        .unwrap();
        assert_eq!(path.pose_at(0.0), Pose::new(0.0, 0.0, 3.0));
        assert_eq!(path.pose_at(5.0), Pose::new(1.0, 2.0, -3.0));
        let mid = path.pose_at(1.5);
        assert!((mid.x - 0.5).abs() < 1e-12 && (mid.y - 1.0).abs() < 1e-12);
        // Across ±π the shorter arc: from 3 to −3 rad through π.
        assert!(
            (mid.yaw.abs() - std::f64::consts::PI).abs() < 1e-9,
            "{mid:?}"
        );
    }

    #[test]
    fn a_time_going_back_is_refused_with_its_line() {
        let dir = std::env::temp_dir().join(format!("hilsim-path-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("p.csv");
        std::fs::write(&file, "t_s,x_m,y_m,yaw_deg\n0,0,0,0\n1,1,0,0\n0.5,2,0,0\n").unwrap();
        let err = RecordedPath::load(&file).unwrap_err();
        assert_eq!(err.line, Some(4), "{err}");
        std::fs::write(&file, "t_s,x_m,y_m,yaw_deg\n0,0,0,0\n1,1,0,90\n").unwrap();
        let path = RecordedPath::load(&file).unwrap();
        let back = dir.join("q.csv");
        std::fs::write(&back, path.to_csv()).unwrap();
        assert_eq!(RecordedPath::load(&back).unwrap(), path);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
