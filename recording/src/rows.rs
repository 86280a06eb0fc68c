//! A recording directory read one row at a time, so that a command that passes over a recording
//! (an export, a report) holds a few rows of each table, not the recording: its memory is the
//! same whatever the recording's length.

use std::convert::Infallible;
use std::path::{Path, PathBuf};

use crate::csv::{read_table, Header, Parse, TableRows};
use crate::input;
use crate::read::{self, is_present};
use crate::{
    CommandSample, Error, LidarSample, Meta, OdometrySample, SampleSink, SonarSample, Tables,
    TruthSample,
};

/// A recording directory whose tables are read as streams.
///
/// ```
/// use hilsim_recording::{CommandSample, Meta, Recording, RecordingDir};
/// let mut rec = Recording::new(Meta::default());
/// rec.commands.push(CommandSample { t_s: 0.0, left_mps: 0.1, right_mps: 0.1 });
/// let dir = tempfile::tempdir().unwrap();
/// rec.write_dir(&dir.path().join("run")).unwrap();
/// let run = RecordingDir::open(&dir.path().join("run")).unwrap();
/// run.check(&mut Recording::default()).unwrap();
/// let commands: Vec<_> = run.commands().unwrap().collect::<Result<_, _>>().unwrap();
/// assert_eq!(commands, rec.commands);
/// assert!(run.lidar().unwrap().is_none());
/// ```
#[derive(Debug, Clone)]
pub struct RecordingDir {
    path: PathBuf,
    /// The directory's device and inode when opened.
    identity: (u64, u64),
    meta: Meta,
    tables: Tables,
}

impl RecordingDir {
    /// Opens a recording directory: reads its `meta.toml` and sees which tables it has. The
    /// tables are not read: [`RecordingDir::check`] reads them as [`crate::Recording::read_dir`]
    /// does.
    ///
    /// # Errors
    /// Not a directory, or its `meta.toml` is missing or not valid (as `read_dir` says).
    pub fn open(dir: &Path) -> Result<Self, Error> {
        if !dir.is_dir() {
            return Err(Error::format(dir, None, "not a recording directory"));
        }
        let identity = input::dir_identity(dir)?;
        let meta = read::read_meta(&dir.join("meta.toml"))?;
        let present = |name: &str| is_present(&dir.join(name));
        Ok(Self {
            path: dir.to_path_buf(),
            identity,
            meta,
            tables: Tables {
                odometry: present("odometry.csv"),
                lidar: present("lidar.csv"),
                sonar: present("sonar.csv"),
                truth: present("truth.csv"),
            },
        })
    }

    /// The directory.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Its `meta.toml`.
    #[must_use]
    pub fn meta(&self) -> &Meta {
        &self.meta
    }

    /// Which optional tables it has.
    #[must_use]
    pub fn tables(&self) -> Tables {
        self.tables
    }

    /// Reads every table whole, in the order and with the errors of
    /// [`crate::Recording::read_dir`] (a file's error is the one a reader of the whole file finds
    /// first), handing each sample to `sink`: the commands, then the odometry, lidar, sonar and
    /// truth, each table in time order. One line is held at a time.
    ///
    /// # Errors
    /// The first malformed file, naming it and the line.
    pub fn check(&self, sink: &mut impl SampleSink<Error = Infallible>) -> Result<(), Error> {
        let path = |name: &str| self.path.join(name);
        let ok = |result: Result<(), Infallible>| match result {
            Ok(()) => (),
            Err(never) => match never {},
        };
        read_table(&path("commands.csv"), read::commands, |c| {
            ok(sink.command(&c));
        })?;
        if self.tables.odometry {
            read_table(&path("odometry.csv"), read::odometry, |o| {
                ok(sink.odometry(&o));
            })?;
        }
        if self.tables.lidar {
            read_table(&path("lidar.csv"), read::lidar, |r| ok(sink.lidar(&r)))?;
        }
        if self.tables.sonar {
            read_table(&path("sonar.csv"), read::sonar, |s| ok(sink.sonar(&s)))?;
        }
        if self.tables.truth {
            read_table(&path("truth.csv"), read::truth, |p| ok(sink.truth(&p)))?;
        }
        self.still_the_same()
    }

    /// `commands.csv`, one row at a time.
    ///
    /// # Errors
    /// The file cannot be opened, or its header lacks a column.
    pub fn commands(&self) -> Result<Rows<CommandSample>, Error> {
        let rows = Rows::open(&self.path.join("commands.csv"), read::commands)?;
        self.still_the_same()?;
        Ok(rows)
    }

    /// `odometry.csv`, one row at a time; `None` without one.
    ///
    /// # Errors
    /// As [`RecordingDir::commands`].
    pub fn odometry(&self) -> Result<Option<Rows<OdometrySample>>, Error> {
        self.optional(self.tables.odometry, "odometry.csv", read::odometry)
    }

    /// `lidar.csv`, one row at a time; `None` without one.
    ///
    /// # Errors
    /// As [`RecordingDir::commands`].
    pub fn lidar(&self) -> Result<Option<Rows<LidarSample>>, Error> {
        self.optional(self.tables.lidar, "lidar.csv", read::lidar)
    }

    /// `sonar.csv`, one row at a time; `None` without one.
    ///
    /// # Errors
    /// As [`RecordingDir::commands`].
    pub fn sonar(&self) -> Result<Option<Rows<SonarSample>>, Error> {
        self.optional(self.tables.sonar, "sonar.csv", read::sonar)
    }

