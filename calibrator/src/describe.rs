//! A calibration for people, and read back from the JSON `hilsim calibrate --json` prints.

use std::collections::BTreeMap;
use std::fmt::Write;

use crate::checks::Check;
use crate::{
    Calibration, CalibrationError, LidarModelMetrics, Method, Metrics, Sensor, SensorModel,
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
                Method::Landmarks | Method::Groundtruth => "lidar distance",
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
        let value: serde_json::Value = serde_json::from_str(text).map_err(|err| {
            CalibrationError::Invalid(format!("{origin}:{}: not JSON: {err}", err.line()))
        })?;
        Self::from_json_value(&value, origin)
    }

    /// Every calibration in a JSON text: one `hilsim calibrate --json` object, or a run's
    /// `results.json` (its `calibrations` list). `origin` names the text in errors.
    ///
    /// # Errors
    /// As [`Calibration::from_json`].
    pub fn all_from_json(text: &str, origin: &str) -> Result<Vec<Self>, CalibrationError> {
        let value: serde_json::Value = serde_json::from_str(text).map_err(|err| {
            CalibrationError::Invalid(format!("{origin}:{}: not JSON: {err}", err.line()))
        })?;
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
        let method = match value["method"].as_str() {
            Some("em") => Method::Em,
            Some("landmarks") => Method::Landmarks,
            Some("groundtruth") => Method::Groundtruth,
            other => {
                return Err(invalid(format!(
                    "{origin}: `method` must be em, landmarks or groundtruth, found {other:?}"
                )))
            }
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
            landmarks: value["landmarks"].as_array().and_then(|list| {
                list.iter()
                    .map(|p| Some([p.get(0)?.as_f64()?, p.get(1)?.as_f64()?]))
                    .collect()
            }),
            notes,
        })
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
