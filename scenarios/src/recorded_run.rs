//! A run of a scenario with its recording put on disk: streamed as it is taken (the run's
//! memory bounded whatever its length), or, through the serial path, held whole and written
//! after the run; the run's `results.json` beside it.

use std::path::Path;

use hilsim_lidar_emulator::Emulation;
use hilsim_recording::{write_file_atomically, RecordingStream};
use hilsim_sim::Scenario;

use crate::pipeline::{execute, execute_into, Report, RunError, Via};

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
