//! The crate's error: what is wrong and with which file.

use std::fmt;
use std::path::{Path, PathBuf};

/// Why a bag could not be imported or a recording exported.
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// The bag (or the MCAP file being written) is not what it must be: its path and the one
    /// thing wrong.
    Bag {
        /// The file or bag directory.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Writing or reading the recording failed (the recording crate's error names the file).
    Recording(hilsim_recording::Error),
}

impl Error {
    /// Whether writing to a pipe whose reader has gone failed (see
    /// [`hilsim_recording::Error::is_broken_pipe`]).
    #[must_use]
    pub fn is_broken_pipe(&self) -> bool {
        matches!(self, Self::Recording(err) if err.is_broken_pipe())
    }

    pub(crate) fn bag(path: &Path, message: impl Into<String>) -> Self {
        Self::Bag {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            // A path can come from a bag (`metadata.yaml` lists its files).
            Self::Bag { path, message } => write!(
                f,
                "{}: {message}",
                hilsim_recording::printable_cut(&path.display().to_string(), 4096)
            ),
            Self::Recording(err) => err.fmt(f),
        }
    }
}

impl std::error::Error for Error {}

impl From<hilsim_recording::Error> for Error {
    fn from(err: hilsim_recording::Error) -> Self {
        Self::Recording(err)
    }
}
