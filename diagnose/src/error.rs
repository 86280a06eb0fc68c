//! The error of a diagnosis that could not be made.

/// A diagnosis that could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MismatchError {
    /// The input is malformed (a trajectory that goes back in time, a non-finite value).
    #[error("{0}")]
    Input(String),
    /// The recording cannot be diagnosed against this scenario; the message says why.
    #[error("{0}")]
    Refused(String),
}
