//! A firmware-in-the-loop run as `hilsim hil` asks for it, checked whole before a port is opened
//! or the firmware started, so that bad input costs nothing.

use std::fmt;
use std::path::Path;
use std::time::Duration;

use hilsim_hil::firmware::{split_command_line, Firmware, SplitError};
use hilsim_hil::hil_run::{HilConfig, HilPorts, HilWorld};
use hilsim_lidar_emulator::ModelError;
use hilsim_sim::scenario::{ScenarioError, MAX_RUN_S};
use hilsim_sim::Scenario;

/// A firmware run as asked for, unchecked.
#[derive(Debug, Clone, Copy)]
pub struct FirmwareRequest<'a> {
    /// The scenario file.
    pub scenario: &'a Path,
    /// The firmware's command line, split as a shell would.
    pub firmware: &'a str,
    /// The recording directory to write, if any (checked replaceable now rather than after the
    /// run; a missing parent is created when the recording is written).
    pub out: Option<&'a Path>,
    /// The run's length in seconds, overriding the scenario's `duration_s`.
    pub duration_s: Option<f64>,
    /// Seconds without a request before the firmware counts as hung.
    pub watchdog_s: f64,
    /// The seed overriding the scenario's.
    pub seed: Option<u64>,
}

/// A firmware run as checked: nothing opened or started yet.
pub struct FirmwarePlan {
    /// The firmware's command line as words.
    pub argv: Vec<String>,
    /// The firmware's command line on one line, whatever its own line breaks.
    pub command_line: String,
    /// The scenario's file, as shown in messages.
    pub origin: String,
    /// The scenario, its seed and duration overridden as asked.
    pub scenario: Scenario,
    /// The scenario's world and sensors, driven by the firmware.
    pub world: HilWorld,
    /// The run's length and watchdog.
    pub config: HilConfig,
}

/// Why a firmware run cannot be set up.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FirmwarePlanError {
    /// A length of time out of (0, [`MAX_RUN_S`]].
    #[error("{what} must be a number of seconds in (0, {MAX_RUN_S}], got {}", Shown(*.value))]
    Seconds {
        /// The flag or key (prefixed by its file when it is a key).
        what: String,
        /// What was given.
        value: f64,
    },
    /// The firmware's command line does not split into words.
    #[error("--firmware: {0}")]
    Firmware(SplitError),
    /// The scenario file is unreadable or invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The scenario replays a log's run, which a firmware cannot drive.
    #[error(
        "{0}: the scenario replays a log's run (`[robot] path`, `[sensors.lidar] schedule`): \
         under `hil` the firmware drives and the lidar turns as its unit does; `hilsim record` \
         makes the run's twin"
    )]
    Replays(String),
    /// Neither the scenario nor the request gives the run's length.
    #[error("{0}: under `hil` the firmware drives: set `duration_s` or pass --duration")]
    NoDuration(String),
    /// The output directory may not be replaced.
    #[error(transparent)]
    Output(#[from] hilsim_recording::Error),
    /// The firmware cannot be started.
    #[error("--firmware: cannot start `{program}`")]
    Start {
        /// The program.
        program: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A sensor's model makes no sense.
    #[error("{origin}: sensor model")]
    SensorModel {
        /// The scenario's file.
        origin: String,
        /// Why.
        #[source]
        source: ModelError,
    },
}

/// A length as the seconds message shows it: a non-finite one by name.
struct Shown(f64);

impl fmt::Display for Shown {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_finite() {
            write!(f, "{}", self.0)
        } else {
            write!(f, "a non-finite value")
        }
    }
}

impl FirmwarePlan {
    /// Checks `request` in the order a user fixes it: the flags, the firmware's command line,
    /// the scenario, the output, then the sensor models.
    ///
    /// # Errors
    /// The first thing found wrong, naming the flag or the file.
    pub fn new(request: &FirmwareRequest<'_>) -> Result<Self, FirmwarePlanError> {
        if let Some(d) = request.duration_s {
            seconds("--duration", d)?;
        }
        let watchdog = seconds("--watchdog", request.watchdog_s)?;
        let argv = split_command_line(request.firmware).map_err(FirmwarePlanError::Firmware)?;
        let origin = request.scenario.display().to_string();
        let mut scenario = Scenario::load_with_duration(request.scenario, request.duration_s)?;
        scenario.seed = request.seed.unwrap_or(scenario.seed);
        if scenario.files.schedule.is_some() || scenario.files.path.is_some() {
            return Err(FirmwarePlanError::Replays(origin));
        }
        let Some(duration_s) = scenario.duration_s else {
            return Err(FirmwarePlanError::NoDuration(origin));
        };
        let duration = seconds(&format!("{origin}: duration_s"), duration_s)?;
        if let Some(dir) = request.out {
            hilsim_recording::check_replaceable_recording(dir)?;
        }
        let world = HilWorld::new(&scenario, scenario.seed).map_err(|source| {
            FirmwarePlanError::SensorModel {
                origin: origin.clone(),
                source,
            }
        })?;
        let config = HilConfig {
            watchdog,
            ..HilConfig::new(duration)
        };
        let command_line = request
            .firmware
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        Ok(Self {
            argv,
            command_line,
            origin,
            scenario,
            world,
            config,
        })
    }
}

impl FirmwarePlan {
    /// Starts the firmware, the paths of `ports` in its environment (`HILSIM_LIDAR_PORT`,
    /// `HILSIM_ROBOT_PORT`).
    ///
    /// # Errors
    /// The program cannot be started.
    pub fn spawn(&self, ports: &HilPorts) -> Result<Firmware, FirmwarePlanError> {
        let env = [
            ("HILSIM_LIDAR_PORT", ports.lidar_path()),
            ("HILSIM_ROBOT_PORT", ports.robot_path()),
        ];
        Firmware::spawn(&self.argv, &env).map_err(|source| FirmwarePlanError::Start {
            program: self.argv[0].clone(),
            source,
        })
    }

    /// One line saying what runs: the firmware started as `pid`, the scenario, for how long.
    #[must_use]
    pub fn started_line(&self, pid: u32) -> String {
        format!(
            "firmware: pid {pid} `{}`; {} ({}) for {:.1} s in real time",
            self.command_line,
            hilsim_recording::printable(&self.scenario.name),
            hilsim_recording::printable(&self.origin),
            self.config.duration.as_secs_f64()
        )
    }
}

/// `value` seconds, in (0, [`MAX_RUN_S`]].
fn seconds(what: &str, value: f64) -> Result<Duration, FirmwarePlanError> {
    if value > 0.0 && value <= MAX_RUN_S {
        Ok(Duration::from_secs_f64(value))
    } else {
        Err(FirmwarePlanError::Seconds {
            what: what.to_string(),
            value,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seconds_out_of_range_are_named() {
        let e = seconds("--watchdog", 0.0).unwrap_err().to_string();
        assert_eq!(
            e,
            format!("--watchdog must be a number of seconds in (0, {MAX_RUN_S}], got 0")
        );
        let e = seconds("--duration", f64::NAN).unwrap_err().to_string();
        assert!(e.ends_with("got a non-finite value"), "{e}");
        let e = seconds("--duration", f64::INFINITY)
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("got a non-finite value"), "{e}");
        assert_eq!(
            seconds("--duration", 2.5).unwrap(),
            Duration::from_secs_f64(2.5)
        );
    }
}
