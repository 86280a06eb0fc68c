//! A recording too long to hold whole, kept as every k-th part of it: what a command that
//! draws a recording (a report) holds, so that its memory is bounded whatever the recording's
//! length. A recording within the bound is kept whole, sample for sample.

use std::borrow::Cow;
use std::convert::Infallible;

use crate::{
    CommandSample, Error, LidarSample, OdometrySample, Recording, RecordingDir, SampleSink,
    SonarSample, TruthSample,
};

/// The most rows of one table a command that holds a recording to draw or calibrate from keeps
/// in memory (`hilsim report`, `hilsim run`): a longer recording is thinned ([`Thinning`]), so
/// that the command's memory is bounded whatever the recording's length. Half a million rows is
/// about four and a half minutes of an XV-11's 1,800 readings a second, and some 14 hours of
/// truth at 10 Hz; a report's charts thin far below it anyway.
pub const MAX_ROWS_HELD: u64 = 500_000;

/// Which part of a recording is kept: every `lidar_revolutions`-th lidar revolution (whole
/// revolutions, so that a scan drawn is a scan), and every `rows[t]`-th row of the other tables
/// (commands, odometry, sonar, truth). All 1: the whole recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Thinning {
    /// Every how many lidar revolutions one is kept.
    pub lidar_revolutions: u64,
    /// Every how many rows one is kept, of the commands, odometry, sonar and truth.
    pub rows: [u64; 4],
}

impl Thinning {
    /// The whole recording.
    pub const WHOLE: Self = Self {
        lidar_revolutions: 1,
        rows: [1; 4],
    };

    /// Whether nothing is left out.
    #[must_use]
    pub fn is_whole(&self) -> bool {
        *self == Self::WHOLE
    }

    /// What was kept, in words ("every 8th lidar revolution, every 4th odometry row"), for a
    /// page that draws a thinned recording; empty when whole.
    #[must_use]
    pub fn describe(&self) -> String {
        let every = |k: u64, what: &str| (k > 1).then(|| format!("every {} {what}", ordinal(k)));
        let parts: Vec<String> = [
            every(self.lidar_revolutions, "lidar revolution"),
            every(self.rows[0], "command"),
            every(self.rows[1], "odometry row"),
            every(self.rows[2], "sonar ping"),
            every(self.rows[3], "true pose"),
        ]
        .into_iter()
        .flatten()
        .collect();
        match parts.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            _ => parts.concat(),
        }
    }

    /// The thinning that keeps at most about `max_rows` rows of each table of a recording of
    /// `counts` rows (lidar revolutions kept whole: its rows are bounded as the revolutions are
    /// alike).
    fn of(counts: &Counts, max_rows: u64) -> Self {
        // A power of two, as a sink that thins while the rows arrive doubles it
        // ([`ThinnedSink`]): the same part of a recording is kept either way.
        let every = |rows: u64| rows.div_ceil(max_rows.max(1)).max(1).next_power_of_two();
        Self {
            lidar_revolutions: every(counts.lidar),
            rows: [
                every(counts.rows[0]),
                every(counts.rows[1]),
                every(counts.rows[2]),
                every(counts.rows[3]),
            ],
        }
    }
}

