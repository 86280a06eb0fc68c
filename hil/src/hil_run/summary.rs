//! A hil run's report for people: how it ended, where the robot went, what the firmware asked and
//! read, and its stderr when it failed.

use std::fmt::Write;

use super::report::{Ending, HilReport};
use crate::firmware::{describe_status, Ended, TERM_GRACE};

impl HilReport {
    /// The summary `hilsim hil` prints.
    #[must_use]
    pub fn summary(&self) -> String {
        let mut out = String::new();
        // Writing to a String cannot fail.
        let _ = self.write_run(&mut out);
        let _ = self.write_firmware(&mut out);
        out
    }

    /// How it ended, the robot's path, the command port.
    fn write_run(&self, out: &mut String) -> std::fmt::Result {
        let at = self.ended_at_s;
        match &self.ending {
            Ending::TimeUp => writeln!(out, "ended: the run's time was up at {at:.2} s")?,
            Ending::FirmwareExited => {
                writeln!(out, "ended: the firmware exited with status 0 at {at:.2} s")?
            }
            Ending::Fault(fault) => writeln!(out, "FAULT at {at:.2} s: {fault}")?,
            Ending::Stopped => writeln!(out, "interrupted at {at:.2} s: the run did not finish")?,
        }
        let rec = &self.run.recording;
        if let Some(truth) = &rec.truth {
            if let (Some(first), Some(last)) = (truth.first(), truth.last()) {
                let path: f64 = truth
                    .windows(2)
                    .map(|w| (w[1].x_m - w[0].x_m).hypot(w[1].y_m - w[0].y_m))
                    .sum();
                writeln!(
                    out,
                    "robot: drove {path:.3} m in {:.2} s simulated, from ({:.3}, {:.3}) to ({:.3}, {:.3}) \
                     heading {:.1}°; {} collision(s)",
                    self.simulated_s,
                    first.x_m,
                    first.y_m,
                    last.x_m,
                    last.y_m,
                    last.yaw_rad.to_degrees(),
                    self.run.collisions.len()
                )?;
            }
        }
        for c in &self.run.collisions {
            writeln!(out, "  {c}")?;
        }
        let c = &self.commands;
        writeln!(
            out,
            "requests: {} (TestMode {}, SetMotor {}, GetMotors {}, GetLDSScan {}, GetSonar {}), \
             {} error(s), {} bytes",
            c.requests,
            c.test_mode,
            c.set_motor,
            c.get_motors,
            c.get_lds_scan,
            c.get_sonar,
            c.errors,
            c.bytes
        )?;
        for error in &c.first_errors {
            writeln!(out, "  error: {error}")?;
        }
        if self.replies_dropped > 0 {
            writeln!(
                out,
                "  {} replies dropped: the firmware did not read the robot port",
                self.replies_dropped
            )?;
        }
        Ok(())
    }

    /// The lidar stream, real-time lateness, the firmware's exit and stderr.
    fn write_firmware(&self, out: &mut String) -> std::fmt::Result {
        if let Some(read) = self.lidar_bytes_read {
            let s = &self.stream;
            write!(
                out,
                "lidar: {} revolutions sent, {} dropped; the firmware read {read} of {} bytes",
                s.revolutions_sent, s.revolutions_dropped, s.bytes_written
            )?;
            if let Some(lateness) = s.lateness_summary() {
                write!(out, "; {lateness}")?;
            }
            writeln!(out)?;
        }
        if let Some(faults) = &self.link_faults {
            writeln!(out, "{}", faults.describe())?;
        }
        writeln!(
            out,
            "real time: physics steps computed at most {:.1} ms late",
            self.max_step_lateness.as_secs_f64() * 1e3
        )?;
        let mut failed = self.fault().is_some();
        if let Some(exit) = &self.firmware {
            let how = match (exit.ended, exit.shrugged_off_sigterm) {
                (Ended::ByItself, false) => "exited by itself".to_string(),
                (Ended::ByItself, true) => {
                    "exited by itself after the SIGTERM it had blocked or ignored".to_string()
                }
                (Ended::Terminated, _) => "left on SIGTERM once the run was over".to_string(),
                (Ended::Killed, true) => {
                    "had SIGTERM blocked or ignored and was killed".to_string()
                }
                (Ended::Killed, false) => format!(
                    "still running {} s after SIGTERM and was killed",
                    TERM_GRACE.as_secs_f64()
                ),
            };
            writeln!(out, "firmware: {how}: {}", describe_status(exit.status))?;
            failed |= exit.ended == Ended::ByItself && !exit.status.success();
            if !exit.escaped.is_empty() {
                let list: Vec<String> = exit.escaped.iter().map(ToString::to_string).collect();
                writeln!(
                    out,
                    "firmware: {} process(es) it started had left its process group and were \
                     still running; killed: {}",
                    exit.escaped.len(),
                    list.join(", ")
                )?;
            }
        }
        let tail = &self.stderr;
        if failed && !tail.lines.is_empty() {
            writeln!(
                out,
                "firmware stderr (last {} of {} lines):",
                tail.lines.len(),
                tail.total
            )?;
            for line in &tail.lines {
                writeln!(out, "  | {line}")?;
            }
        }
        Ok(())
    }
}
