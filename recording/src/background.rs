//! A [`RecordingStream`] on a thread of its own, so that formatting and writing the CSV text
//! (half of `hilsim record`'s work) runs beside the simulation instead of after each step.
//! Samples cross in batches through a bounded channel: memory stays flat in the run's length.

use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::thread::JoinHandle;

use crate::{
    CommandSample, Error, LidarSample, OdometrySample, RecordingStream, SampleSink, SonarSample,
    TruthSample,
};

/// Samples per batch: a lidar revolution is 360, a second of a run about 2,000.
const BATCH: usize = 4096;
/// Batches in flight: with the one being filled and the one being written, at most four batches
/// (about 300 KiB) are held whatever the run's length.
const IN_FLIGHT: usize = 2;

/// One sample of any table, in the order the simulation took it.
#[derive(Debug, Clone, Copy)]
enum Sample {
    Command(CommandSample),
    Odometry(OdometrySample),
    Lidar(LidarSample),
    Sonar(SonarSample),
    Truth(TruthSample),
}

/// A [`SampleSink`] that hands its samples to a [`RecordingStream`] written by another thread.
/// [`BackgroundStream::finish`] puts the recording in place; dropped unfinished, it leaves the
/// output as it was (as the stream does).
pub struct BackgroundStream {
    batch: Vec<Sample>,
    to_writer: Option<SyncSender<Vec<Sample>>>,
    writer: Option<JoinHandle<Result<RecordingStream, Error>>>,
}

impl BackgroundStream {
    /// Writes `stream` on a new thread.
    ///
    /// # Errors
    /// The thread cannot be started.
    pub fn spawn(stream: RecordingStream) -> Result<Self, Error> {
        let (to_writer, batches) = sync_channel(IN_FLIGHT);
        let path = stream.dir().to_path_buf();
        let writer = std::thread::Builder::new()
            .name("recording writer".into())
            .spawn(move || write_batches(stream, &batches))
            .map_err(|err| Error::io(&path, err))?;
        Ok(Self {
            batch: Vec::with_capacity(BATCH),
            to_writer: Some(to_writer),
            writer: Some(writer),
        })
    }

    fn push(&mut self, sample: Sample) -> Result<(), Error> {
        self.batch.push(sample);
        if self.batch.len() < BATCH {
            return Ok(());
        }
        let full = std::mem::replace(&mut self.batch, Vec::with_capacity(BATCH));
        let sent = self.to_writer.as_ref().map(|to| to.send(full));
        match sent {
            Some(Ok(())) => Ok(()),
            // The writer stopped: its error says why.
            _ => Err(self.join().err().unwrap_or_else(writer_gone)),
        }
    }

    /// Ends the channel and waits for the writer: the stream, or the writer's first error.
    fn join(&mut self) -> Result<RecordingStream, Error> {
        self.to_writer = None;
        let writer = self.writer.take().ok_or_else(writer_gone)?;
        writer.join().map_err(|_| writer_gone())?
    }

    /// Writes what is left, completes every file and puts the recording in place
    /// ([`RecordingStream::finish`]).
    ///
    /// # Errors
    /// An I/O error naming the file.
    pub fn finish(mut self) -> Result<(), Error> {
        let rest = std::mem::take(&mut self.batch);
        if let Some(to) = &self.to_writer {
            // A closed channel means the writer failed: `join` returns its error.
            let _ = to.send(rest);
        }
        self.join()?.finish()
    }
}

impl Drop for BackgroundStream {
    fn drop(&mut self) {
        // Unfinished: the writer ends and its stream, dropped, removes what it wrote.
        self.to_writer = None;
        if let Some(writer) = self.writer.take() {
            let _ = writer.join();
        }
    }
}

fn writer_gone() -> Error {
    Error::io(
        std::path::Path::new("recording writer"),
        std::io::Error::other("the writing thread ended unexpectedly"),
    )
}

/// The writer thread: every batch into `stream`, in order, until the channel closes.
fn write_batches(
    mut stream: RecordingStream,
    batches: &Receiver<Vec<Sample>>,
) -> Result<RecordingStream, Error> {
    for batch in batches {
        for sample in batch {
            match sample {
                Sample::Command(c) => stream.command(&c)?,
                Sample::Odometry(o) => stream.odometry(&o)?,
                Sample::Lidar(r) => stream.lidar(&r)?,
                Sample::Sonar(s) => stream.sonar(&s)?,
                Sample::Truth(p) => stream.truth(&p)?,
            }
        }
    }
    Ok(stream)
}

