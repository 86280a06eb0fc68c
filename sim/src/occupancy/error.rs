//! What can go wrong reading, writing or building a map.

use std::fmt;
use std::path::PathBuf;

/// A map that could not be read, written or built.
#[derive(Debug)]
#[non_exhaustive]
pub enum MapError {
    /// A map file could not be read.
    Io {
        /// The file.
        path: PathBuf,
        /// The system's error.
        error: std::io::Error,
    },
    /// A map file's contents are not what map_server reads: a YAML key, an image header, the
    /// pixels.
    Format {
        /// The file.
        path: PathBuf,
        /// The 1-based line, in a text file when the problem is at one.
        line: Option<usize>,
        /// What was expected.
        message: String,
    },
    /// Writing the map was refused or failed (a user's file at the path, a directory, a full
    /// disk), as `hilsim_recording::atomic` decides for every output.
    Output(hilsim_recording::Error),
    /// The map would have more cells than its limit allows (see [`crate::occupancy::MAX_CELLS`]
    /// and [`crate::occupancy::MAX_BUILDER_CELLS`]).
    TooLarge {
        /// What was too large and the limit, in words.
        message: String,
    },
    /// A parameter that makes no map: a resolution that is not a positive number, a coordinate
    /// that is not finite.
    Invalid {
        /// What was wrong.
        message: String,
    },
}

impl MapError {
    pub(crate) fn format(
        path: &std::path::Path,
        line: Option<usize>,
        message: impl Into<String>,
    ) -> Self {
        Self::Format {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    pub(crate) fn io(path: &std::path::Path, error: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            error,
        }
    }

    pub(crate) fn invalid(message: impl Into<String>) -> Self {
        Self::Invalid {
            message: message.into(),
        }
    }
}

impl fmt::Display for MapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, error } => write!(f, "{}: {error}", path.display()),
            Self::Format {
                path,
                line,
                message,
            } => {
                write!(f, "{}", path.display())?;
                if let Some(line) = line {
                    write!(f, ":{line}")?;
                }
                write!(f, ": {message}")
            }
            Self::Output(error) => write!(f, "{error}"),
            Self::TooLarge { message } | Self::Invalid { message } => f.write_str(message),
        }
    }
}

/// The I/O error's text is part of the message (one line naming the file), so it is not also
/// the source: a report that prints the chain would say it twice.
impl std::error::Error for MapError {}

impl From<hilsim_recording::Error> for MapError {
    fn from(error: hilsim_recording::Error) -> Self {
        Self::Output(error)
    }
}
