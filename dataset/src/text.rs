//! How a dataset's progress and summaries read, as `hilsim dataset` prints them.

use std::fmt;
use std::path::Path;

use crate::{MergeSummary, Plan, RunReport, Summary};

impl fmt::Display for Plan {
    /// What this call will do, one line.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} runs in this share: {} made before, {} to make on {} thread(s)",
            self.share, self.skipped, self.to_make, self.jobs
        )?;
        if self.remade > 0 {
            write!(
                f,
                " ({} of them made before but damaged since: their files differ from the \
                 manifest's hash)",
                self.remade
            )?;
        }
        Ok(())
    }
}

impl RunReport {
    /// The run's line, the `done`th of `planned`: its directory, its seed and how it went.
    #[must_use]
    pub fn line(&self, done: u64, planned: u64) -> String {
        let name = crate::layout::run_dir_name(self.run);
        let status = match &self.failure {
            None => format!("made in {:.2} s", self.elapsed.as_secs_f64()),
            Some(reason) => format!("failed: {reason}"),
        };
        format!("[{done}/{planned}] {name} (seed {}) {status}", self.seed)
    }
}

impl Summary {
    /// The summary line of the dataset made in `dir`.
    #[must_use]
    pub fn line(&self, dir: &Path) -> String {
        format!(
            "dataset {}: {} made, {} skipped (made before), {} failed, in {:.1} s ({:.2} runs/s); \
             manifest {}",
            dir.display(),
            self.made,
            self.skipped,
            self.failed,
            self.elapsed.as_secs_f64(),
            self.runs_per_s(),
            self.manifest.display()
        )
    }
}

impl MergeSummary {
    /// The summary line of the dataset merged into `out`.
    #[must_use]
    pub fn line(&self, out: &Path) -> String {
        format!(
            "merged {}: {} runs: {} made, {} failed, {} missing ({} run directories brought \
             in); manifest {}",
            out.display(),
            self.runs,
            self.made,
            self.failed,
            self.missing,
            self.copied,
            self.manifest.display()
        )
    }
}