impl SampleSink for BackgroundStream {
    type Error = Error;

    fn command(&mut self, c: &CommandSample) -> Result<(), Error> {
        self.push(Sample::Command(*c))
    }
    fn odometry(&mut self, o: &OdometrySample) -> Result<(), Error> {
        self.push(Sample::Odometry(*o))
    }
    fn lidar(&mut self, r: &LidarSample) -> Result<(), Error> {
        self.push(Sample::Lidar(*r))
    }
    fn sonar(&mut self, s: &SonarSample) -> Result<(), Error> {
        self.push(Sample::Sonar(*s))
    }
    fn truth(&mut self, p: &TruthSample) -> Result<(), Error> {
        self.push(Sample::Truth(*p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Meta, Recording, Tables};
    use std::fs;

    fn samples(n: usize) -> Recording {
        let mut rec = Recording::new(Meta::default());
        rec.commands = vec![CommandSample {
            t_s: 0.0,
            left_mps: 0.1,
            right_mps: 0.1,
        }];
        rec.lidar = Some(
            (0..n)
                .map(|i| LidarSample {
                    t_s: i as f64 * 0.000_555,
                    rev: (i / 360) as u64,
                    angle_deg: (i % 360) as f64,
                    range_m: 1.0 + (i % 7) as f64 * 0.125,
                    strength: 40,
                    invalid: i % 11 == 0,
                    warning: false,
                    true_range_m: Some(1.0),
                })
                .collect(),
        );
        rec.truth = Some(
            (0..n / 10)
                .map(|i| TruthSample {
                    t_s: i as f64 * 0.01,
                    x_m: 0.5,
                    y_m: 0.0,
                    yaw_rad: 0.1,
                })
                .collect(),
        );
        rec
    }

    fn tables(rec: &Recording) -> Tables {
        Tables {
            odometry: rec.odometry.is_some(),
            lidar: rec.lidar.is_some(),
            sonar: rec.sonar.is_some(),
            truth: rec.truth.is_some(),
        }
    }

    /// Many batches, interleaved tables: the same bytes as the whole-table writer.
    #[test]
    fn a_recording_written_in_the_background_equals_the_written_one() {
        let tmp = tempfile::tempdir().unwrap();
        let rec = samples(3 * BATCH + 17);
        rec.write_dir(&tmp.path().join("whole")).unwrap();
        let out = tmp.path().join("background");
        let stream = RecordingStream::create(&out, rec.meta.clone(), tables(&rec)).unwrap();
        let mut sink = BackgroundStream::spawn(stream).unwrap();
        sink.command(&rec.commands[0]).unwrap();
        let truth = rec.truth.as_ref().unwrap();
        for (i, r) in rec.lidar.as_ref().unwrap().iter().enumerate() {
            sink.lidar(r).unwrap();
            if i % 10 == 9 {
                sink.truth(&truth[i / 10]).unwrap();
            }
        }
        sink.finish().unwrap();
        for name in Recording::FILES {
            let whole = fs::read(tmp.path().join("whole").join(name)).ok();
            let background = fs::read(out.join(name)).ok();
            assert_eq!(whole, background, "{name}");
        }
    }

    /// The writer's error reaches the simulation's side, and nothing is left behind.
    #[test]
    fn a_writer_error_stops_the_run_and_leaves_nothing() {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("out");
        // No lidar table declared: the writer refuses the first lidar sample.
        let stream = RecordingStream::create(&out, Meta::default(), Tables::default()).unwrap();
        let mut sink = BackgroundStream::spawn(stream).unwrap();
        let rec = samples(4 * BATCH);
        let err = rec
            .lidar
            .as_ref()
            .unwrap()
            .iter()
            .try_for_each(|r| sink.lidar(r))
            .unwrap_err();
        assert!(err.to_string().contains("lidar.csv"), "{err}");
        drop(sink);
        assert_eq!(fs::read_dir(tmp.path()).unwrap().count(), 0);
    }

    /// Dropped unfinished: the output is as it was.
    #[test]
    fn an_unfinished_background_stream_leaves_nothing() {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("out");
        let rec = samples(2 * BATCH);
        let stream = RecordingStream::create(&out, rec.meta.clone(), tables(&rec)).unwrap();
        let mut sink = BackgroundStream::spawn(stream).unwrap();
        for r in rec.lidar.as_ref().unwrap() {
            sink.lidar(r).unwrap();
        }
        drop(sink);
        assert_eq!(fs::read_dir(tmp.path()).unwrap().count(), 0);
    }
}