/// `k` as an English ordinal: 2nd, 3rd, 4th, 11th, 21st.
fn ordinal(k: u64) -> String {
    let suffix = match (k % 10, k % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{k}{suffix}")
}

/// Rows of each table: the lidar's, and the commands', odometry's, sonar's and truth's.
#[derive(Debug, Default)]
struct Counts {
    lidar: u64,
    rows: [u64; 4],
}

impl SampleSink for Counts {
    type Error = Infallible;
    fn command(&mut self, _: &CommandSample) -> Result<(), Infallible> {
        self.rows[0] += 1;
        Ok(())
    }
    fn odometry(&mut self, _: &OdometrySample) -> Result<(), Infallible> {
        self.rows[1] += 1;
        Ok(())
    }
    fn lidar(&mut self, _: &LidarSample) -> Result<(), Infallible> {
        self.lidar += 1;
        Ok(())
    }
    fn sonar(&mut self, _: &SonarSample) -> Result<(), Infallible> {
        self.rows[2] += 1;
        Ok(())
    }
    fn truth(&mut self, _: &TruthSample) -> Result<(), Infallible> {
        self.rows[3] += 1;
        Ok(())
    }
}

/// Whether the `index`-th row (0-based) of a table thinned to every `k`-th is kept.
fn kept(index: usize, k: u64) -> bool {
    index as u64 % k == 0
}

fn thin<T: Copy>(rows: &[T], k: u64) -> Vec<T> {
    rows.iter()
        .enumerate()
        .filter(|(i, _)| kept(*i, k))
        .map(|(_, r)| *r)
        .collect()
}

impl Recording {
    /// The recording, or every k-th part of it when a table holds more than `max_rows` rows
    /// (see [`Thinning`]); borrowed when whole.
    #[must_use]
    pub fn thinned(&self, max_rows: u64) -> (Cow<'_, Self>, Thinning) {
        let len = |n: usize| n as u64;
        let counts = Counts {
            lidar: len(self.lidar.as_ref().map_or(0, Vec::len)),
            rows: [
                len(self.commands.len()),
                len(self.odometry.as_ref().map_or(0, Vec::len)),
                len(self.sonar.as_ref().map_or(0, Vec::len)),
                len(self.truth.as_ref().map_or(0, Vec::len)),
            ],
        };
        let thinning = Thinning::of(&counts, max_rows);
        if thinning.is_whole() {
            return (Cow::Borrowed(self), thinning);
        }
        let k = thinning.rows;
        let lidar = self.lidar.as_ref().map(|rows| {
            rows.iter()
                .filter(|r| r.rev % thinning.lidar_revolutions == 0)
                .copied()
                .collect()
        });
        let thinned = Self {
            meta: self.meta.clone(),
            commands: thin(&self.commands, k[0]),
            odometry: self.odometry.as_deref().map(|r| thin(r, k[1])),
            lidar,
            sonar: self.sonar.as_deref().map(|r| thin(r, k[2])),
            truth: self.truth.as_deref().map(|r| thin(r, k[3])),
        };
        (Cow::Owned(thinned), thinning)
    }
}

impl RecordingDir {
    /// Reads the recording as [`Recording::thinned`] keeps it, holding at most about
    /// `max_rows` rows of each table: the tables are checked and counted first (the errors of
    /// [`Recording::read_dir`]), then read again keeping every k-th part. A recording within
    /// the bound is read whole, sample for sample as `read_dir` reads it.
    ///
    /// # Errors
    /// A malformed table, naming the file and line.
    pub fn read_thinned(&self, max_rows: u64) -> Result<(Recording, Thinning), Error> {
        let mut counts = Counts::default();
        self.check(&mut counts)?;
        let thinning = Thinning::of(&counts, max_rows);
        let k = thinning.rows;
        let keep = |index: usize, k: u64| kept(index, k);
        let mut rec = Recording::new(self.meta().clone());
        for (i, c) in self.commands()?.enumerate() {
            let c = c?;
            if keep(i, k[0]) {
                rec.commands.push(c);
            }
        }
        if let Some(rows) = self.odometry()? {
            let mut kept_rows = Vec::new();
            for (i, o) in rows.enumerate() {
                let o = o?;
                if keep(i, k[1]) {
                    kept_rows.push(o);
                }
            }
            rec.odometry = Some(kept_rows);
        }
        if let Some(rows) = self.lidar()? {
            let mut kept_rows = Vec::new();
            for r in rows {
                let r = r?;
                if r.rev % thinning.lidar_revolutions == 0 {
                    kept_rows.push(r);
                }
            }
            rec.lidar = Some(kept_rows);
        }
        if let Some(rows) = self.sonar()? {
            let mut kept_rows = Vec::new();
            for (i, s) in rows.enumerate() {
                let s = s?;
                if keep(i, k[2]) {
                    kept_rows.push(s);
                }
            }
            rec.sonar = Some(kept_rows);
        }
        if let Some(rows) = self.truth()? {
            let mut kept_rows = Vec::new();
            for (i, p) in rows.enumerate() {
                let p = p?;
                if keep(i, k[3]) {
                    kept_rows.push(p);
                }
            }
            rec.truth = Some(kept_rows);
        }
        Ok((rec, thinning))
    }
}

/// A [`SampleSink`] that keeps a recording as [`Recording::thinned`] would keep it, while the
/// samples arrive: every table whole until it passes `max_rows`, then every 2nd, 4th… row (whole
/// lidar revolutions) of it. It holds at most `max_rows` rows of a table, plus one revolution.
#[derive(Debug)]
pub struct ThinnedSink {
    recording: Recording,
    max_rows: usize,
    thinning: Thinning,
    /// Rows seen of the commands, odometry, sonar and truth.
    seen: [u64; 4],
}

impl ThinnedSink {
    /// An empty recording with `meta` and the `tables` given, to keep at most `max_rows` rows
    /// of each.
    #[must_use]
    pub fn new(meta: crate::Meta, tables: crate::Tables, max_rows: u64) -> Self {
        let mut recording = Recording::new(meta);
        recording.odometry = tables.odometry.then(Vec::new);
        recording.lidar = tables.lidar.then(Vec::new);
        recording.sonar = tables.sonar.then(Vec::new);
        recording.truth = tables.truth.then(Vec::new);
        Self {
            recording,
            max_rows: usize::try_from(max_rows.max(1)).unwrap_or(usize::MAX),
            thinning: Thinning::WHOLE,
            seen: [0; 4],
        }
    }

    /// The part kept, and which part it is.
    #[must_use]
    pub fn finish(self) -> (Recording, Thinning) {
        (self.recording, self.thinning)
    }
}

/// Keeps `row`, the `seen`-th of its table, in `rows` thinned to every `k`-th row; past `max`
/// rows, every other row kept is dropped and `k` doubled.
fn keep_row<T: Copy>(rows: &mut Vec<T>, row: &T, seen: &mut u64, k: &mut u64, max: usize) {
    if *seen % *k == 0 {
        rows.push(*row);
        if rows.len() > max {
            let mut position = 0;
            rows.retain(|_| {
                position += 1;
                position % 2 == 1
            });
            *k *= 2;
        }
    }
    *seen += 1;
}

fn table<T>(rows: &mut Option<Vec<T>>) -> &mut Vec<T> {
    rows.get_or_insert_with(Vec::new)
}

impl SampleSink for ThinnedSink {
    type Error = Infallible;
    fn command(&mut self, c: &CommandSample) -> Result<(), Infallible> {
        let (rows, seen, k) = (
            &mut self.recording.commands,
            &mut self.seen[0],
            &mut self.thinning.rows[0],
        );
        keep_row(rows, c, seen, k, self.max_rows);
        Ok(())
    }
    fn odometry(&mut self, o: &OdometrySample) -> Result<(), Infallible> {
        let rows = table(&mut self.recording.odometry);
        keep_row(
            rows,
            o,
            &mut self.seen[1],
            &mut self.thinning.rows[1],
            self.max_rows,
        );
        Ok(())
    }
    fn lidar(&mut self, r: &LidarSample) -> Result<(), Infallible> {
        let rows = table(&mut self.recording.lidar);
        let k = &mut self.thinning.lidar_revolutions;
        if r.rev % *k == 0 {
            rows.push(*r);
            // Whole revolutions: a revolution is only ever dropped whole, at its first reading.
            if rows.len() > self.max_rows && rows.first().is_some_and(|f| f.rev != r.rev) {
                *k *= 2;
                let k = *k;
                rows.retain(|x| x.rev % k == 0);
            }
        }
        Ok(())
    }
    fn sonar(&mut self, s: &SonarSample) -> Result<(), Infallible> {
        let rows = table(&mut self.recording.sonar);
        keep_row(
            rows,
            s,
            &mut self.seen[2],
            &mut self.thinning.rows[2],
            self.max_rows,
        );
        Ok(())
    }
    fn truth(&mut self, p: &TruthSample) -> Result<(), Infallible> {
        let rows = table(&mut self.recording.truth);
        keep_row(
            rows,
            p,
            &mut self.seen[3],
            &mut self.thinning.rows[3],
            self.max_rows,
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Meta;

    fn recording(revolutions: u64, per_rev: u64) -> Recording {
        let mut rec = Recording::new(Meta::default());
        let mut lidar = Vec::new();
        for rev in 0..revolutions {
            for k in 0..per_rev {
                let t_s = (rev * per_rev + k) as f64 * 0.001;
                lidar.push(LidarSample {
                    t_s,
                    rev,
                    angle_deg: k as f64,
                    range_m: 1.0,
                    strength: 100,
                    invalid: false,
                    warning: false,
                    true_range_m: None,
                });
            }
        }
        rec.lidar = Some(lidar);
        rec.truth = Some(
            (0..1000)
                .map(|i| TruthSample {
                    t_s: f64::from(i) * 0.01,
                    x_m: 0.0,
                    y_m: 0.0,
                    yaw_rad: 0.0,
                })
                .collect(),
        );
        rec.commands.push(CommandSample {
            t_s: 0.0,
            left_mps: 0.1,
            right_mps: 0.1,
        });
        rec
    }

    #[test]
    fn a_recording_within_the_bound_is_kept_whole_and_read_as_read_dir_reads_it() {
        let rec = recording(10, 36);
        let (kept, thinning) = rec.thinned(1000);
        assert!(thinning.is_whole());
        assert!(matches!(kept, Cow::Borrowed(_)));
        let dir = tempfile::tempdir().unwrap();
        rec.write_dir(&dir.path().join("r")).unwrap();
        let opened = RecordingDir::open(&dir.path().join("r")).unwrap();
        let (read, thinning) = opened.read_thinned(1000).unwrap();
        assert!(thinning.is_whole());
        assert_eq!(read, Recording::read_dir(&dir.path().join("r")).unwrap());
    }

    #[test]
    fn a_longer_recording_keeps_whole_revolutions_and_at_most_the_bound_of_each_table() {
        let rec = recording(100, 36);
        let (kept, thinning) = rec.thinned(500);
        assert_eq!(thinning.lidar_revolutions, 8, "3600 readings into 500");
        assert_eq!(thinning.rows[3], 2, "1000 poses into 500");
        let lidar = kept.lidar.as_ref().unwrap();
        assert!(lidar.len() <= 500 + 36, "{}", lidar.len());
        assert!(lidar.iter().all(|r| r.rev % 8 == 0));
        assert_eq!(lidar.len() % 36, 0, "whole revolutions");
        assert_eq!(kept.truth.as_ref().unwrap().len(), 500);
        assert_eq!(
            thinning.describe(),
            "every 8th lidar revolution and every 2nd true pose"
        );
        assert_eq!(
            [1, 2, 3, 4, 11, 12, 13, 21, 22, 101, 111].map(ordinal),
            [
                "1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd", "101st",
                "111th"
            ]
        );
        // Read from a directory as streams, the same part is kept.
        let dir = tempfile::tempdir().unwrap();
        rec.write_dir(&dir.path().join("r")).unwrap();
        let opened = RecordingDir::open(&dir.path().join("r")).unwrap();
        let (read, read_thinning) = opened.read_thinned(500).unwrap();
        assert_eq!(read_thinning, thinning);
        assert_eq!(read.lidar, kept.lidar);
        assert_eq!(read.truth, kept.truth);
    }

    #[test]
    fn a_sink_thinning_as_rows_arrive_holds_the_bound_and_keeps_what_the_whole_thinning_keeps() {
        let rec = recording(100, 36);
        let tables = crate::Tables {
            odometry: false,
            lidar: true,
            sonar: false,
            truth: true,
        };
        let mut sink = ThinnedSink::new(rec.meta.clone(), tables, 512);
        let mut most = 0;
        for r in rec.lidar.as_ref().unwrap() {
            let Ok(()) = sink.lidar(r);
            most = most.max(sink.recording.lidar.as_ref().map_or(0, Vec::len));
        }
        for p in rec.truth.as_ref().unwrap() {
            let Ok(()) = sink.truth(p);
        }
        let Ok(()) = sink.command(&rec.commands[0]);
        assert!(most <= 512 + 36, "held {most} rows");
        let (kept, thinning) = sink.finish();
        let (whole, whole_thinning) = rec.thinned(512);
        assert_eq!(thinning, whole_thinning);
        assert_eq!(kept, *whole);
        // Within the bound, every sample is kept.
        let mut sink = ThinnedSink::new(rec.meta.clone(), tables, 1_000_000);
        for r in rec.lidar.as_ref().unwrap() {
            let Ok(()) = sink.lidar(r);
        }
        assert!(sink.finish().1.is_whole());
    }
}
