//! One scenario end to end: emulate, calibrate with its methods, measure, check.

use hilsim_calibrator::{Calibration, SampleOptions};
use hilsim_lidar_emulator::{Emulation, Run};
use hilsim_sim::Scenario;

use crate::metrics::{self, Metrics, Outcome, RunMetrics};
use hilsim_recording::{
    CommandSample, LidarSample, OdometrySample, SampleSink, SonarSample, ThinnedSink, Thinning,
    TruthSample, MAX_ROWS_HELD,
};

/// Takes every sample nowhere (a run that writes no recording).
struct Discard;

impl SampleSink for Discard {
    type Error = std::convert::Infallible;
    fn command(&mut self, _: &CommandSample) -> Result<(), Self::Error> {
        Ok(())
    }
    fn odometry(&mut self, _: &OdometrySample) -> Result<(), Self::Error> {
        Ok(())
    }
    fn lidar(&mut self, _: &LidarSample) -> Result<(), Self::Error> {
        Ok(())
    }
    fn sonar(&mut self, _: &SonarSample) -> Result<(), Self::Error> {
        Ok(())
    }
    fn truth(&mut self, _: &TruthSample) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// Every sample to the metrics, to the part of the recording kept, and to `also`.
struct Tee<'a, S> {
    metrics: RunMetrics,
    kept: ThinnedSink,
    also: &'a mut S,
}

impl<S: SampleSink> SampleSink for Tee<'_, S> {
    type Error = S::Error;
    fn command(&mut self, c: &CommandSample) -> Result<(), Self::Error> {
        let (Ok(()), Ok(())) = (self.metrics.command(c), self.kept.command(c));
        self.also.command(c)
    }
    fn odometry(&mut self, o: &OdometrySample) -> Result<(), Self::Error> {
        let (Ok(()), Ok(())) = (self.metrics.odometry(o), self.kept.odometry(o));
        self.also.odometry(o)
    }
    fn lidar(&mut self, r: &LidarSample) -> Result<(), Self::Error> {
        let (Ok(()), Ok(())) = (self.metrics.lidar(r), self.kept.lidar(r));
        self.also.lidar(r)
    }
    fn sonar(&mut self, p: &SonarSample) -> Result<(), Self::Error> {
        let (Ok(()), Ok(())) = (self.metrics.sonar(p), self.kept.sonar(p));
        self.also.sonar(p)
    }
    fn truth(&mut self, p: &TruthSample) -> Result<(), Self::Error> {
        let (Ok(()), Ok(())) = (self.metrics.truth(p), self.kept.truth(p));
        self.also.truth(p)
    }
}

/// How the lidar's data reaches the metrics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Via {
    /// In-process, as the emulator produced it.
    #[default]
    Memory,
    /// Encoded as Neato packets through a real pseudo-terminal and decoded again.
    Serial,
}

/// Why a scenario could not be run to the end (a failed assertion is not an error: see
/// [`Report::passed`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// The scenario's sensor models are invalid.
    #[error("{origin}: sensor model: {message}")]
    SensorModel {
        /// The scenario's file (or built-in name).
        origin: String,
        /// Why.
        message: String,
    },
    /// A sample could not be handed on (the recording being written: an I/O error).
    #[error("{0}")]
    Output(String),
    /// The serial path (a pty) failed.
    #[error("the serial path (pty): {0}")]
    Serial(String),
    /// A calibration the scenario asks for failed.
    #[error("{origin}: {method} calibration: {message}")]
    Calibration {
        /// The scenario's file (or built-in name).
        origin: String,
        /// The method's name.
        method: &'static str,
        /// Why.
        message: String,
    },
    /// The serial path was asked for a lidar other than the Neato XV-11.
    #[error(
        "{origin}: `--via serial` reads the Neato XV-11's wire, and the lidar is a {model}: \
         `hilsim serve` streams its protocol"
    )]
    SerialNeedsXv11 {
        /// The scenario's file (or built-in name).
        origin: String,
        /// The scenario's lidar.
        model: hilsim_sim::scenario::LidarModel,
    },
    /// The run's worker stopped before it finished (a bug: it panicked).
    #[error("{0}: the run did not finish")]
    Unfinished(String),
}

/// Everything one run of a scenario produced.
#[derive(Debug)]
pub struct Report {
    /// The scenario as run.
    pub scenario: Scenario,
    /// The emulation's output: the recording (as much of it as is kept: see
    /// [`Report::thinning`]), the collisions.
    pub run: Run,
    /// Which part of the run's recording is kept: the whole of a run within [`MAX_ROWS_HELD`]
    /// rows a table.
    pub thinning: Thinning,
    /// One per method the scenario names, in its order.
    pub calibrations: Vec<Calibration>,
    /// Every metric that could be computed.
    pub metrics: Metrics,
    /// Each `[[expect]]` assertion's outcome, in the scenario's order.
    pub outcomes: Vec<Outcome>,
}

