//! A calibration for people, and read back from the JSON `hilsim calibrate --json` prints.

use std::collections::BTreeMap;
use std::fmt::Write;

use crate::checks::Check;
use crate::{
    Calibration, CalibrationError, LidarModelMetrics, Method, Metrics, OdometryModel, Sensor,
    SensorModel,
};

impl Calibration {
    /// One line per sensor, the metrics, the notes.
    #[must_use]
    pub fn describe(&self) -> String {
        let mut s = String::new();
        // Writing to a String cannot fail.
        let _ = self.write_description(&mut s);
        s
    }

    fn write_description(&self, s: &mut String) -> std::fmt::Result {
        writeln!(
            s,
            "{}: {} iteration(s), {}",
            self.method.name(),
            self.iterations,
            if self.converged {
                "converged"
            } else {
                "NOT converged"
            }
        )?;
        for (sensor, model) in &self.sensors {
            writeln!(
                s,
                "  {:<9} alpha {}  beta {}",
                format!("{sensor:?}").to_lowercase(),
                coefficients(&model.alpha, &model.alpha_sd),
                coefficients(&model.beta, &model.beta_sd)
            )?;
        }
        if let Some(order) = self.order {
            writeln!(s, "  order {order}")?;
        }
        if let Some(o) = &self.odometry {
            write_odometry(s, o)?;
        }
        if let Some(landmarks) = &self.landmarks {
            for (i, [x, y]) in landmarks.iter().enumerate() {
                writeln!(s, "  landmark {i}: ({x:.3}, {y:.3}) m")?;
            }
        }
        if let Some(m) = self.metrics {
            // What the first figures measure: EM's is its smoothed distance (eq. 31 of the
            // paper's comparison), which fuses every sensor and the commands.
            let what = match self.method {
                Method::Em => "smoothed distance (all sensors and commands)",
                Method::Landmarks | Method::Groundtruth | Method::Odometry => "lidar distance",
            };
            writeln!(
                s,
                "  {what}: MSE raw {:.3e} m², calibrated {:.3e} m² (ratio {:.2}); NMSE raw {:.3e}, calibrated {:.3e}",
                m.mse_raw,
                m.mse_calibrated,
                m.mse_ratio(),
                m.nmse_raw,
                m.nmse_calibrated
            )?;
            if let (Method::Em, Some(l)) = (self.method, m.lidar_model) {
                writeln!(
                    s,
                    "  lidar model alone (each raw reading inverted through it): MSE raw {:.3e} m², calibrated {:.3e} m² (ratio {:.2}, {} readings)",
                    l.mse_raw, l.mse_calibrated, l.mse_ratio, l.readings
                )?;
            }
        }
        // The passed checks in one line, each failed one with what it means.
        let passed: Vec<&str> = self
            .checks
            .iter()
            .filter(|c| c.pass)
            .map(|c| c.name.as_str())
            .collect();
        if !passed.is_empty() {
            writeln!(s, "  checks passed: {}", passed.join(", "))?;
        }
        for check in self.checks.iter().filter(|c| !c.pass) {
            writeln!(s, "  check FAILED: {}: {}", check.name, check.detail)?;
        }
        for note in &self.notes {
            writeln!(s, "  note: {note}")?;
        }
        Ok(())
    }

    /// A calibration read back from its JSON (as [`Calibration::to_json`] writes it): the
    /// sensor models, and what else the JSON holds (standard errors, iterations, metrics,
    /// checks, notes; each optional). `origin` names the text in errors.
    ///
    /// # Errors
    /// [`CalibrationError::Invalid`] naming `origin` (and the line, for malformed JSON).
    pub fn from_json(text: &str, origin: &str) -> Result<Self, CalibrationError> {
        let value = parse_json(text, origin)?;
        if let Some(serde_json::Value::Array(_)) = value.get("calibrations") {
            return Err(CalibrationError::Invalid(format!(
                "{origin}: a run's results (a `calibrations` list), not one calibration: give \
                 the JSON that `hilsim calibrate --json` prints"
            )));
        }
        Self::from_json_value(&value, origin)
    }

    /// Every calibration in a JSON text: one `hilsim calibrate --json` object, or a run's
    /// `results.json` (its `calibrations` list). `origin` names the text in errors.
    ///
    /// # Errors
    /// As [`Calibration::from_json`].
    pub fn all_from_json(text: &str, origin: &str) -> Result<Vec<Self>, CalibrationError> {
        let value = parse_json(text, origin)?;
        match value.get("calibrations") {
            Some(serde_json::Value::Array(list)) => list
                .iter()
                .enumerate()
                .map(|(i, c)| Self::from_json_value(c, &format!("{origin}: calibrations[{i}]")))
                .collect(),
            Some(_) => Err(CalibrationError::Invalid(format!(
                "{origin}: `calibrations` must be a list"
            ))),
            None => Ok(vec![Self::from_json_value(&value, origin)?]),
        }
    }

