//! Reading a scenario: TOML into the typed form, then the checks serde cannot express; every
//! error names the file and, where it can, the line.

use std::path::Path;

use super::error::ScenarioError;
use super::locate;
use super::schema::Scenario;
use super::validate;

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
}
