//! `--vary KEY=LO..HI`: a scenario parameter drawn per run, set by editing the scenario's TOML
//! document at a dotted key path.
//!
//! A key path is TOML bare keys joined by dots, each optionally followed by array indices:
//! `robot.start.x`, `sensors.lidar.angle_noise_deg`, `world.cylinders[2].radius`,
//! `sensors.lidar.noise[2]`, `drive[1].speed_mps`. It must lead to a number, or to a key absent
//! from a table that exists (`sensors.lidar.rpm_wobble` when `[sensors.lidar]` is there): tables
//! and array elements are never created, so varying a key can never add a sensor.

use std::fmt;
use std::str::FromStr;

use toml::{Table, Value};

use crate::Error;

/// One `--vary`: a key path and the range its values are drawn from, `lo ≤ value ≤ hi`.
///
/// ```
/// use hilsim_dataset::Vary;
/// let v: Vary = "robot.start.x=0.5..1.5".parse()?;
/// assert_eq!((v.key(), v.lo(), v.hi()), ("robot.start.x", 0.5, 1.5));
/// assert!("robot.start.x=1.5..0.5".parse::<Vary>().is_err());
/// # Ok::<(), hilsim_dataset::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Vary {
    key: KeyPath,
    lo: f64,
    hi: f64,
}

impl Vary {
    /// Each `KEY=LO..HI` of `specs` (`--vary`, repeatable), in order.
    ///
    /// # Errors
    /// The first that is not one.
    pub fn parse_all(specs: &[String]) -> Result<Vec<Self>, Error> {
        specs.iter().map(|s| s.parse()).collect()
    }

    /// A vary of `key` over `[lo, hi]`.
    ///
    /// # Errors
    /// The key path is malformed, a bound is not finite, or `lo > hi`.
    pub fn new(key: &str, lo: f64, hi: f64) -> Result<Self, Error> {
        let spec = format!("{key}={lo}..{hi}");
        let bad = |message: String| Error::Vary {
            spec: spec.clone(),
            message,
        };
        let key = KeyPath::parse(key).map_err(bad)?;
        if !(lo.is_finite() && hi.is_finite() && (hi - lo).is_finite()) {
            return Err(bad("expected finite bounds".to_string()));
        }
        if lo > hi {
            return Err(bad(format!("expected LO ≤ HI, found {lo} > {hi}")));
        }
        Ok(Self { key, lo, hi })
    }

    /// The key path as written.
    #[must_use]
    pub fn key(&self) -> &str {
        &self.key.text
    }

    /// The lower bound.
    #[must_use]
    pub fn lo(&self) -> f64 {
        self.lo
    }

    /// The upper bound.
    #[must_use]
    pub fn hi(&self) -> f64 {
        self.hi
    }

    /// Sets this key to `value` in a scenario document.
    pub(crate) fn set(&self, doc: &mut Table, value: f64) -> Result<(), String> {
        self.key.set(doc, value)
    }

    pub(crate) fn error(&self, message: impl Into<String>) -> Error {
        Error::Vary {
            spec: self.to_string(),
            message: message.into(),
        }
    }
}

impl fmt::Display for Vary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}..{}", self.key.text, self.lo, self.hi)
    }
}

const SYNTAX: &str = "expected KEY=LO..HI, e.g. robot.start.x=0.5..1.5";

impl FromStr for Vary {
    type Err = Error;

    fn from_str(spec: &str) -> Result<Self, Error> {
        let bad = |message: &str| Error::Vary {
            spec: spec.to_string(),
            message: message.to_string(),
        };
        let (key, range) = spec.split_once('=').ok_or_else(|| bad(SYNTAX))?;
        let (lo, hi) = range.split_once("..").ok_or_else(|| bad(SYNTAX))?;
        // `1...2` would read as 1..0.2: a bound beside the two dots has a digit there.
        if lo.trim_end().ends_with('.') || hi.trim_start().starts_with('.') {
            return Err(bad(&format!(
                "more than two dots between the bounds (write .5 as 0.5); {SYNTAX}"
            )));
        }
        let number = |s: &str| {
            let s = s.trim();
            // Rust also reads `inf`, `nan` and `infinity`: refuse anything but a finite number.
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(bad(&format!("`{s}` is not a finite number; {SYNTAX}"))),
            }
        };
        let (lo, hi) = (number(lo)?, number(hi)?);
        Vary::new(key.trim(), lo, hi).map_err(|err| match err {
            Error::Vary { message, .. } => bad(&message),
            other => other,
        })
    }
}

