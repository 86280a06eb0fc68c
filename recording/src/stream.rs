//! Writing a recording as its samples arrive, so that a run of any length records in flat
//! memory: rows go straight to their files in a temporary sibling of the output directory, which
//! is renamed into place when complete (as [`crate::Recording::write_dir`] does, with the same
//! bytes for the same samples).

use std::convert::Infallible;
use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::atomic::{
    check_replaceable_recording, new_sibling_dir, put_recording_in_place, resolve_output_dir,
};
use crate::write::rows;
use crate::{
    CommandSample, Error, LidarDecimals, LidarSample, Meta, OdometrySample, Recording, SonarSample,
    TruthSample,
};

/// Where samples go as they are taken: a recording in memory, or its files as they are written.
/// Samples of each table arrive in time order.
pub trait SampleSink {
    /// Why a sample could not be kept.
    type Error;
    /// A wheel command (one row per change).
    ///
    /// # Errors
    /// The sample cannot be kept (an I/O error naming the file).
    fn command(&mut self, c: &CommandSample) -> Result<(), Self::Error>;
    /// An odometer reading.
    ///
    /// # Errors
    /// As [`SampleSink::command`].
    fn odometry(&mut self, o: &OdometrySample) -> Result<(), Self::Error>;
    /// A lidar reading.
    ///
    /// # Errors
    /// As [`SampleSink::command`].
    fn lidar(&mut self, r: &LidarSample) -> Result<(), Self::Error>;
    /// A lidar reading whose numbers are decimals already (an importer's): kept as
    /// [`SampleSink::lidar`] keeps [`LidarDecimals::sample`], which is what this default does;
    /// a stream writes the digits as they are, without the round trip through `f64`.
    ///
    /// # Errors
    /// As [`SampleSink::command`].
    fn lidar_decimals(&mut self, r: &LidarDecimals) -> Result<(), Self::Error> {
        self.lidar(&r.sample())
    }
    /// A sonar ping.
    ///
    /// # Errors
    /// As [`SampleSink::command`].
    fn sonar(&mut self, s: &SonarSample) -> Result<(), Self::Error>;
    /// A true pose.
    ///
    /// # Errors
    /// As [`SampleSink::command`].
    fn truth(&mut self, p: &TruthSample) -> Result<(), Self::Error>;
}

/// A recording in memory takes every sample (into the tables it has).
impl SampleSink for Recording {
    type Error = Infallible;

    fn command(&mut self, c: &CommandSample) -> Result<(), Infallible> {
        self.commands.push(*c);
        Ok(())
    }
    fn odometry(&mut self, o: &OdometrySample) -> Result<(), Infallible> {
        self.odometry.get_or_insert_with(Vec::new).push(*o);
        Ok(())
    }
    fn lidar(&mut self, r: &LidarSample) -> Result<(), Infallible> {
        self.lidar.get_or_insert_with(Vec::new).push(*r);
        Ok(())
    }
    fn sonar(&mut self, s: &SonarSample) -> Result<(), Infallible> {
        self.sonar.get_or_insert_with(Vec::new).push(*s);
        Ok(())
    }
    fn truth(&mut self, p: &TruthSample) -> Result<(), Infallible> {
        self.truth.get_or_insert_with(Vec::new).push(*p);
        Ok(())
    }
}

/// Which optional tables a streamed recording has (`commands.csv` always).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Tables {
    /// `odometry.csv`.
    pub odometry: bool,
    /// `lidar.csv`.
    pub lidar: bool,
    /// `sonar.csv`.
    pub sonar: bool,
    /// `truth.csv`.
    pub truth: bool,
}

/// One table's file. The lidar's and the sonar's header depends on whether rows carry the true
/// range, so it is written with the first row (or, for an empty table, at the end).
struct TableFile {
    path: PathBuf,
    file: File,
    /// Rows not yet written to `file` (written when [`FLUSH_AT`] bytes are waiting), so that a
    /// row is formatted straight into it.
    text: Vec<u8>,
    /// The header, once written; `None` before the first row of a table whose header waits.
    with_truth: Option<bool>,
}

/// A table's rows are written to its file in pieces of about this size (bounded memory; few
/// system calls).
const FLUSH_AT: usize = 1 << 18;

