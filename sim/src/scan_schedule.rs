//! When a recorded lidar took its scans and at which angles, for a scenario that replays a
//! log's run (`[sensors.lidar] schedule`): the emulated lidar takes a reading at every beam of
//! every recorded scan, so the twin's readings pair one for one with the log's.
//!
//! The file is a CSV `t_s,rev,beams,first_deg,step_deg,beam_period_s`, a row per scan: beam `i`
//! (from 0 to `beams − 1`) is taken at `t_s + i × beam_period_s` at `first_deg + i × step_deg`
//! in the lidar's frame (counter-clockwise from its forward axis; a negative step scans
//! clockwise). Scans start in time order and revolution numbers increase; a revolution number
//! is the log's, so gaps where the log lost scans stay gaps.

use std::path::Path;

use crate::numeric_csv::read_rows;
use crate::scenario::ScenarioError;

/// The header of a schedule file.
pub const SCHEDULE_HEADER: [&str; 6] = [
    "t_s",
    "rev",
    "beams",
    "first_deg",
    "step_deg",
    "beam_period_s",
];

/// The most scans a schedule holds: a day at 40 Hz (a fast scanning rangefinder's rate).
pub const MAX_SCANS: usize = 3_456_000;

/// The most beams in one scan: a 0.1° lidar's full turn.
pub const MAX_BEAMS_PER_SCAN: u32 = 3600;

/// One scan's timing and beam angles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scan {
    /// When its first beam is taken, seconds.
    pub t_s: f64,
    /// Its revolution number.
    pub rev: u64,
    /// How many beams.
    pub beams: u32,
    /// The first beam's angle, degrees.
    pub first_deg: f64,
    /// The angle between consecutive beams, degrees.
    pub step_deg: f64,
    /// The time between consecutive beams, seconds.
    pub beam_period_s: f64,
}

impl Scan {
    /// When beam `i` is taken, seconds.
    #[must_use]
    pub fn beam_time_s(&self, i: u32) -> f64 {
        self.t_s + f64::from(i) * self.beam_period_s
    }

    /// Beam `i`'s angle, degrees in [0, 360), to the micro-degree (so that a log's whole
    /// degrees stay whole after `i` steps of rounding).
    #[must_use]
    pub fn beam_deg(&self, i: u32) -> f64 {
        let deg = (self.first_deg + f64::from(i) * self.step_deg).rem_euclid(360.0);
        ((deg * 1e6).round() / 1e6).rem_euclid(360.0)
    }

    fn check(&self) -> Result<(), String> {
        if self.t_s < 0.0 {
            return Err(format!("t_s {}: a scan before t = 0", self.t_s));
        }
        if self.beams == 0 || self.beams > MAX_BEAMS_PER_SCAN {
            return Err(format!(
                "beams {}: expected 1 to {MAX_BEAMS_PER_SCAN}",
                self.beams
            ));
        }
        if self.beam_period_s < 0.0 || self.beam_period_s * f64::from(self.beams) > 10.0 {
            return Err(format!(
                "beam_period_s {}: expected a scan taken within 10 s",
                self.beam_period_s
            ));
        }
        if self.step_deg.abs() * f64::from(self.beams - 1) > 360.0 + 1e-6 {
            return Err(format!(
                "step_deg {}: {} beams would turn more than once",
                self.step_deg, self.beams
            ));
        }
        Ok(())
    }
}

/// A recorded lidar's scans.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ScanSchedule {
    scans: Vec<Scan>,
}

impl ScanSchedule {
    /// A schedule of `scans`.
    ///
    /// # Errors
    /// A scan that makes no sense, or scans out of time or revolution order.
    pub fn new(scans: impl IntoIterator<Item = Scan>) -> Result<Self, String> {
        let mut schedule = Self::default();
        for scan in scans {
            schedule.push(scan)?;
        }
        Ok(schedule)
    }

