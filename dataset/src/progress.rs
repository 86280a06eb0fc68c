//! How a caller follows a dataset being made: the library prints nothing; it reports through
//! [`Progress`], which the command line implements as a progress bar or plain lines.

use std::time::Duration;

/// What a [`crate::Dataset::generate`] call will do, reported once before any run is made.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Runs in this call's share of the dataset (the shard, or the one `--run`).
    pub share: u64,
    /// Of those, already made (their directories exist): skipped.
    pub skipped: u64,
    /// Of those, to make now.
    pub to_make: u64,
    /// Of those to make, runs made before whose files differed from the content hash their
    /// manifest recorded (truncated, say): removed, to be made again.
    pub remade: u64,
    /// Worker threads.
    pub jobs: usize,
}

/// One run finished (made or failed).
#[derive(Debug, Clone, PartialEq)]
pub struct RunReport {
    /// The run's index.
    pub run: u64,
    /// The run's seed.
    pub seed: u64,
    /// `None` when made; the reason when it failed.
    pub failure: Option<String>,
    /// Wall time the run took.
    pub elapsed: Duration,
}

/// Receives progress. Called on the thread that called `generate`, never concurrently.
///
/// ```
/// use hilsim_dataset::{Progress, RunReport};
/// /// Collects the runs that failed.
/// struct Failures(Vec<u64>);
/// impl Progress for Failures {
///     fn run_finished(&mut self, run: &RunReport) {
///         if run.failure.is_some() {
///             self.0.push(run.run);
///         }
///     }
/// }
/// let mut failures = Failures(Vec::new());
/// failures.run_finished(&RunReport {
///     run: 3,
///     seed: 1,
///     failure: Some("robot.start: inside cylinder 0".into()),
///     elapsed: std::time::Duration::ZERO,
/// });
/// assert_eq!(failures.0, [3]);
/// ```
pub trait Progress {
    /// Once, after the directory was checked and scanned, before any run is made.
    fn planned(&mut self, _plan: &Plan) {}
    /// After each run, in the order they finish.
    fn run_finished(&mut self, _run: &RunReport) {}
}

/// No progress reports.
impl Progress for () {}

/// What a [`crate::Dataset::generate`] call did.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Runs in this call's share.
    pub share: u64,
    /// Runs made now.
    pub made: u64,
    /// Runs already made before (skipped).
    pub skipped: u64,
    /// Runs that failed now (recorded in the manifest with their reasons).
    pub failed: u64,
    /// Wall time of the whole call.
    pub elapsed: Duration,
    /// The manifest written.
    pub manifest: std::path::PathBuf,
}

impl Summary {
    /// Runs attempted per second of wall time (made or failed).
    #[must_use]
    pub fn runs_per_s(&self) -> f64 {
        let s = self.elapsed.as_secs_f64();
        if s > 0.0 {
            (self.made + self.failed) as f64 / s
        } else {
            0.0
        }
    }
}
