//! A calibration for people, and read back from the JSON `hilsim calibrate --json` prints.

use std::collections::BTreeMap;
use std::fmt::Write;

use crate::{Calibration, CalibrationError, Method, Sensor, SensorModel};

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

    /// The sensor models of a calibration's JSON (as [`Calibration::to_json`] writes it); the
    /// rest (iterations, metrics, notes) is not read back. `origin` names the text in errors.
    ///
    /// # Errors
    /// [`CalibrationError::Invalid`] naming `origin` (and the line, for malformed JSON).
    pub fn from_json(text: &str, origin: &str) -> Result<Self, CalibrationError> {
        let invalid = |message: String| CalibrationError::Invalid(message);
        let value: serde_json::Value = serde_json::from_str(text)
            .map_err(|err| invalid(format!("{origin}:{}: not JSON: {err}", err.line())))?;
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
                model[key]
                    .as_array()
                    .and_then(|a| {
                        a.iter()
                            .map(serde_json::Value::as_f64)
                            .collect::<Option<Vec<_>>>()
                    })
                    .ok_or_else(|| {
                        invalid(format!(
                            "{origin}: sensors.{name}.{key} must be an array of numbers"
                        ))
                    })
            };
            let model = SensorModel::without_sd(coeffs("alpha")?, coeffs("beta")?);
            sensors.insert(sensor, model);
        }
        Ok(Calibration {
            method,
            sensors,
            iterations: 0,
            converged: true,
            checks: Vec::new(),
            metrics: None,
            order: None,
            landmarks: None,
            notes: Vec::new(),
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
