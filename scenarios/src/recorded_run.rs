//! A run of a scenario with its recording put on disk: streamed as it is taken (the run's
//! memory bounded whatever its length), or, through the serial path, held whole and written
//! after the run; the run's `results.json` beside it.

use std::io;
use std::path::{Path, PathBuf};

use hilsim_lidar_emulator::Emulation;
use hilsim_recording::{write_file_atomically, RecordingStream};
use hilsim_sim::Scenario;

use crate::pipeline::{execute, execute_into, Report, RunError, Via};

/// Where a run's recording goes as it is taken: to the recording directory asked for, or, for
/// an MCAP file alone, to a temporary directory beside it (removed when this is dropped), so
/// that the run's memory is bounded whatever its length; nowhere through the serial path, whose
/// run is held whole and written from memory.
pub struct StreamTarget {
    // Held only to be removed when dropped.
    _scratch: Option<tempfile::TempDir>,
    dir: Option<PathBuf>,
}

impl StreamTarget {
    /// The target of a run by `via` asked to write the recording to `out` and an MCAP file to
    /// `mcap`.
    ///
    /// # Errors
    /// The temporary directory cannot be made (naming where).
    pub fn new(via: Via, out: Option<&Path>, mcap: Option<&Path>) -> io::Result<Self> {
        let scratch = match (out, mcap, via) {
            (None, Some(mcap), Via::Memory) => Some(scratch_dir(mcap)?),
            _ => None,
        };
        let dir = match via {
            Via::Memory => out
                .map(Path::to_path_buf)
                .or_else(|| scratch.as_ref().map(|s| s.path().join("recording"))),
            Via::Serial => None,
        };
        Ok(Self {
            _scratch: scratch,
            dir,
        })
    }

    /// The directory the recording is streamed to, if any.
    #[must_use]
    pub fn dir(&self) -> Option<&Path> {
        self.dir.as_deref()
    }
}

/// A temporary directory beside `mcap` (the same file system, removed when dropped) for the
/// recording an MCAP file is exported from.
fn scratch_dir(mcap: &Path) -> io::Result<tempfile::TempDir> {
    let parent = mcap
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    // Standard output or a device has no directory of its own to put it beside.
    let parent = if parent.starts_with("/dev") || parent.starts_with("/proc") {
        std::env::temp_dir()
    } else {
        parent.to_path_buf()
    };
    tempfile::Builder::new()
        .prefix(".hilsim-run.")
        .tempdir_in(&parent)
        .map_err(|e| {
            let why = format!(
                "{}: cannot make a temporary directory: {e}",
                parent.display()
            );
            io::Error::new(e.kind(), why)
        })
}

/// A run whose recording is not yet in place: [`RecordedRun::finish`] puts it there.
pub struct RecordedRun {
    /// The run.
    pub report: Report,
    stream: Option<RecordingStream>,
}

impl RecordedRun {
    /// Runs `scenario` as [`execute`] does, every sample written as it is taken into a
    /// recording at `streamed_to` when given (then left in a temporary directory beside it
    /// until [`RecordedRun::finish`]).
    ///
    /// # Errors
    /// As [`execute`]; the recording cannot be created.
    pub fn execute(
        scenario: Scenario,
        origin: &str,
        via: Via,
        streamed_to: Option<&Path>,
    ) -> Result<Self, RunError> {
        let Some(dir) = streamed_to else {
            let report = execute(scenario, origin, via)?;
            return Ok(Self {
                report,
                stream: None,
            });
        };
        let emulation =
            Emulation::new(&scenario, scenario.seed).map_err(|e| RunError::SensorModel {
                origin: origin.to_string(),
                message: e.to_string(),
            })?;
        let mut stream = RecordingStream::create(dir, emulation.meta().clone(), emulation.tables())
            .map_err(|e| RunError::Output(e.to_string()))?;
        drop(emulation);
        let report = execute_into(scenario, origin, via, &mut stream)?;
        Ok(Self {
            report,
            stream: Some(stream),
        })
    }

    /// Puts the recording in place: a streamed one where it was streamed to, with `results`
    /// as its `results.json` when `out` is given; a run held whole into `out`, when given.
    ///
    /// # Errors
    /// A file cannot be written, naming it.
    pub fn finish(
        self,
        out: Option<&Path>,
        results: &str,
    ) -> Result<Report, hilsim_recording::Error> {
        let add_results =
            |tmp: &Path| write_file_atomically(&tmp.join("results.json"), results.as_bytes());
        match (self.stream, out) {
            (Some(stream), Some(_)) => stream.finish_with(add_results)?,
            (Some(stream), None) => stream.finish()?,
            (None, Some(dir)) => hilsim_recording::replace_recording_dir(dir, |tmp| {
                self.report.run.recording.write_files(tmp)?;
                add_results(tmp)
            })?,
            (None, None) => {}
        }
        Ok(self.report)
    }
}

impl Via {
    /// Checks that `scenario`'s lidar can take this path: the serial path reads the Neato
    /// XV-11's wire only. `origin` names the scenario.
    ///
    /// # Errors
    /// The serial path for another unit.
    pub fn check(self, scenario: &Scenario, origin: &str) -> Result<(), RunError> {
        let lidar = scenario.sensors.lidar.as_ref();
        let model = lidar.map(|l| l.model).unwrap_or_default();
        if self == Via::Serial && model != hilsim_sim::scenario::LidarModel::Xv11 {
            return Err(RunError::SerialNeedsXv11 {
                origin: origin.to_string(),
                model,
            });
        }
        Ok(())
    }
}

impl Report {
    /// The run's report page (`index.html`), the scenario named by `origin`.
    #[must_use]
    pub fn page(&self, origin: &str) -> String {
        let title = format!("hilsim run: {}", self.scenario.name);
        let name = format!("{origin} (seed {}, in memory)", self.scenario.seed);
        hilsim_report::render(hilsim_report::Inputs {
            title: &title,
            recording: &self.run.recording,
            recording_name: &hilsim_report::drawn_name(&name, &self.thinning),
            scenario: Some(&self.scenario),
            calibrations: &self.calibrations,
            truth_estimated: false,
        })
    }
}
