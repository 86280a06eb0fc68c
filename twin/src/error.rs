//! What can go wrong building a run's twin.

use hilsim_sim::occupancy::MapError;
use hilsim_sim::ScenarioError;

/// Why a twin could not be built or compared.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TwinError {
    /// A recording that cannot be read.
    #[error(transparent)]
    Recording(#[from] hilsim_recording::Error),
    /// A scenario (the one written, or the one given) that cannot be loaded.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// A map that cannot be read or written.
    #[error("{0}")]
    Map(String),
    /// A sensor model that makes no sense.
    #[error("{0}")]
    Model(String),
    /// Input that cannot make a twin (one line, naming the file).
    #[error("{0}")]
    Input(String),
}

impl From<MapError> for TwinError {
    fn from(err: MapError) -> Self {
        Self::Map(err.to_string())
    }
}