    /// [`Calibration::from_json`] of a parsed value.
    fn from_json_value(value: &serde_json::Value, origin: &str) -> Result<Self, CalibrationError> {
        let invalid = |message: String| CalibrationError::Invalid(message);
        if !value.is_object() {
            return Err(invalid(format!(
                "{origin}: expected a JSON object (as `hilsim calibrate --json` prints), found {}",
                shown(value)
            )));
        }
        let method = match value.get("method") {
            Some(serde_json::Value::String(name)) => Method::from_name(name),
            _ => None,
        };
        let Some(method) = method else {
            let found = value
                .get("method")
                .map_or_else(|| "none".to_string(), shown);
            return Err(invalid(format!(
                "{origin}: `method` must be {}, found {found}",
                method_names()
            )));
        };
        let numbers = |v: &serde_json::Value| -> Option<Vec<f64>> {
            v.as_array()?
                .iter()
                .map(serde_json::Value::as_f64)
                .collect::<Option<Vec<_>>>()
        };
        let mut sensors = BTreeMap::new();
        for (name, sensor) in [
            ("lidar", Sensor::Lidar),
            ("sonar", Sensor::Sonar),
            ("odometer", Sensor::Odometer),
        ] {
            let model = &value["sensors"][name];
            if model.is_null() {
                continue;
            }
            let coeffs = |key: &str| -> Result<Vec<f64>, CalibrationError> {
                numbers(&model[key]).ok_or_else(|| {
                    invalid(format!(
                        "{origin}: sensors.{name}.{key} must be an array of numbers"
                    ))
                })
            };
            let optional = |key: &str| -> Result<Vec<f64>, CalibrationError> {
                if model[key].is_null() {
                    Ok(Vec::new())
                } else {
                    coeffs(key)
                }
            };
            let mut m = SensorModel::without_sd(coeffs("alpha")?, coeffs("beta")?);
            m.alpha_sd = optional("alpha_sd")?;
            m.beta_sd = optional("beta_sd")?;
            // A standard error per coefficient, or none: another count describes another model.
            for (sd, given, of, n) in [
                ("alpha_sd", &m.alpha_sd, "alpha", m.alpha.len()),
                ("beta_sd", &m.beta_sd, "beta", m.beta.len()),
            ] {
                if !given.is_empty() && given.len() != n {
                    return Err(invalid(format!(
                        "{origin}: sensors.{name}.{sd} has {} standard errors for {n} {of} coefficients",
                        given.len()
                    )));
                }
            }
            sensors.insert(sensor, m);
        }
        let metrics = value.get("metrics").and_then(|m| {
            let f = |key: &str| m[key].as_f64();
            Some(Metrics {
                mse_raw: f("mse_raw")?,
                mse_calibrated: f("mse_calibrated")?,
                nmse_raw: f("nmse_raw")?,
                nmse_calibrated: f("nmse_calibrated")?,
                lidar_model: m.get("lidar_model").and_then(|l| {
                    Some(LidarModelMetrics {
                        mse_raw: l["mse_raw"].as_f64()?,
                        mse_calibrated: l["mse_calibrated"].as_f64()?,
                        mse_ratio: l["mse_ratio"].as_f64()?,
                        readings: usize::try_from(l["readings"].as_u64()?).ok()?,
                    })
                }),
            })
        });
        let checks = value["checks"]
            .as_array()
            .map(|list| {
                list.iter()
                    .filter_map(|c| {
                        Some(Check {
                            name: c["name"].as_str()?.to_string(),
                            value: c["value"].as_f64().unwrap_or(f64::NAN),
                            threshold: c["threshold"].as_f64().unwrap_or(f64::NAN),
                            pass: c["pass"].as_bool()?,
                            detail: c["detail"].as_str().unwrap_or_default().to_string(),
                        })
                    })
                    .collect()
            })
            .unwrap_or_default();
        let notes = value["notes"]
            .as_array()
            .map(|list| {
                list.iter()
                    .filter_map(|n| n.as_str().map(str::to_string))
                    .collect()
            })
            .unwrap_or_default();
        Ok(Calibration {
            method,
            sensors,
            iterations: value["iterations"]
                .as_u64()
                .and_then(|n| usize::try_from(n).ok())
                .unwrap_or(0),
            converged: value["converged"].as_bool().unwrap_or(true),
            checks,
            metrics,
            order: value["order"]
                .as_u64()
                .and_then(|n| usize::try_from(n).ok()),
            odometry: match value.get("odometry") {
                None | Some(serde_json::Value::Null) => None,
                Some(v) => Some(
                    serde_json::from_value(v.clone())
                        .map_err(|e| invalid(format!("{origin}: `odometry`: {e}")))?,
                ),
            },
            landmarks: value["landmarks"].as_array().and_then(|list| {
                list.iter()
                    .map(|p| Some([p.get(0)?.as_f64()?, p.get(1)?.as_f64()?]))
                    .collect()
            }),
            notes,
        })
    }
}

