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
/// use hilsim_dataset::{Plan, Progress, RunReport};
/// #[derive(Default)]
/// struct Count(u64);
/// impl Progress for Count {
///     fn run_finished(&mut self, _run: &RunReport) {
///         self.0 += 1;
///     }
/// }
/// let mut count = Count::default();
/// count.planned(&Plan { share: 1, skipped: 0, to_make: 1, jobs: 1 });
/// # let _ = &mut count;
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