impl Report {
    /// Whether every assertion held.
    #[must_use]
    pub fn passed(&self) -> bool {
        self.outcomes.iter().all(|o| o.passed)
    }
}

/// Simulates, emulates the sensors, calibrates, computes the metrics and checks the
/// assertions; with [`Via::Serial`] the lidar data reaches the metrics through a pty and the
/// decoder. `origin` names the scenario in errors.
///
/// # Errors
/// [`RunError`] when the run cannot be made or a calibration fails.
pub fn execute(scenario: Scenario, origin: &str, via: Via) -> Result<Report, RunError> {
    execute_into(scenario, origin, via, &mut Discard)
}

/// As [`execute`], also handing every sample to `also` as it is taken (to write the recording
/// as it goes). In process, the run's memory is bounded whatever its length: the metrics are
/// taken as the samples arrive, and the calibrations and the report's recording keep at most
/// [`MAX_ROWS_HELD`] rows of a table ([`Report::thinning`] says which part; a run within it is
/// kept whole). Through the serial path the run is held whole.
///
/// # Errors
/// [`RunError`] when the run cannot be made, a calibration fails or `also` refuses a sample.
pub fn execute_into<S>(
    scenario: Scenario,
    origin: &str,
    via: Via,
    also: &mut S,
) -> Result<Report, RunError>
where
    S: SampleSink,
    S::Error: std::fmt::Display,
{
    let emulation =
        Emulation::new(&scenario, scenario.seed).map_err(|e| RunError::SensorModel {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
    let (run, mut metrics, thinning) = match via {
        Via::Memory => {
            let mut sinks = Tee {
                metrics: RunMetrics::default(),
                kept: ThinnedSink::new(emulation.meta().clone(), emulation.tables(), MAX_ROWS_HELD),
                also,
            };
            let collisions = emulation
                .record_into(&mut sinks)
                .map_err(|e| RunError::Output(e.to_string()))?;
            let metrics = sinks.metrics.finish(collisions.len());
            let (recording, thinning) = sinks.kept.finish();
            (
                Run {
                    recording,
                    collisions,
                },
                metrics,
                thinning,
            )
        }
        Via::Serial => {
            let run = hilsim_hil::loopback::run_through_pty(emulation)
                .map_err(|e| RunError::Serial(e.to_string()))?
                .0;
            let metrics = metrics::of_run(&run);
            (run, metrics, Thinning::WHOLE)
        }
    };
    let mut calibrations = Vec::new();
    for &method in &scenario.calibration.methods {
        let calibration =
            hilsim_calibrator::calibrate(&run.recording, method, SampleOptions::default())
                .map_err(|e| RunError::Calibration {
                    origin: origin.to_string(),
                    method: method.name(),
                    message: e.to_string(),
                })?;
        metrics.extend(metrics::of_calibration(&calibration));
        calibrations.push(calibration);
    }
    let outcomes = metrics::check(&scenario.expect, &metrics, metrics::RunKind::Scripted);
    Ok(Report {
        scenario,
        run,
        thinning,
        calibrations,
        metrics,
        outcomes,
    })
}

/// Runs `scenarios` (each with the name errors are reported under) on `workers` threads;
/// the reports come back in the input order.
#[must_use]
pub fn execute_all(
    scenarios: &[(String, Scenario)],
    workers: usize,
) -> Vec<Result<Report, RunError>> {
    let mut slots: Vec<Option<Result<Report, RunError>>> =
        (0..scenarios.len()).map(|_| None).collect();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(&mut slots);
    std::thread::scope(|scope| {
        for _ in 0..workers.clamp(1, scenarios.len().max(1)) {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some((origin, scenario)) = scenarios.get(i) else {
                    break;
                };
                let report = execute(scenario.clone(), origin, Via::Memory);
                if let Ok(mut slots) = results.lock() {
                    slots[i] = Some(report);
                }
            });
        }
    });
    slots
        .into_iter()
        .zip(scenarios)
        .map(|(slot, (origin, _))| {
            slot.unwrap_or_else(|| Err(RunError::Unfinished(origin.clone())))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_measured_as_it_goes_equals_its_recording_measured_whole() {
        let scenario = crate::builtin::straight_board().expect("the built-in scenario");
        let whole = Emulation::new(&scenario, scenario.seed)
            .expect("the emulation")
            .run();
        let report = execute(scenario, "straight-board", Via::Memory).expect("the run");
        assert!(report.thinning.is_whole());
        assert_eq!(report.run.recording, whole.recording);
        let mut expected = metrics::of_run(&whole);
        for c in &report.calibrations {
            expected.extend(metrics::of_calibration(c));
        }
        // To the bit: the sums are taken in the same order.
        assert_eq!(report.metrics, expected);
    }
}
