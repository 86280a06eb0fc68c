//! The dataset's error type: every error names the file, directory or `--vary` key concerned and
//! what was expected, on one line.

use std::path::{Path, PathBuf};

use hilsim_sim::ScenarioError;

/// What stopped a dataset from being made or merged. A run that fails on its own (its varied
/// scenario is invalid, say) is not an error: it is recorded in the manifest as failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The base scenario cannot be read or is invalid (file and line).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// A `--vary KEY=LO..HI` is malformed, names no number in the scenario, or has a bound that
    /// is out of range for its key.
    #[error("--vary `{spec}`: {message}")]
    Vary {
        /// The argument as given.
        spec: String,
        /// What was expected.
        message: String,
    },
    /// A `--shard I/K` is malformed.
    #[error("--shard `{spec}`: {message}")]
    Shard {
        /// The argument as given.
        spec: String,
        /// What was expected.
        message: String,
    },
    /// A parameter is out of range (`--runs 0`, `--run` past the end, a seed that TOML cannot
    /// hold).
    #[error("{0}")]
    Parameter(String),
    /// The output directory holds another dataset (other parameters), or is not a dataset.
    #[error("{}: {message}", path.display())]
    Mismatch {
        /// The directory or `dataset.toml` concerned.
        path: PathBuf,
        /// What differs.
        message: String,
    },
    /// A run directory or manifest is not what this crate writes (edited or damaged by hand).
    #[error("{}: {message}", path.display())]
    Corrupt {
        /// The file or directory concerned.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A file or directory could not be read or written.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file or directory concerned.
        path: PathBuf,
        /// The operating system's error: in the message and not a `source`, since a report that
        /// prints the chain of sources would say it twice.
        error: std::io::Error,
    },
    /// Another process is making the same runs in the directory (writing the same manifest).
    #[error(
        "{}: another hilsim ({}) is writing this dataset's {manifest}: one process per shard; \
         wait for it, or give another --out or --shard",
        dir.display(),
        pid.map_or_else(|| "PID unknown".to_string(), |p| format!("pid {p}"))
    )]
    Busy {
        /// The dataset directory.
        dir: PathBuf,
        /// The manifest the other process writes.
        manifest: String,
        /// The other process's ID, when it has written it.
        pid: Option<u32>,
    },
    /// A recording could not be written.
    #[error(transparent)]
    Recording(#[from] hilsim_recording::Error),
}

impl Error {
    pub(crate) fn io(path: &Path, error: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            error,
        }
    }

    pub(crate) fn corrupt(path: &Path, message: impl Into<String>) -> Self {
        Self::Corrupt {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    pub(crate) fn mismatch(path: &Path, message: impl Into<String>) -> Self {
        Self::Mismatch {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}
