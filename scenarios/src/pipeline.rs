//! One scenario end to end: emulate, calibrate with its methods, measure, check.

use hilsim_calibrator::{Calibration, SampleOptions};
use hilsim_lidar_emulator::{Emulation, Run};
use hilsim_sim::Scenario;

use crate::metrics::{self, Metrics, Outcome};

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
    /// The run's worker stopped before it finished (a bug: it panicked).
    #[error("{0}: the run did not finish")]
    Unfinished(String),
}

/// Everything one run of a scenario produced.
#[derive(Debug)]
pub struct Report {
    /// The scenario as run.
    pub scenario: Scenario,
    /// The emulation's output: the recording, the collisions.
    pub run: Run,
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
    let emulation =
        Emulation::new(&scenario, scenario.seed).map_err(|e| RunError::SensorModel {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
    let run = match via {
        Via::Memory => emulation.run(),
        Via::Serial => {
            hilsim_hil::loopback::run_through_pty(emulation)
                .map_err(|e| RunError::Serial(e.to_string()))?
                .0
        }
    };
    let mut metrics = metrics::of_run(&run);
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