/// A calibration's JSON text, parsed: a byte-order mark some editors write first is skipped (RFC
/// 8259 lets a parser ignore it), and an object naming a key twice is refused (the second would
/// silently replace the first).
fn parse_json(text: &str, origin: &str) -> Result<serde_json::Value, CalibrationError> {
    use serde::de::DeserializeSeed;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut de = serde_json::Deserializer::from_str(text);
    let value = NoDuplicateKeys
        .deserialize(&mut de)
        .and_then(|value| de.end().map(|()| value))
        .map_err(|err| {
            let what = if err.classify() == serde_json::error::Category::Data {
                ""
            } else {
                "not JSON: "
            };
            CalibrationError::Invalid(format!("{origin}:{}: {what}{err}", err.line()))
        })?;
    Ok(value)
}

/// Every method's name, for a message: `em, landmarks, groundtruth or odometry`.
fn method_names() -> String {
    let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
    match names.split_last() {
        Some((last, [])) => (*last).to_string(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// A JSON value for a message: terminal-safe and short.
fn shown(value: &serde_json::Value) -> String {
    hilsim_recording::printable_cut(&value.to_string(), 60).into_owned()
}

/// Deserializes any JSON value, refusing an object that names a key twice.
struct NoDuplicateKeys;

impl<'de> serde::de::DeserializeSeed<'de> for NoDuplicateKeys {
    type Value = serde_json::Value;

    fn deserialize<D: serde::Deserializer<'de>>(self, de: D) -> Result<Self::Value, D::Error> {
        de.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for NoDuplicateKeys {
    type Value = serde_json::Value;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<Self::Value, E> {
        Ok(v.into())
    }

    fn visit_i64<E>(self, v: i64) -> Result<Self::Value, E> {
        Ok(v.into())
    }

    fn visit_u64<E>(self, v: u64) -> Result<Self::Value, E> {
        Ok(v.into())
    }

    fn visit_f64<E>(self, v: f64) -> Result<Self::Value, E> {
        Ok(v.into())
    }

    fn visit_str<E>(self, v: &str) -> Result<Self::Value, E> {
        Ok(v.into())
    }

    fn visit_unit<E>(self) -> Result<Self::Value, E> {
        Ok(serde_json::Value::Null)
    }

    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut list = Vec::new();
        while let Some(item) = seq.next_element_seed(NoDuplicateKeys)? {
            list.push(item);
        }
        Ok(list.into())
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let mut object = serde_json::Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if object.contains_key(&key) {
                return Err(serde::de::Error::custom(format!(
                    "the key `{}` appears twice in one object",
                    hilsim_recording::printable(&key)
                )));
            }
            let value = map.next_value_seed(NoDuplicateKeys)?;
            object.insert(key, value);
        }
        Ok(object.into())
    }
}

/// `[a, b]`, or `[a ± sa, b ± sb]` with standard errors (a coefficient held at 0 has none).
fn coefficients(c: &[f64], sd: &[f64]) -> String {
    let parts: Vec<String> = c
        .iter()
        .enumerate()
        .map(|(i, v)| match sd.get(i) {
            Some(sd) if *sd > 0.0 => format!("{v:.5} ± {sd:.5}"),
            _ => format!("{v:.5}"),
        })
        .collect();
    format!("[{}]", parts.join(", "))
}

/// The wheels and the mount with their standard deviations, in millimetres and milliradians
/// (the sizes a robot's owner measures them in).
fn write_odometry(s: &mut String, o: &OdometryModel) -> std::fmt::Result {
    let sd = o.standard_deviations();
    writeln!(
        s,
        "  wheel radius   left {:.3} ± {:.3} mm   right {:.3} ± {:.3} mm",
        o.left_wheel_radius_m * 1e3,
        sd[0] * 1e3,
        o.right_wheel_radius_m * 1e3,
        sd[1] * 1e3
    )?;
    if let Some([left, right]) = o.wheel_scale {
        writeln!(
            s,
            "  wheel scale    left {left:.5}   right {right:.5}   (real travel over recorded)"
        )?;
    }
    if let Some(latency) = o.lidar_latency_s {
        let sd = o
            .lidar_latency_sd_s
            .map_or(String::new(), |sd| format!(" ± {:.1}", sd * 1e3));
        writeln!(
            s,
            "  lidar latency  {:+.1}{sd} ms   (its stamps against the encoders')",
            latency * 1e3
        )?;
    }
    writeln!(
        s,
        "  wheel base     {:.3} ± {:.3} mm",
        o.wheel_base_m * 1e3,
        sd[2] * 1e3
    )?;
    writeln!(
        s,
        "  lidar mount    x {:.2} ± {:.2} mm   y {:.2} ± {:.2} mm   yaw {:.2} ± {:.2} mrad ({:.3}°)",
        o.lidar_x_m * 1e3,
        sd[3] * 1e3,
        o.lidar_y_m * 1e3,
        sd[4] * 1e3,
        o.lidar_yaw_rad * 1e3,
        sd[5] * 1e3,
        o.lidar_yaw_rad.to_degrees()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIDAR_ONLY: &str = r#"{"method": "em", "sensors": {"lidar": {"alpha": [0.05, 0.9, 0.01], "beta": [0, 0, 0.01]}}}"#;

    fn error(text: &str) -> String {
        Calibration::from_json(text, "cal.json")
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn a_byte_order_mark_before_the_json_is_skipped() {
        let with_mark = format!("\u{feff}{LIDAR_ONLY}");
        let cal = Calibration::from_json(&with_mark, "cal.json").unwrap();
        assert_eq!(cal, Calibration::from_json(LIDAR_ONLY, "cal.json").unwrap());
        assert_eq!(
            Calibration::all_from_json(&with_mark, "cal.json")
                .unwrap()
                .len(),
            1
        );
    }

    #[test]
    fn a_key_named_twice_is_refused_with_its_line() {
        let twice = LIDAR_ONLY.replace(
            r#""method": "em","#,
            "\"method\": \"em\",\n\"method\": \"em\",",
        );
        let err = error(&twice);
        assert!(
            err.starts_with("cal.json:2: the key `method` appears twice"),
            "{err}"
        );
        let nested = LIDAR_ONLY.replace(
            r#""beta": [0, 0, 0.01]"#,
            r#""beta": [0, 0, 0.01], "alpha": []"#,
        );
        assert!(error(&nested).contains("the key `alpha` appears twice"));
        assert!(error("{").contains("cal.json:1: not JSON"));
    }

    #[test]
    fn a_bad_method_is_quoted_terminal_safe_and_a_missing_one_said_so() {
        let hostile = LIDAR_ONLY.replace(r#""em""#, r#""<\u001b[31m>""#);
        let err = error(&hostile);
        assert!(err.ends_with(r#"found "<\u001b[31m>""#), "{err}");
        assert!(!err.contains('\u{1b}'), "{err}");
        assert!(!err.contains("Some("), "{err}");
        let err = error(r#"{"sensors": {}}"#);
        assert!(
            err.ends_with("`method` must be em, landmarks, groundtruth or odometry, found none"),
            "{err}"
        );
        let err = error("[1, 2]");
        assert!(err.contains("expected a JSON object"), "{err}");
    }

    #[test]
    fn a_runs_results_are_not_one_calibration() {
        let results = format!(r#"{{"scenario": "x", "calibrations": [{LIDAR_ONLY}]}}"#);
        let err = error(&results);
        assert!(err.contains("a run's results"), "{err}");
        assert!(err.contains("hilsim calibrate --json"), "{err}");
        // Where a run's results are welcome, they are read.
        assert_eq!(
            Calibration::all_from_json(&results, "r.json")
                .unwrap()
                .len(),
            1
        );
    }

    #[test]
    fn standard_errors_count_one_per_coefficient() {
        let one = LIDAR_ONLY.replace(
            r#""alpha": [0.05, 0.9, 0.01]"#,
            r#""alpha": [0.05, 0.9, 0.01], "alpha_sd": [0.1]"#,
        );
        let err = error(&one);
        assert!(
            err.contains("sensors.lidar.alpha_sd has 1 standard errors for 3 alpha coefficients"),
            "{err}"
        );
        let three = one.replace("[0.1]", "[0.1, 0.1, 0.1]");
        assert!(Calibration::from_json(&three, "cal.json").is_ok());
    }
}
