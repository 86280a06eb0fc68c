//! Reading a scenario: TOML into the typed form, then the checks serde cannot express; every
//! error names the file and, where it can, the line.

use std::io::Read;
use std::path::Path;

use super::error::ScenarioError;
use super::locate;
use super::schema::Scenario;
use super::validate;

/// The largest scenario file read, in bytes. A real one is a few KB (the largest checked in is
/// under 3 KB); a file is read whole before it is parsed, so this bounds what any input, even
/// an endless one (`/dev/zero`, a pipe that never closes), costs.
pub(crate) const MAX_SCENARIO_BYTES: u64 = 1 << 20;

impl Scenario {
    /// Reads and validates a scenario file: at most [`MAX_SCENARIO_BYTES`] (1 MiB).
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
        let text = read_scenario_text(path)?;
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
        model_defaults(&mut scenario, text);
        scenario.files = super::files::read(&scenario, origin)?;
        if let (None, Some(path)) = (scenario.duration_s, &scenario.files.path) {
            // A replayed log's run lasts as long as its path.
            scenario.duration_s = Some(path.end_s());
        }
        validate::validate(&scenario).map_err(|invalid| ScenarioError {
            file: origin.to_path_buf(),
            line: locate::line_of(text, &invalid.path),
            message: format!("{}: {}", locate::display(&invalid.path), invalid.message),
        })?;
        Ok(scenario)
    }
}

/// Fills the lidar keys the file leaves out with its model's datasheet values (serde's defaults
/// are the XV-11's, which is what a file without a model means).
fn model_defaults(scenario: &mut Scenario, text: &str) {
    let Some(lidar) = scenario.sensors.lidar.as_mut() else {
        return;
    };
    if lidar.model == super::LidarModel::Xv11 {
        return;
    }
    // The text parsed once already; this second look only asks which keys it sets.
    let table: Option<toml::Table> = text.parse().ok();
    let set = |key: &str| {
        table
            .as_ref()
            .and_then(|t| t.get("sensors")?.get("lidar")?.get(key))
            .is_some()
    };
    let spec = lidar.model.spec();
    if !set("rpm") {
        lidar.rpm = spec.rev_hz * 60.0;
    }
    if !set("min_range_m") {
        lidar.min_range_m = spec.min_range_m;
    }
    if !set("max_range_m") {
        lidar.max_range_m = spec.max_range_m;
    }
    if let (false, Some(noise)) = (set("noise"), spec.noise) {
        lidar.noise = noise.to_vec();
    }
}

/// The text of the scenario file at `path`, unparsed (for tools that edit it before parsing, as
/// `hilsim dataset --vary` does): at most [`MAX_SCENARIO_BYTES`], UTF-8.
///
/// # Errors
/// The file cannot be read, is larger than the limit, or is not UTF-8 (naming the line).
pub fn read_scenario_text(path: &Path) -> Result<String, ScenarioError> {
    let bytes = read_bounded(path)?;
    String::from_utf8(bytes).map_err(|err| ScenarioError {
        file: path.to_path_buf(),
        line: Some(
            1 + err.as_bytes()[..err.utf8_error().valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count(),
        ),
        message: "not a text file: expected UTF-8 TOML".to_string(),
    })
}

/// The bytes of `path`, when there are at most [`MAX_SCENARIO_BYTES`]. A regular file's length is
/// checked before it is read; anything else (a pipe, a device) is read up to one byte more.
fn read_bounded(path: &Path) -> Result<Vec<u8>, ScenarioError> {
    let max = MAX_SCENARIO_BYTES;
    let error = |message: String| ScenarioError {
        file: path.to_path_buf(),
        line: None,
        message,
    };
    let cannot_read = |err: std::io::Error| error(format!("cannot read: {err}"));
    let too_large = || error("larger than 1 MiB; not a scenario file".to_string());
    let file = std::fs::File::open(path).map_err(cannot_read)?;
    let meta = file.metadata().map_err(cannot_read)?;
    if meta.is_file() && meta.len() > max {
        return Err(too_large());
    }
    let mut bytes = Vec::new();
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot_read)?;
    if bytes.len() as u64 > max {
        return Err(too_large());
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_endless_file_is_refused_after_1_mib() {
        let zero = Scenario::load(Path::new("/dev/zero")).unwrap_err();
        assert_eq!(
            zero.to_string(),
            "/dev/zero: larger than 1 MiB; not a scenario file"
        );
        let missing = Scenario::load(Path::new("/nonexistent/missing.toml")).unwrap_err();
        assert!(missing.message.starts_with("cannot read: "), "{missing}");
    }
}
