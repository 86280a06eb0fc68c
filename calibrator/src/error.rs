//! Why a calibration could not be made. Every variant is something the user can act on; none is
//! ever reported as a NaN parameter.

/// A calibration that could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CalibrationError {
    /// The recording lacks a table or a `meta.toml` key the method needs.
    #[error("{0}")]
    Missing(String),
    /// Too few usable samples to identify the model.
    #[error("too few samples: {0}")]
    TooFewSamples(String),
    /// The data cannot identify the model (e.g. the robot never moved).
    #[error("unidentifiable: {0}")]
    Unidentifiable(String),
    /// The estimate diverged (negative variance, singular innovation, non-finite values).
    #[error("diverged: {0}")]
    Diverged(String),
    /// The input contradicts the method's assumptions (e.g. time going backwards).
    #[error("{0}")]
    Invalid(String),
}
