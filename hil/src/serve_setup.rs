//! A scenario's lidar made ready to serve: what `hilsim serve` checks before it opens a port.

use std::fmt;

use hilsim_lidar_emulator::{Emulation, ModelError};
use hilsim_sim::Scenario;

use crate::faults::WireFaults;
use crate::{Pacing, ServeOptions};

/// Why a scenario's lidar cannot be served.
#[derive(Debug)]
#[non_exhaustive]
pub enum ServeSetupError {
    /// The scenario has no lidar.
    NoLidar(String),
    /// The lidar replays a log's scans, which have no unit's packets.
    ReplaysScans(String),
    /// A sensor's model makes no sense.
    SensorModel {
        /// The scenario's file.
        origin: String,
        /// Why.
        source: ModelError,
    },
}

impl fmt::Display for ServeSetupError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoLidar(origin) => {
                write!(f, "{origin}: the scenario has no [sensors.lidar] to serve")
            }
            Self::ReplaysScans(origin) => write!(
                f,
                "{origin}: the lidar replays a log's scans (`schedule`), which have no unit's \
                 packets to serve; `hilsim record` makes its twin"
            ),
            Self::SensorModel { origin, .. } => write!(f, "{origin}: sensor model"),
        }
    }
}

impl std::error::Error for ServeSetupError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::SensorModel { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl ServeOptions {
    /// The options that serve `scenario`'s lidar (`origin` names its file) in its unit's
    /// protocol, paced by `pacing`, no client known to be reading; with the emulation to serve.
    ///
    /// # Errors
    /// The scenario has no lidar, or one replaying a log's scans, or a sensor model that makes
    /// no sense.
    pub fn for_scenario(
        scenario: &Scenario,
        origin: &str,
        pacing: Pacing,
    ) -> Result<(Self, Emulation), ServeSetupError> {
        let Some(lidar) = &scenario.sensors.lidar else {
            return Err(ServeSetupError::NoLidar(origin.to_string()));
        };
        if scenario.files.schedule.is_some() {
            return Err(ServeSetupError::ReplaysScans(origin.to_string()));
        }
        let options = Self {
            model: lidar.model,
            pacing,
            // Validation has checked the table: its faults resolve.
            faults: WireFaults::new(&scenario.link.faults().unwrap_or_default(), scenario.seed),
            client_connected: false,
        };
        let emulation = Emulation::new(scenario, scenario.seed).map_err(|source| {
            ServeSetupError::SensorModel {
                origin: origin.to_string(),
                source,
            }
        })?;
        Ok((options, emulation))
    }
}
