//! The recording's error type: every error names the file, and the line where there is one.

use std::fmt;
use std::path::{Path, PathBuf};

/// What went wrong reading or writing a recording.
#[derive(Debug)]
pub struct Error {
    /// The file concerned.
    pub path: PathBuf,
    /// The 1-based line, for errors inside a text file.
    pub line: Option<usize>,
    /// What went wrong.
    pub kind: ErrorKind,
}

/// The kinds of recording error.
#[derive(Debug)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The file could not be read or written.
    Io(std::io::Error),
    /// The file's contents do not follow the format.
    Format(String),
}

impl Error {
    /// Whether writing to a pipe whose reader has gone failed (`hilsim … | head`): not an error
    /// to report, a reason to stop quietly.
    #[must_use]
    pub fn is_broken_pipe(&self) -> bool {
        matches!(&self.kind, ErrorKind::Io(io) if io.kind() == std::io::ErrorKind::BrokenPipe)
    }

    pub(crate) fn io(path: &Path, err: std::io::Error) -> Self {
        Self {
            path: path.to_path_buf(),
            line: None,
            kind: ErrorKind::Io(err),
        }
    }

    pub(crate) fn format(path: &Path, line: Option<usize>, msg: impl Into<String>) -> Self {
        Self {
            path: path.to_path_buf(),
            line,
            kind: ErrorKind::Format(msg.into()),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        match &self.kind {
            ErrorKind::Io(err) => write!(f, ": {err}"),
            ErrorKind::Format(msg) => write!(f, ": {msg}"),
        }
    }
}

/// The I/O error's text is part of the message (one line naming the file), so it is not also
/// the source: a report that prints the chain would say it twice.
impl std::error::Error for Error {}
