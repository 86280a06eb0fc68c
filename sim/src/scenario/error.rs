//! What a scenario that cannot be loaded reports.

use std::fmt;
use std::path::PathBuf;

/// A scenario that could not be loaded: the file, the line where known, and what was wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioError {
    /// The scenario file.
    pub file: PathBuf,
    /// The 1-based line, when the problem is at a place in the file.
    pub line: Option<usize>,
    /// What was expected.
    pub message: String,
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for ScenarioError {}
