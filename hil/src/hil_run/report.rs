//! What a run did and why it ended.

use std::fmt;
use std::process::ExitStatus;
use std::time::Duration;

use hilsim_lidar_emulator::Run;

use super::config::FloodLimits;
use crate::command_port::CommandStats;
use crate::firmware::{describe_status, FirmwareExit, StderrTail};
use crate::streamer::StreamStats;

/// A firmware fault: the run failed its check.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Fault {
    /// The firmware exited with a non-zero status or was killed by a signal.
    Crashed(ExitStatus),
    /// No request for the watchdog period.
    Hung {
        /// The watchdog period.
        watchdog: Duration,
    },
    /// Too much sent within a second.
    Flooded {
        /// Bytes received in the last second.
        bytes: u64,
        /// Requests received in the last second.
        commands: u64,
        /// The limits exceeded.
        limits: FloodLimits,
    },
    /// Less than one revolution of the lidar stream read.
    LidarNeverRead {
        /// Bytes the firmware took from the lidar port.
        bytes_read: u64,
        /// Bytes written to it.
        bytes_written: u64,
    },
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Crashed(status) => {
                write!(f, "the firmware crashed: {}", describe_status(*status))
            }
            Self::Hung { watchdog } => write!(
                f,
                "the firmware hung: no request on the robot port for {:.1} s (the watchdog)",
                watchdog.as_secs_f64()
            ),
            Self::Flooded {
                bytes,
                commands,
                limits,
            } => write!(
                f,
                "the firmware flooded the robot port: {bytes} bytes and {commands} requests in \
                 one second (limits: {} bytes/s, the line rate of 115200 8N1, and {} requests/s)",
                limits.bytes_per_s, limits.commands_per_s
            ),
            Self::LidarNeverRead {
                bytes_written: 0, ..
            } => f.write_str(
                "the firmware never started the lidar: the unit waits for its start command and \
                 sent nothing",
            ),
            Self::LidarNeverRead {
                bytes_read,
                bytes_written,
            } => write!(
                f,
                "the firmware never read the lidar port: it took {bytes_read} of the \
                 {bytes_written} bytes streamed (less than one revolution); the rest was discarded"
            ),
        }
    }
}

/// Why the run ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Ending {
    /// The run's time was up.
    TimeUp,
    /// The firmware exited with status 0.
    FirmwareExited,
    /// A firmware fault.
    Fault(Fault),
    /// The caller's stop flag was raised (Ctrl-C).
    Stopped,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct HilReport {
    /// Why it ended.
    pub ending: Ending,
    /// When it ended, seconds from the start.
    pub ended_at_s: f64,
    /// Simulated seconds (the last physics step may end up to one step after `ended_at_s`).
    pub simulated_s: f64,
    /// The recording (truth included; the commands as the motion controller issued them) and
    /// the collisions.
    pub run: Run,
    /// The command port's counts.
    pub commands: CommandStats,
    /// Replies dropped because the firmware did not read the earlier ones.
    pub replies_dropped: u64,
    /// The lidar stream's counts.
    pub stream: StreamStats,
    /// What the scenario's `[link]` faults did to the stream (`None`: it has none).
    pub link_faults: Option<crate::faults::FaultCounts>,
    /// Bytes of the lidar stream the firmware took (`None` without a lidar).
    pub lidar_bytes_read: Option<u64>,
    /// How late the latest physics step was computed after its start time: real-time health.
    pub max_step_lateness: Duration,
    /// How the firmware ended (`None`: the run had none).
    pub firmware: Option<FirmwareExit>,
    /// The end of the firmware's stderr.
    pub stderr: StderrTail,
}

impl HilReport {
    /// The fault, if the run ended on one.
    #[must_use]
    pub fn fault(&self) -> Option<&Fault> {
        match &self.ending {
            Ending::Fault(fault) => Some(fault),
            _ => None,
        }
    }
}