/// A dotted key path with optional array indices.
#[derive(Debug, Clone, PartialEq)]
struct KeyPath {
    text: String,
    steps: Vec<Step>,
}

#[derive(Debug, Clone, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
}

impl KeyPath {
    fn parse(text: &str) -> Result<Self, String> {
        let expected = || {
            format!(
                "`{text}` is not a key path: expected TOML bare keys (letters, digits, `_`, `-`) \
                 joined by `.`, each optionally followed by an index like `[2]`"
            )
        };
        if text.is_empty() {
            return Err("expected a key before `=`".to_string());
        }
        let mut steps = Vec::new();
        for part in text.split('.') {
            let (name, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
            if name.is_empty()
                || !name
                    .bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
            {
                return Err(expected());
            }
            steps.push(Step::Key(name.to_string()));
            while !rest.is_empty() {
                let close = rest.find(']').ok_or_else(expected)?;
                let digits = &rest[1..close];
                if !rest.starts_with('[')
                    || digits.is_empty()
                    || !digits.bytes().all(|b| b.is_ascii_digit())
                {
                    return Err(expected());
                }
                steps.push(Step::Index(digits.parse().map_err(|_| expected())?));
                rest = &rest[close + 1..];
            }
        }
        if steps == [Step::Key("seed".to_string())] {
            return Err(
                "the seed is set per run by the dataset (give the dataset's with --seed)"
                    .to_string(),
            );
        }
        Ok(Self {
            text: text.to_string(),
            steps,
        })
    }

    /// The path up to (not including) step `n`, as written.
    fn prefix(&self, n: usize) -> String {
        let mut s = String::new();
        for step in &self.steps[..n] {
            match step {
                Step::Key(k) => {
                    if !s.is_empty() {
                        s.push('.');
                    }
                    s.push_str(k);
                }
                Step::Index(i) => s.push_str(&format!("[{i}]")),
            }
        }
        s
    }

    /// Sets the number at this path to `value`: an existing integer or float, or a new key in an
    /// existing table.
    fn set(&self, doc: &mut Table, value: f64) -> Result<(), String> {
        let last = self.steps.len() - 1;
        let Step::Key(first) = &self.steps[0] else {
            unreachable!("a key path starts with a key");
        };
        if last == 0 {
            return set_leaf(doc, first, &self.text, value);
        }
        let mut cur: &mut Value = doc.get_mut(first).ok_or_else(|| {
            format!(
                "no table `{first}` in the scenario (tables are not created: add it to the \
                 scenario to vary its keys)"
            )
        })?;
        for (i, step) in self.steps.iter().enumerate().skip(1) {
            let here = self.prefix(i);
            match step {
                Step::Key(k) => {
                    let Value::Table(t) = cur else {
                        return Err(format!("`{here}` is {}, not a table", kind(cur)));
                    };
                    if i == last {
                        return set_leaf(t, k, &self.text, value);
                    }
                    cur = t.get_mut(k).ok_or_else(|| {
                        format!(
                            "no table `{}` in the scenario (tables are not created: add it to \
                             the scenario to vary its keys)",
                            self.prefix(i + 1)
                        )
                    })?;
                }
                Step::Index(n) => {
                    let Value::Array(a) = cur else {
                        return Err(format!("`{here}` is {}, not an array", kind(cur)));
                    };
                    let len = a.len();
                    let element = a.get_mut(*n).ok_or_else(|| {
                        format!("`{here}` has {len} element(s): there is no [{n}]")
                    })?;
                    if i == last {
                        return match element {
                            Value::Integer(_) | Value::Float(_) => {
                                *element = Value::Float(value);
                                Ok(())
                            }
                            other => {
                                Err(format!("`{}` is {}, not a number", self.text, kind(other)))
                            }
                        };
                    }
                    cur = element;
                }
            }
        }
        unreachable!("the last step returns");
    }
}

/// Sets `table[key]`: an existing number is replaced, an absent key is added.
fn set_leaf(table: &mut Table, key: &str, path: &str, value: f64) -> Result<(), String> {
    match table.get(key) {
        None | Some(Value::Integer(_) | Value::Float(_)) => {
            table.insert(key.to_string(), Value::Float(value));
            Ok(())
        }
        Some(other) => Err(format!("`{path}` is {}, not a number", kind(other))),
    }
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::String(_) => "a string",
        Value::Integer(_) => "an integer",
        Value::Float(_) => "a float",
        Value::Boolean(_) => "a boolean",
        Value::Datetime(_) => "a date-time",
        Value::Array(_) => "an array",
        Value::Table(_) => "a table",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc() -> Table {
        toml::from_str(
            r#"
            name = "t"
            duration_s = 2
            [robot]
            start = { x = 0.5, y = 0.0 }
            wheel_base_m = 0.23
            [sensors.lidar]
            noise = [0.0, 0.0, 0.004]
            [[drive]]
            stop_s = 1.0
            "#,
        )
        .unwrap()
    }

    fn set(key: &str, v: f64) -> Result<Table, String> {
        let vary: Vary = format!("{key}=0..1")
            .parse()
            .map_err(|e: Error| e.to_string())?;
        let mut d = doc();
        vary.set(&mut d, v)?;
        Ok(d)
    }

    #[test]
    fn numbers_are_set_where_the_path_leads() {
        let d = set("robot.start.x", 0.75).unwrap();
        assert_eq!(d["robot"]["start"]["x"].as_float(), Some(0.75));
        let d = set("duration_s", 0.25).unwrap();
        assert_eq!(
            d["duration_s"].as_float(),
            Some(0.25),
            "an integer becomes a float"
        );
        let d = set("sensors.lidar.noise[2]", 0.5).unwrap();
        assert_eq!(d["sensors"]["lidar"]["noise"][2].as_float(), Some(0.5));
        let d = set("drive[0].stop_s", 0.5).unwrap();
        assert_eq!(d["drive"][0]["stop_s"].as_float(), Some(0.5));
        let d = set("robot.start.yaw_deg", 0.5).unwrap();
        assert_eq!(
            d["robot"]["start"]["yaw_deg"].as_float(),
            Some(0.5),
            "added"
        );
    }

    #[test]
    fn paths_that_lead_nowhere_name_the_key() {
        for (key, fragment) in [
            ("robot.actuation.scale_sd", "no table `robot.actuation`"),
            ("sensors.sonar.half_angle_deg", "no table `sensors.sonar`"),
            ("name", "`name` is a string, not a number"),
            ("robot.start", "`robot.start` is a table, not a number"),
            ("sensors.lidar.noise", "`sensors.lidar.noise` is an array"),
            (
                "sensors.lidar.noise[3]",
                "`sensors.lidar.noise` has 3 element(s)",
            ),
            ("drive.stop_s", "`drive` is an array, not a table"),
            ("robot[0]", "`robot` is a table, not an array"),
            ("nothing.here", "no table `nothing` in the scenario"),
        ] {
            let err = set(key, 0.5).unwrap_err();
            assert!(err.contains(fragment), "{key}: {err}");
        }
    }

    #[test]
    fn malformed_specs_are_refused() {
        for (spec, fragment) in [
            ("robot.start.x", "expected KEY=LO..HI"),
            ("robot.start.x=1", "expected KEY=LO..HI"),
            ("=0..1", "expected a key before `=`"),
            ("robot..x=0..1", "is not a key path"),
            ("robot.start.x=a..1", "`a` is not a finite number"),
            ("robot.start.x=0..inf", "`inf` is not a finite number"),
            ("robot.start.x=nan..1", "`nan` is not a finite number"),
            ("robot.start.x=2..1", "expected LO ≤ HI"),
            (
                "robot.start.y=1...2",
                "`robot.start.y=1...2`: more than two dots between the bounds",
            ),
            ("robot.start.y=1. ..2", "more than two dots"),
            ("robot.start.y=0.5..-.5", "expected LO ≤ HI"),
            ("a[x]=0..1", "is not a key path"),
            ("a[1=0..1", "is not a key path"),
            ("a b=0..1", "is not a key path"),
            ("seed=0..1", "the seed is set per run"),
            (
                "x=-1.7976931348623157e308..1.7976931348623157e308",
                "finite bounds",
            ),
        ] {
            let err = spec.parse::<Vary>().unwrap_err().to_string();
            assert!(err.starts_with(&format!("--vary `{spec}`: ")), "{err}");
            assert!(err.contains(fragment), "{spec}: {err}");
        }
        let v: Vary = "world.cylinders[2].center[0]=-1.5..-0.5".parse().unwrap();
        assert_eq!((v.lo(), v.hi()), (-1.5, -0.5));
        assert_eq!(v.to_string(), "world.cylinders[2].center[0]=-1.5..-0.5");
        let v: Vary = "x=1e-3..2E-3".parse().unwrap();
        assert_eq!((v.lo(), v.hi()), (0.001, 0.002));
    }
}