    fn push(&mut self, scan: Scan) -> Result<(), String> {
        scan.check()?;
        if let Some(last) = self.scans.last() {
            if scan.t_s < last.t_s || scan.rev <= last.rev {
                return Err(format!(
                    "scan at t_s {} rev {} after one at t_s {} rev {}: scans start in time order \
                     and revolutions increase",
                    scan.t_s, scan.rev, last.t_s, last.rev
                ));
            }
        }
        self.scans.push(scan);
        Ok(())
    }

    /// Reads a schedule file (see the module's documentation).
    ///
    /// # Errors
    /// The file cannot be read or is not a schedule: the error names the file and the line.
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        let mut schedule = Self::default();
        read_rows(
            path,
            SCHEDULE_HEADER,
            MAX_SCANS,
            |[t_s, rev, beams, first_deg, step_deg, beam_period_s]| {
                let whole = |v: f64, name: &str, max: f64| {
                    if v >= 0.0 && v <= max && v.fract() == 0.0 {
                        Ok(v)
                    } else {
                        Err(format!("{name} {v}: expected a whole number from 0"))
                    }
                };
                schedule.push(Scan {
                    t_s,
                    rev: whole(rev, "rev", 9e15)? as u64,
                    beams: whole(beams, "beams", f64::from(u32::MAX))? as u32,
                    first_deg,
                    step_deg,
                    beam_period_s,
                })
            },
        )?;
        Ok(schedule)
    }

    /// The schedule as the CSV text [`ScanSchedule::load`] reads.
    #[must_use]
    pub fn to_csv(&self) -> String {
        let mut text = SCHEDULE_HEADER.join(",");
        text.push('\n');
        for s in &self.scans {
            text.push_str(&format!(
                "{},{},{},{},{},{}\n",
                s.t_s, s.rev, s.beams, s.first_deg, s.step_deg, s.beam_period_s
            ));
        }
        text
    }

    /// The scans, in time order.
    #[must_use]
    pub fn scans(&self) -> &[Scan] {
        &self.scans
    }

    /// When the last beam is taken, seconds (0 without scans).
    #[must_use]
    pub fn end_s(&self) -> f64 {
        self.scans
            .iter()
            .map(|s| s.beam_time_s(s.beams - 1))
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scan(t_s: f64, rev: u64) -> Scan {
        Scan {
            t_s,
            rev,
            beams: 180,
            first_deg: -90.0,
            step_deg: 1.0,
            beam_period_s: 1.0 / 75.0 / 360.0,
        }
    }

    #[test]
    fn beams_are_timed_and_angled_from_their_scan() {
        let s = scan(2.0, 7);
        assert_eq!(s.beam_deg(0), 270.0);
        assert_eq!(s.beam_deg(90), 0.0);
        assert!((s.beam_time_s(179) - (2.0 + 179.0 / 27_000.0)).abs() < 1e-12);
    }

    #[test]
    fn scans_out_of_order_or_turning_twice_are_refused() {
        assert!(ScanSchedule::new([scan(1.0, 1), scan(0.5, 2)]).is_err());
        assert!(ScanSchedule::new([scan(1.0, 1), scan(1.1, 1)]).is_err());
        let twice = Scan {
            step_deg: 3.0,
            ..scan(0.0, 0)
        };
        assert!(ScanSchedule::new([twice]).is_err());
        let ok = ScanSchedule::new([scan(0.0, 0), scan(0.2, 3)]).unwrap();
        assert_eq!(ok.scans().len(), 2);
    }

    #[test]
    fn a_schedule_survives_its_file() {
        let dir = std::env::temp_dir().join(format!("hilsim-schedule-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("s.csv");
        let schedule = ScanSchedule::new([scan(0.0, 0), scan(0.2, 3)]).unwrap();
        std::fs::write(&file, schedule.to_csv()).unwrap();
        assert_eq!(ScanSchedule::load(&file).unwrap(), schedule);
        std::fs::write(
            &file,
            "t_s,rev,beams,first_deg,step_deg,beam_period_s\n0,1.5,3,0,1,0\n",
        )
        .unwrap();
        let err = ScanSchedule::load(&file).unwrap_err();
        assert_eq!(err.line, Some(2), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