impl TableFile {
    fn create(dir: &Path, name: &str, header: Option<&str>) -> Result<Self, Error> {
        let path = dir.join(name);
        let file = File::create(&path).map_err(|err| Error::io(&path, err))?;
        let mut table = Self {
            path,
            file,
            // A row is at most a few hundred bytes (eight numbers of `Display`'s longest).
            text: Vec::with_capacity(FLUSH_AT + 4096),
            with_truth: None,
        };
        if let Some(header) = header {
            table.with_truth = Some(false);
            table.text.extend_from_slice(header.as_bytes());
        }
        Ok(table)
    }

    /// Writes the waiting rows to the file.
    fn flush(&mut self) -> Result<(), Error> {
        self.file
            .write_all(&self.text)
            .map_err(|err| Error::io(&self.path, err))?;
        self.text.clear();
        Ok(())
    }

    /// Writes one row made by `format`; `truth` says whether it carries a true range (for the
    /// tables whose header waits for their first row: every row must agree with it).
    fn row(
        &mut self,
        truth: Option<bool>,
        header: fn(bool) -> &'static str,
        format: impl FnOnce(&mut Vec<u8>, bool),
    ) -> Result<(), Error> {
        let with_truth = match (self.with_truth, truth) {
            (Some(w), Some(t)) if w != t => {
                return Err(Error::format(
                    &self.path,
                    None,
                    "a true range on some rows only: a streamed table has it on all or none",
                ))
            }
            (Some(w), _) => w,
            (None, t) => {
                let w = t.unwrap_or(false);
                self.with_truth = Some(w);
                self.text.extend_from_slice(header(w).as_bytes());
                w
            }
        };
        format(&mut self.text, with_truth);
        if self.text.len() >= FLUSH_AT {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes a waiting header (an empty table has none of the truth column) and flushes; the
    /// file, to be synced with the others ([`sync_together`]).
    fn finish(
        mut self,
        header: Option<fn(bool) -> &'static str>,
    ) -> Result<(PathBuf, File), Error> {
        if let (None, Some(header)) = (self.with_truth, header) {
            self.text.extend_from_slice(header(false).as_bytes());
        }
        self.flush()?;
        Ok((self.path, self.file))
    }
}

/// A recording written as it is taken (a [`SampleSink`]); [`RecordingStream::finish`] puts it in
/// place. Dropped unfinished, it removes what it wrote and leaves the output as it was.
pub struct RecordingStream {
    dir: PathBuf,
    tmp: PathBuf,
    meta: Meta,
    commands: Option<TableFile>,
    odometry: Option<TableFile>,
    lidar: Option<TableFile>,
    sonar: Option<TableFile>,
    truth: Option<TableFile>,
}

impl RecordingStream {
    /// Starts a recording to be put at `dir`, with `meta` and the `tables` given. `dir` must be
    /// replaceable ([`crate::check_replaceable_recording`]); it is untouched until
    /// [`RecordingStream::finish`]. What killed writers left beside `dir` is not looked for here
    /// (that lists the parent): a command writing one output calls
    /// [`crate::tidy_after_killed_writers`] first.
    ///
    /// # Errors
    /// `dir` holds something other than a recording, or a file cannot be created.
    pub fn create(dir: &Path, meta: Meta, tables: Tables) -> Result<Self, Error> {
        let dir = resolve_output_dir(dir)?;
        check_replaceable_recording(&dir)?;
        let tmp = new_sibling_dir(&dir)?;
        let mut stream = Self {
            dir,
            tmp: tmp.clone(),
            meta,
            commands: None,
            odometry: None,
            lidar: None,
            sonar: None,
            truth: None,
        };
        // Once `stream` exists, an error drops it, which removes `tmp`.
        stream.commands = Some(TableFile::create(
            &tmp,
            "commands.csv",
            Some(rows::COMMANDS_HEADER),
        )?);
        if tables.odometry {
            let header = Some(rows::ODOMETRY_HEADER);
            stream.odometry = Some(TableFile::create(&tmp, "odometry.csv", header)?);
        }
        if tables.lidar {
            stream.lidar = Some(TableFile::create(&tmp, "lidar.csv", None)?);
        }
        if tables.sonar {
            stream.sonar = Some(TableFile::create(&tmp, "sonar.csv", None)?);
        }
        if tables.truth {
            let header = Some(rows::TRUTH_HEADER);
            stream.truth = Some(TableFile::create(&tmp, "truth.csv", header)?);
        }
        Ok(stream)
    }

    /// Where the recording is put when finished.
    #[must_use]
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The `meta.toml` to be written when finished, to complete with what only the samples
    /// tell (an importer learns a sensor's beam from its messages).
    pub fn meta_mut(&mut self) -> &mut Meta {
        &mut self.meta
    }

    /// Completes every file, writes `meta.toml` and puts the recording in place of `dir`.
    ///
    /// # Errors
    /// An I/O error naming the file.
    pub fn finish(self) -> Result<(), Error> {
        self.finish_with(|_| Ok(()))
    }

    /// As [`RecordingStream::finish`], running `extra` on the complete directory before it is
    /// put in place (to add files of one's own beside the recording, or check it).
    ///
    /// # Errors
    /// An I/O error naming the file, or `extra`'s.
    pub fn finish_with<E: From<Error>>(
        mut self,
        extra: impl FnOnce(&Path) -> Result<(), E>,
    ) -> Result<(), E> {
        let tables = [
            (self.commands.take(), None),
            (self.odometry.take(), None),
            (
                self.lidar.take(),
                Some(rows::lidar_header as fn(bool) -> &'static str),
            ),
            (
                self.sonar.take(),
                Some(rows::sonar_header as fn(bool) -> &'static str),
            ),
            (self.truth.take(), None),
        ];
        let mut files = Vec::with_capacity(6);
        for (table, header) in tables {
            if let Some(table) = table {
                files.push(table.finish(header)?);
            }
        }
        // meta.toml straight into the temporary directory: the directory is put in place whole.
        let meta_path = self.tmp.join("meta.toml");
        let meta = toml::to_string(&self.meta)
            .map_err(|err| Error::format(&meta_path, None, err.to_string()))?;
        let mut meta_file = File::create(&meta_path).map_err(|err| Error::io(&meta_path, err))?;
        meta_file
            .write_all(meta.as_bytes())
            .map_err(|err| Error::io(&meta_path, err))?;
        files.push((meta_path, meta_file));
        sync_together(&files)?;
        extra(&self.tmp)?;
        put_recording_in_place(&self.tmp, &self.dir)?;
        // In place: nothing for `drop` to remove.
        self.tmp = PathBuf::new();
        Ok(())
    }
}

/// Syncs every file at once, one thread each: a journalling file system commits concurrent
/// syncs together, so a recording costs about one commit instead of one per file (six syncs in
/// turn were most of a short recording's fixed cost).
fn sync_together(files: &[(PathBuf, File)]) -> Result<(), Error> {
    std::thread::scope(|scope| {
        let syncs: Vec<_> = files
            .iter()
            .map(|(path, file)| {
                scope.spawn(move || file.sync_all().map_err(|err| Error::io(path, err)))
            })
            .collect();
        syncs
            .into_iter()
            .map(|sync| {
                sync.join().unwrap_or_else(|_| {
                    Err(Error::io(
                        Path::new("recording"),
                        std::io::Error::other("a sync thread panicked"),
                    ))
                })
            })
            .collect::<Result<Vec<()>, Error>>()
            .map(|_| ())
    })
}

impl Drop for RecordingStream {
    fn drop(&mut self) {
        if !self.tmp.as_os_str().is_empty() {
            let _ = fs::remove_dir_all(&self.tmp);
        }
    }
}

/// The table's file, or an error naming it when the stream was started without that table.
fn table<'a>(
    table: &'a mut Option<TableFile>,
    tmp: &Path,
    name: &str,
) -> Result<&'a mut TableFile, Error> {
    table.as_mut().ok_or_else(|| {
        Error::format(
            &tmp.join(name),
            None,
            "a sample for a table the recording was started without",
        )
    })
}

impl SampleSink for RecordingStream {
    type Error = Error;

    fn command(&mut self, c: &CommandSample) -> Result<(), Error> {
        table(&mut self.commands, &self.tmp, "commands.csv")?.row(
            None,
            |_| rows::COMMANDS_HEADER,
            |s, _| rows::command(s, c),
        )
    }
    fn odometry(&mut self, o: &OdometrySample) -> Result<(), Error> {
        table(&mut self.odometry, &self.tmp, "odometry.csv")?.row(
            None,
            |_| rows::ODOMETRY_HEADER,
            |s, _| rows::odometry(s, o),
        )
    }
    fn lidar(&mut self, r: &LidarSample) -> Result<(), Error> {
        table(&mut self.lidar, &self.tmp, "lidar.csv")?.row(
            Some(r.true_range_m.is_some()),
            rows::lidar_header,
            |s, with_truth| rows::lidar(s, r, with_truth),
        )
    }
    fn lidar_decimals(&mut self, r: &LidarDecimals) -> Result<(), Error> {
        table(&mut self.lidar, &self.tmp, "lidar.csv")?.row(
            Some(false),
            rows::lidar_header,
            |s, _| rows::lidar_decimals(s, r),
        )
    }
    fn sonar(&mut self, p: &SonarSample) -> Result<(), Error> {
        table(&mut self.sonar, &self.tmp, "sonar.csv")?.row(
            Some(p.true_range_m.is_some()),
            rows::sonar_header,
            |s, with_truth| rows::sonar(s, p, with_truth),
        )
    }
    fn truth(&mut self, p: &TruthSample) -> Result<(), Error> {
        table(&mut self.truth, &self.tmp, "truth.csv")?.row(
            None,
            |_| rows::TRUTH_HEADER,
            |s, _| rows::truth(s, p),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_recording() -> Recording {
        let mut rec = Recording::new(Meta::default());
        rec.commands = vec![CommandSample {
            t_s: 0.0,
            left_mps: 0.1,
            right_mps: 0.1,
        }];
        rec.odometry = Some(Vec::new());
        rec.lidar = Some(
            (0..3)
                .map(|i| LidarSample {
                    t_s: f64::from(i) * 0.01,
                    rev: 0,
                    angle_deg: f64::from(i) * 0.5,
                    range_m: 1.25,
                    strength: 40,
                    invalid: i == 1,
                    warning: false,
                    true_range_m: Some(1.2),
                })
                .collect(),
        );
        rec.sonar = Some(Vec::new());
        rec.truth = Some(vec![TruthSample {
            t_s: 0.0,
            x_m: 0.5,
            y_m: 0.0,
            yaw_rad: std::f64::consts::PI,
        }]);
        rec
    }

    fn stream_out(rec: &Recording, dir: &Path) -> Result<(), Error> {
        let tables = Tables {
            odometry: rec.odometry.is_some(),
            lidar: rec.lidar.is_some(),
            sonar: rec.sonar.is_some(),
            truth: rec.truth.is_some(),
        };
        let mut stream = RecordingStream::create(dir, rec.meta.clone(), tables)?;
        for c in &rec.commands {
            stream.command(c)?;
        }
        for r in rec.lidar.iter().flatten() {
            stream.lidar(r)?;
        }
        for p in rec.truth.iter().flatten() {
            stream.truth(p)?;
        }
        stream.finish()
    }

    /// The same samples give the same bytes as the whole-table writer, empty tables (whose
    /// truth column waits for a row) included.
    #[test]
    fn a_streamed_recording_equals_the_written_one_byte_for_byte() {
        let tmp = tempfile::tempdir().unwrap();
        let rec = sample_recording();
        rec.write_dir(&tmp.path().join("whole")).unwrap();
        stream_out(&rec, &tmp.path().join("streamed")).unwrap();
        for name in Recording::FILES {
            let whole = fs::read(tmp.path().join("whole").join(name)).ok();
            let streamed = fs::read(tmp.path().join("streamed").join(name)).ok();
            assert_eq!(whole, streamed, "{name}");
        }
        assert_eq!(
            Recording::read_dir(&tmp.path().join("streamed")).unwrap(),
            rec
        );
    }

    /// A stream dropped before it finishes leaves the output and its directory as they were.
    #[test]
    fn an_unfinished_stream_leaves_nothing_behind() {
        let tmp = tempfile::tempdir().unwrap();
        let rec = sample_recording();
        rec.write_dir(&tmp.path().join("out")).unwrap();
        let before = fs::read(tmp.path().join("out/lidar.csv")).unwrap();
        {
            let mut stream = RecordingStream::create(
                &tmp.path().join("out"),
                Meta::default(),
                Tables::default(),
            )
            .unwrap();
            stream.command(&rec.commands[0]).unwrap();
            // No lidar table was declared: a lidar sample is an error, and nothing is written.
            assert!(stream.lidar(&rec.lidar.as_ref().unwrap()[0]).is_err());
        }
        assert_eq!(fs::read(tmp.path().join("out/lidar.csv")).unwrap(), before);
        assert_eq!(fs::read_dir(tmp.path()).unwrap().count(), 1);
    }

    /// A true range on some rows only cannot be streamed (its header is already written).
    #[test]
    fn a_true_range_on_some_rows_only_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let mut rec = sample_recording();
        if let Some(lidar) = rec.lidar.as_mut() {
            lidar[2].true_range_m = None;
        }
        let err = stream_out(&rec, &tmp.path().join("out")).unwrap_err();
        assert!(err.to_string().contains("lidar.csv"), "{err}");
        assert!(!tmp.path().join("out").exists());
    }
}
