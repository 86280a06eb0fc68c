//! A firmware-in-the-loop run judged by its scenario's assertions, and how `hilsim hil`
//! shows it (a summary, or one JSON object).

use std::io::{self, Write};

use hilsim_hil::firmware::{describe_status, Ended};
use hilsim_hil::hil_run::{Ending, HilReport};
use hilsim_sim::scenario::Expect;

use crate::metrics::{self, Metrics, Outcome, RunKind};

/// A firmware's run, its metrics and the outcome of each of the scenario's assertions.
pub struct FirmwareRun {
    /// The run.
    pub report: HilReport,
    /// The metrics a firmware's run has.
    pub metrics: Metrics,
    /// Each assertion's outcome.
    pub outcomes: Vec<Outcome>,
}

impl FirmwareRun {
    /// Judges `report` by the assertions `expects`.
    #[must_use]
    pub fn judge(report: HilReport, expects: &[Expect]) -> Self {
        let metrics = metrics::of_hil(&report);
        let outcomes = metrics::check(expects, &metrics, RunKind::FirmwareInTheLoop);
        Self {
            report,
            metrics,
            outcomes,
        }
    }

    /// The metrics of the assertions that failed.
    #[must_use]
    pub fn failed(&self) -> Vec<&str> {
        let failed = self.outcomes.iter().filter(|o| !o.passed);
        failed.map(|o| o.metric.as_str()).collect()
    }

    /// The run ended on time or the firmware exited, and every assertion held.
    #[must_use]
    pub fn passed(&self) -> bool {
        matches!(self.report.ending, Ending::TimeUp | Ending::FirmwareExited)
            && self.outcomes.iter().all(|o| o.passed)
    }

    /// `hilsim hil --json`'s object: how the run ended, its metrics and assertions, the stream
    /// and the firmware.
    #[must_use]
    pub fn to_json(&self) -> serde_json::Value {
        let report = &self.report;
        let ending = match &report.ending {
            Ending::TimeUp => "time_up",
            Ending::FirmwareExited => "firmware_exited",
            Ending::Fault(_) => "fault",
            Ending::Stopped => "stopped",
        };
        let firmware = report.firmware.as_ref().map(|f| {
            let escaped = f
                .escaped
                .iter()
                .map(|p| serde_json::json!({"pid": p.pid, "command": p.command}));
            serde_json::json!({
                "status": describe_status(f.status),
                "exit_code": f.status.code(),
                "ended": match f.ended {
                    Ended::ByItself => "by_itself",
                    Ended::Terminated => "terminated",
                    Ended::Killed => "killed",
                },
                "shrugged_off_sigterm": f.shrugged_off_sigterm,
                "escaped": escaped.collect::<Vec<_>>(),
            })
        });
        let s = &report.stream;
        serde_json::json!({
            "ending": ending,
            "fault": report.fault().map(ToString::to_string),
            "ended_at_s": report.ended_at_s,
            "simulated_s": report.simulated_s,
            "passed": self.passed(),
            "metrics": self.metrics,
            "expectations": self.outcomes,
            "stream": {
                "revolutions_sent": s.revolutions_sent,
                "revolutions_dropped": s.revolutions_dropped,
                "bytes_written": s.bytes_written,
                "lidar_bytes_read": report.lidar_bytes_read,
            },
            "link_faults": report.link_faults,
            "firmware": firmware,
        })
    }

    /// `hilsim hil`'s summary: the run's, each assertion, and which failed.
    ///
    /// # Errors
    /// Writing to `w` failed.
    pub fn write_summary(&self, w: &mut dyn Write) -> io::Result<()> {
        w.write_all(self.report.summary().as_bytes())?;
        for outcome in &self.outcomes {
            writeln!(w, "  {}", outcome.describe())?;
        }
        let failed = self.failed();
        if !failed.is_empty() {
            writeln!(
                w,
                "{} of {} assertion(s) failed: {}",
                failed.len(),
                self.outcomes.len(),
                failed.join(", ")
            )?;
        }
        Ok(())
    }
}