    /// `truth.csv`, one row at a time; `None` without one.
    ///
    /// # Errors
    /// As [`RecordingDir::commands`].
    pub fn truth(&self) -> Result<Option<Rows<TruthSample>>, Error> {
        self.optional(self.tables.truth, "truth.csv", read::truth)
    }

    fn optional<T>(
        &self,
        present: bool,
        name: &str,
        parse: fn(&Header) -> Result<Parse<T>, Error>,
    ) -> Result<Option<Rows<T>>, Error> {
        let rows = present
            .then(|| Rows::open(&self.path.join(name), parse))
            .transpose()?;
        self.still_the_same()?;
        Ok(rows)
    }

    /// Refuses to go on when the directory is no longer the one opened: a table opened after
    /// another recording was put in its place would be that recording's.
    fn still_the_same(&self) -> Result<(), Error> {
        input::check_same_dir(&self.path, self.identity)
    }
}

/// A table's samples in the file's order, read one line at a time: each row's sample, or the
/// first error met on the way (a line that is not UTF-8, a row of the wrong width, a value out of
/// its range, time going backwards), after which it ends. [`RecordingDir::check`] first gives the
/// error `read_dir` would.
pub struct Rows<T>(TableRows<T>);

impl<T> Rows<T> {
    fn open(path: &Path, parse: fn(&Header) -> Result<Parse<T>, Error>) -> Result<Self, Error> {
        TableRows::open(path, parse).map(Self)
    }
}

impl<T> Iterator for Rows<T> {
    type Item = Result<T, Error>;

    fn next(&mut self) -> Option<Self::Item> {
        self.0.next()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Recording;
    use std::fs;

    fn minimal(dir: &Path) {
        fs::write(
            dir.join("meta.toml"),
            "format = \"hilsim-recording/1\"\n[robot]\nwheel_base_m = 0.23\n",
        )
        .unwrap();
        fs::write(
            dir.join("commands.csv"),
            "t_s,left_mps,right_mps\n0,0.1,0.1\n",
        )
        .unwrap();
    }

    #[test]
    fn rows_are_the_samples_read_dir_reads() {
        let dir = tempfile::tempdir().unwrap();
        minimal(dir.path());
        fs::write(
            dir.path().join("sonar.csv"),
            "t_s,range_m\n\n0.0,1.0\n0.1, 1.5 \n",
        )
        .unwrap();
        let whole = Recording::read_dir(dir.path()).unwrap();
        let run = RecordingDir::open(dir.path()).unwrap();
        let mut checked = Recording::default();
        run.check(&mut checked).unwrap();
        assert_eq!(checked.sonar, whole.sonar);
        let sonar: Vec<_> = run.sonar().unwrap().unwrap().map(Result::unwrap).collect();
        assert_eq!(Some(sonar), whole.sonar);
        assert!(run.lidar().unwrap().is_none() && !run.tables().lidar);
    }

    /// `check` gives the error a reader of the whole file finds first (a row of the wrong width
    /// before an earlier bad value); the rows end at the first error on the way.
    #[test]
    fn check_gives_read_dirs_error_and_rows_the_first_on_the_way() {
        let dir = tempfile::tempdir().unwrap();
        minimal(dir.path());
        fs::write(
            dir.path().join("sonar.csv"),
            "t_s,range_m\n0,1\n0,abc\n0.1\n",
        )
        .unwrap();
        let whole = Recording::read_dir(dir.path()).unwrap_err().to_string();
        let run = RecordingDir::open(dir.path()).unwrap();
        let checked = run.check(&mut Recording::default()).unwrap_err();
        assert_eq!(checked.to_string(), whole);
        assert!(whole.ends_with("sonar.csv:4: expected 2 fields (t_s,range_m), found 1"));
        let rows: Vec<_> = run.sonar().unwrap().unwrap().collect();
        assert_eq!(rows.len(), 2, "a sample, an error, the end");
        let err = rows[1].as_ref().unwrap_err().to_string();
        assert!(
            err.ends_with("sonar.csv:3: column `range_m`: expected a finite number, found `abc`"),
            "{err}"
        );
    }

    #[test]
    fn a_recording_replaced_while_it_is_read_is_refused_not_mixed() {
        let dir = tempfile::tempdir().unwrap();
        let run_dir = dir.path().join("run");
        let mut first = Recording::new(crate::Meta::default());
        first.commands.push(CommandSample {
            t_s: 0.0,
            left_mps: 0.1,
            right_mps: 0.1,
        });
        first.write_dir(&run_dir).unwrap();
        let run = RecordingDir::open(&run_dir).unwrap();
        // Another writer puts a new recording in its place before the tables are read.
        let mut second = first.clone();
        second.commands[0].left_mps = 0.2;
        second.write_dir(&run_dir).unwrap();
        let err = run.commands().err().expect("refused").to_string();
        assert!(err.contains("was replaced by another recording"), "{err}");
        let err = run
            .check(&mut Recording::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("was replaced by another recording"), "{err}");
        // Opened anew, it is the new one, whole.
        let again = RecordingDir::open(&run_dir).unwrap();
        let commands: Vec<_> = again.commands().unwrap().collect::<Result<_, _>>().unwrap();
        assert_eq!(commands, second.commands);
    }
}
