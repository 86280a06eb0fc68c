//! Scenario files: the world, the robot, what it does, its sensors, and what must hold.
//!
//! [`Scenario::load`] parses a TOML file into typed structs and validates it before anything
//! runs. Every error is one line naming the file, the line and what was expected.
//!
//! ```
//! use hilsim_sim::Scenario;
//! let s = Scenario::from_toml(
//!     r#"
//!     name = "park"
//!     duration_s = 1.0
//!     [robot]
//!     start = { x = 0.0, y = 0.0 }
//!     wheel_base_m = 0.23
//!     "#,
//!     "inline.toml".as_ref(),
//! )
//! .unwrap();
//! assert_eq!(s.physics.step_hz, 100.0);
//! let err = Scenario::from_toml("name = 1", "bad.toml".as_ref()).unwrap_err();
//! assert!(err.to_string().starts_with("bad.toml:1: "));
//! ```

mod effects;
mod locate;
pub mod metrics;
mod schema;
mod validate;

use std::fmt;
use std::path::{Path, PathBuf};

pub use effects::*;
pub use schema::*;

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

impl Scenario {
    /// Reads and validates a scenario file.
    ///
    /// # Errors
    /// The file cannot be read, is not UTF-8 TOML, does not match the format, or fails a check.
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        Self::load_with_duration(path, None)
    }

    /// As [`Scenario::load`], with `duration_s` replaced by `duration_s` when given, before
    /// validation: `hilsim hil --duration` bounds a run whose drive program is empty (the
    /// firmware drives) in a file that sets no `duration_s`.
    ///
    /// # Errors
    /// As [`Scenario::load`].
    pub fn load_with_duration(path: &Path, duration_s: Option<f64>) -> Result<Self, ScenarioError> {
        let bytes = std::fs::read(path).map_err(|err| ScenarioError {
            file: path.to_path_buf(),
            line: None,
            message: format!("cannot read: {err}"),
        })?;
        let text = String::from_utf8(bytes).map_err(|err| ScenarioError {
            file: path.to_path_buf(),
            line: Some(
                1 + err.as_bytes()[..err.utf8_error().valid_up_to()]
                    .iter()
                    .filter(|&&b| b == b'\n')
                    .count(),
            ),
            message: "not a text file: expected UTF-8 TOML".to_string(),
        })?;
        Self::from_toml_with_duration(&text, path, duration_s)
    }

    /// Parses and validates scenario text; `origin` names it in errors.
    ///
    /// # Errors
    /// As [`Scenario::load`].
    pub fn from_toml(text: &str, origin: &Path) -> Result<Self, ScenarioError> {
        Self::from_toml_with_duration(text, origin, None)
    }

    /// As [`Scenario::from_toml`], with `duration_s` replaced by `duration_s` when given, before
    /// validation (see [`Scenario::load_with_duration`]).
    ///
    /// # Errors
    /// As [`Scenario::load`].
    pub fn from_toml_with_duration(
        text: &str,
        origin: &Path,
        duration_s: Option<f64>,
    ) -> Result<Self, ScenarioError> {
        let mut scenario: Scenario = toml::from_str(text).map_err(|err| ScenarioError {
            file: origin.to_path_buf(),
            line: Some(err.span().map_or(1, |s| locate::line_at(text, s.start))),
            message: err.message().trim().replace('\n', " "),
        })?;
        if duration_s.is_some() {
            scenario.duration_s = duration_s;
        }
        validate::validate(&scenario).map_err(|invalid| ScenarioError {
            file: origin.to_path_buf(),
            line: locate::line_of(text, &invalid.path),
            message: format!("{}: {}", locate::display(&invalid.path), invalid.message),
        })?;
        Ok(scenario)
    }

    /// The physics step, seconds.
    #[must_use]
    pub fn step_s(&self) -> f64 {
        1.0 / self.physics.step_hz
    }

    /// The number of physics steps the drive program takes (each drive step rounded to whole
    /// physics steps).
    #[must_use]
    pub fn drive_steps(&self) -> u64 {
        crate::drive::DriveProgram::new(self).total_steps()
    }

    /// The run's length in physics steps: `duration_s` when set, else the drive program's end.
    #[must_use]
    pub fn run_steps(&self) -> u64 {
        match self.duration_s {
            Some(d) => (d * self.physics.step_hz).round() as u64,
            None => self.drive_steps(),
        }
    }

    /// The reflectivity of a named material (`None`: the built-in default).
    #[must_use]
    pub fn reflectivity(&self, material: Option<&str>) -> f64 {
        material
            .and_then(|m| self.world.materials.get(m))
            .cloned()
            .unwrap_or_default()
            .reflectivity
    }
}

#[cfg(test)]
mod tests;
