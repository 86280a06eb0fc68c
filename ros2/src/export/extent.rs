//! What the messages need from whole tables before the first is written (the largest ranges,
//! where the odometry started, whether there is truth), gathered in one pass that also refuses
//! a time no ROS 2 stamp holds.

use std::convert::Infallible;
use std::path::Path;

use hilsim_recording::{
    CommandSample, LidarSample, OdometrySample, SampleSink, SonarSample, TruthSample,
};

use super::options::START_NS;
use crate::Error;

/// What the messages need from whole tables before the first is written: the scans' and the
/// sonar's largest range (their `range_max`, `max_range`), where the odometry started, whether
/// there is any truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Extent {
    /// Rows seen of each table, in `TABLES`' order.
    rows: [u64; 5],
    /// The first row whose time no stamp holds: its table, its row (1-based) and its time.
    beyond_stamp: Option<(&'static str, u64, f64)>,
    pub(super) range_max: f32,
    pub(super) sonar_max: f32,
    pub(super) first_odometry: Option<OdometrySample>,
    pub(super) truth: bool,
}

impl Default for Extent {
    fn default() -> Self {
        Self {
            rows: [0; 5],
            beyond_stamp: None,
            range_max: 1.0,
            sonar_max: 1.0,
            first_odometry: None,
            truth: false,
        }
    }
}

/// Whether a stamp holds time `t_s`: `builtin_interfaces/Time`'s `sec` is an int32, so a stamp
/// ends 2³¹ s (68 years) after the epoch, and a time beyond would wrap. Checked in the integers
/// `stamp_ns` makes (an f64 near 2³¹ s is coarser than a nanosecond).
fn stamp_holds(t_s: f64) -> bool {
    let ns = i128::from(START_NS).saturating_add((t_s * 1e9).round() as i128);
    let range =
        i128::from(i32::MIN) * 1_000_000_000..=i128::from(i32::MAX) * 1_000_000_000 + 999_999_999;
    t_s.is_finite() && range.contains(&ns)
}

/// The tables, in the order [`Extent`] counts their rows.
const TABLES: [&str; 5] = [
    "commands.csv",
    "odometry.csv",
    "lidar.csv",
    "sonar.csv",
    "truth.csv",
];

impl Extent {
    /// Counts a row of table `k` (of [`TABLES`]) and keeps the first whose time `t_s` a stamp
    /// cannot hold.
    fn note_time(&mut self, k: usize, t_s: f64) {
        self.rows[k] += 1;
        if self.beyond_stamp.is_none() && !stamp_holds(t_s) {
            self.beyond_stamp = Some((TABLES[k], self.rows[k], t_s));
        }
    }

    /// Refuses a recording with a time that a ROS 2 stamp cannot hold, naming the table and
    /// row, rather than wrapping it to another century.
    pub(super) fn check_stamps(&self) -> Result<(), Error> {
        let Some((table, row, t_s)) = self.beyond_stamp else {
            return Ok(());
        };
        let (earliest, latest) = (
            i64::from(i32::MIN) - START_NS / 1_000_000_000,
            i64::from(i32::MAX) - START_NS / 1_000_000_000,
        );
        Err(Error::bag(
            Path::new(table),
            format!(
                "row {row}: t_s {t_s:e} s, beyond what a ROS 2 stamp holds (its seconds are an \
                 int32: t_s from {earliest} to {latest} s)"
            ),
        ))
    }

    pub(super) fn note_command(&mut self, c: &CommandSample) {
        self.note_time(0, c.t_s);
    }
    pub(super) fn note_odometry(&mut self, o: &OdometrySample) {
        self.note_time(1, o.t_s);
        self.first_odometry.get_or_insert(*o);
    }
    pub(super) fn note_lidar(&mut self, r: &LidarSample) {
        self.note_time(2, r.t_s);
        if !r.invalid {
            self.range_max = self.range_max.max(r.range_m as f32);
        }
    }
    pub(super) fn note_sonar(&mut self, s: &SonarSample) {
        self.note_time(3, s.t_s);
        self.sonar_max = self.sonar_max.max(s.range_m as f32);
    }
    pub(super) fn note_truth(&mut self, p: &TruthSample) {
        self.note_time(4, p.t_s);
        self.truth = true;
    }
}

impl SampleSink for Extent {
    type Error = Infallible;
    fn command(&mut self, c: &CommandSample) -> Result<(), Infallible> {
        self.note_command(c);
        Ok(())
    }
    fn odometry(&mut self, o: &OdometrySample) -> Result<(), Infallible> {
        self.note_odometry(o);
        Ok(())
    }
    fn lidar(&mut self, r: &LidarSample) -> Result<(), Infallible> {
        self.note_lidar(r);
        Ok(())
    }
    fn sonar(&mut self, s: &SonarSample) -> Result<(), Infallible> {
        self.note_sonar(s);
        Ok(())
    }
    fn truth(&mut self, p: &TruthSample) -> Result<(), Infallible> {
        self.note_truth(p);
        Ok(())
    }
}
