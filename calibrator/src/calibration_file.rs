//! A calibration file: the JSON `hilsim calibrate --json` printed, or a run's `results.json`,
//! read within a bound whatever the path is. Its fields read as `Calibration`'s serde
//! attributes say; this module adds what is true of the file as a whole.

use std::io::Read;
use std::path::Path;

use serde::de::{DeserializeOwned, DeserializeSeed, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use serde_json::Value;

use crate::calibration::lenient::shown;
use crate::{Calibration, CalibrationError};

/// Most bytes of a calibration file: a calibration is a few hundred bytes and a run's results
/// a few kilobytes.
const MAX_CALIBRATION_BYTES: u64 = 1 << 20;

impl Calibration {
    /// Reads the JSON that `hilsim calibrate --json` printed, from the file at `path`.
    ///
    /// # Errors
    /// The file cannot be read, is larger than 1 MiB, or holds no calibration.
    pub fn read(path: &Path) -> Result<Self, CalibrationError> {
        Self::from_json(&read_text(path)?, &path.display().to_string())
    }

    /// Every calibration in the file at `path`: one `hilsim calibrate --json` object, or a
    /// run's `results.json`.
    ///
    /// # Errors
    /// As [`Calibration::read`].
    pub fn read_all(path: &Path) -> Result<Vec<Self>, CalibrationError> {
        Self::all_from_json(&read_text(path)?, &path.display().to_string())
    }

    /// A calibration read back from its JSON (as [`Calibration::to_json`] writes it). `origin`
    /// names the text in errors.
    ///
    /// # Errors
    /// [`CalibrationError::Invalid`] naming `origin` and, where there is one, the line.
    pub fn from_json(text: &str, origin: &str) -> Result<Self, CalibrationError> {
        let text = without_byte_order_mark(text);
        match Shape::of(text, origin)? {
            Shape::Results => Err(CalibrationError::Invalid(format!(
                "{origin}: a run's results (a `calibrations` list), not one calibration: give \
                 the JSON that `hilsim calibrate --json` prints"
            ))),
            Shape::One => typed(text, origin),
        }
    }

    /// Every calibration in a JSON text: one `hilsim calibrate --json` object, or a run's
    /// `results.json` (its `calibrations` list). `origin` names the text in errors.
    ///
    /// # Errors
    /// As [`Calibration::from_json`].
    pub fn all_from_json(text: &str, origin: &str) -> Result<Vec<Self>, CalibrationError> {
        /// A run's results, as far as they hold calibrations.
        #[derive(Deserialize)]
        struct RunResults {
            calibrations: Vec<Calibration>,
        }
        let text = without_byte_order_mark(text);
        match Shape::of(text, origin)? {
            Shape::Results => Ok(typed::<RunResults>(text, origin)?.calibrations),
            Shape::One => Ok(vec![typed(text, origin)?]),
        }
    }
}

fn read_text(path: &Path) -> Result<String, CalibrationError> {
    let cannot_read =
        |err| CalibrationError::Invalid(format!("{}: cannot read: {err}", path.display()));
    let file = std::fs::File::open(path).map_err(cannot_read)?;
    let mut text = String::new();
    file.take(MAX_CALIBRATION_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(cannot_read)?;
    if text.len() as u64 > MAX_CALIBRATION_BYTES {
        let why = format!("{}: larger than 1 MiB; not a calibration", path.display());
        return Err(CalibrationError::Invalid(why));
    }
    Ok(text)
}

/// The text after a byte-order mark some editors write first (RFC 8259 lets a parser ignore it).
fn without_byte_order_mark(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// What a calibration file holds at its top level.
enum Shape {
    /// One calibration.
    One,
    /// A run's results: a `calibrations` list.
    Results,
}

impl Shape {
    /// The shape of a JSON text, which must be well formed, name no key twice in one object (the
    /// second would silently replace the first) and be an object; in a run's results, each
    /// calibration an object.
    fn of(text: &str, origin: &str) -> Result<Self, CalibrationError> {
        let mut de = serde_json::Deserializer::from_str(text);
        let value = NoDuplicateKeys
            .deserialize(&mut de)
            .and_then(|value| de.end().map(|()| value))
            .map_err(|err| invalid(origin, &err))?;
        let object = |value: &Value, origin: &str| {
            if value.is_object() {
                Ok(())
            } else {
                Err(CalibrationError::Invalid(format!(
                    "{origin}: expected a JSON object (as `hilsim calibrate --json` prints), found {}",
                    shown(value)
                )))
            }
        };
        object(&value, origin)?;
        match value.get("calibrations") {
            Some(Value::Array(list)) => {
                for (i, c) in list.iter().enumerate() {
                    object(c, &format!("{origin}: calibrations[{i}]"))?;
                }
                Ok(Shape::Results)
            }
            Some(_) => Err(CalibrationError::Invalid(format!(
                "{origin}: `calibrations` must be a list"
            ))),
            None => Ok(Shape::One),
        }
    }
}

/// `text` read as a `T`.
fn typed<T: DeserializeOwned>(text: &str, origin: &str) -> Result<T, CalibrationError> {
    serde_json::from_str(text).map_err(|err| invalid(origin, &err))
}

/// A JSON error as one terminal-safe line: the origin, the line, and serde_json's message (which
/// ends with the line and column).
fn invalid(origin: &str, err: &serde_json::Error) -> CalibrationError {
    let what = if err.classify() == serde_json::error::Category::Data {
        ""
    } else {
        "not JSON: "
    };
    let message = err.to_string();
    CalibrationError::Invalid(format!(
        "{origin}:{}: {what}{}",
        err.line(),
        hilsim_recording::printable(&message)
    ))
}

/// Deserializes any JSON value, refusing an object that names a key twice.
struct NoDuplicateKeys;

impl<'de> DeserializeSeed<'de> for NoDuplicateKeys {
    type Value = Value;

    fn deserialize<D: serde::Deserializer<'de>>(self, de: D) -> Result<Self::Value, D::Error> {
        de.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for NoDuplicateKeys {
    type Value = Value;

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
        Ok(Value::Null)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut list = Vec::new();
        while let Some(item) = seq.next_element_seed(NoDuplicateKeys)? {
            list.push(item);
        }
        Ok(list.into())
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
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

#[cfg(test)]
mod tests {
    use proptest::collection::{btree_map, vec};
    use proptest::option;
    use proptest::prelude::*;

    use super::*;
    use crate::checks::Check;
    use crate::{LidarModelMetrics, Method, Metrics, OdometryModel, Sensor, SensorModel};

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
        assert!(
            err.starts_with(
                r#"cal.json:1: `method` must be em, landmarks, groundtruth or odometry, found "<\u001b[31m>" at line 1 column"#
            ),
            "{err}"
        );
        assert!(!err.contains('\u{1b}'), "{err}");
        assert!(!err.contains("Some("), "{err}");
        let err = error(r#"{"sensors": {}}"#);
        assert!(
            err.starts_with("cal.json:1: missing field `method` at line 1 column"),
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

    #[test]
    fn what_only_describes_the_result_reads_as_absent_where_malformed() {
        let sloppy = r#"{"method": "landmarks", "iterations": "many", "converged": null,
            "metrics": {"mse_raw": null, "mse_calibrated": 1, "nmse_raw": 1, "nmse_calibrated": 1},
            "order": -1, "landmarks": [[1, 2], "x"], "unknown": {"a": 1},
            "sensors": {"lidar": {"alpha": [0, 1], "beta": [0.01], "alpha_sd": null}, "sonar": null, "camera": 1},
            "checks": [{"name": "a", "pass": true, "value": null}, {"name": "b"}, 3],
            "notes": ["kept", 7]}"#;
        let cal = Calibration::from_json(sloppy, "cal.json").unwrap();
        assert_eq!(cal.method, Method::Landmarks);
        assert_eq!((cal.iterations, cal.converged), (0, true));
        assert_eq!(
            (cal.metrics, cal.order, &cal.landmarks),
            (None, None, &None)
        );
        assert_eq!(
            cal.sensors.keys().collect::<Vec<_>>(),
            [&Sensor::Lidar],
            "null and unknown sensors skipped"
        );
        assert!(cal.sensors[&Sensor::Lidar].alpha_sd.is_empty());
        assert_eq!(cal.checks.len(), 1);
        assert!(cal.checks[0].value.is_nan() && cal.checks[0].threshold.is_nan());
        assert_eq!(cal.notes, ["kept"]);
        // The models themselves are not guessed at.
        let err = error(&LIDAR_ONLY.replace("[0.05, 0.9, 0.01]", r#"[0.05, "x", 0.01]"#));
        assert!(
            err.starts_with(
                r#"cal.json:1: invalid type: string "x", expected f64 at line 1 column"#
            ),
            "{err}"
        );
    }

    /// A calibration of any shape the calibrator makes, with finite figures (a NaN is written as
    /// `null`, which reads back as absent or NaN, never equal).
    fn any_calibration() -> impl Strategy<Value = Calibration> {
        let figure = || prop_oneof![-1e3..1e3f64, -1e-6..1e-6f64, proptest::num::f64::NORMAL];
        let model = (1..4usize, any::<bool>()).prop_flat_map(move |(n, with_sd)| {
            let sd = if with_sd { n } else { 0 };
            (
                vec(figure(), n),
                vec(figure(), n),
                vec(figure(), sd),
                vec(figure(), sd),
            )
                .prop_map(|(alpha, beta, alpha_sd, beta_sd)| SensorModel {
                    alpha,
                    beta,
                    alpha_sd,
                    beta_sd,
                })
        });
        let sensors = btree_map(proptest::sample::select(Sensor::ALL.to_vec()), model, 0..=3);
        let lidar_model = option::of((figure(), figure(), figure(), any::<usize>()).prop_map(
            |(mse_raw, mse_calibrated, mse_ratio, readings)| LidarModelMetrics {
                mse_raw,
                mse_calibrated,
                mse_ratio,
                readings,
            },
        ));
        let metrics = option::of(
            (figure(), figure(), figure(), figure(), lidar_model).prop_map(
                |(mse_raw, mse_calibrated, nmse_raw, nmse_calibrated, lidar_model)| Metrics {
                    mse_raw,
                    mse_calibrated,
                    nmse_raw,
                    nmse_calibrated,
                    lidar_model,
                },
            ),
        );
        let odometry = option::of(
            (
                vec(figure(), 6),
                vec(figure(), 36),
                option::of([figure(), figure()]),
                option::of(figure()),
                option::of(figure()),
            )
                .prop_map(
                    |(p, c, wheel_scale, lidar_latency_s, lidar_latency_sd_s)| OdometryModel {
                        left_wheel_radius_m: p[0],
                        right_wheel_radius_m: p[1],
                        wheel_base_m: p[2],
                        lidar_x_m: p[3],
                        lidar_y_m: p[4],
                        lidar_yaw_rad: p[5],
                        covariance: std::array::from_fn(|i| std::array::from_fn(|j| c[6 * i + j])),
                        wheel_scale,
                        lidar_latency_s,
                        lidar_latency_sd_s,
                    },
                ),
        );
        let check = (
            "\\PC{0,12}",
            figure(),
            figure(),
            any::<bool>(),
            "\\PC{0,30}",
        )
            .prop_map(|(name, value, threshold, pass, detail)| Check {
                name,
                value,
                threshold,
                pass,
                detail,
            });
        (
            proptest::sample::select(Method::ALL.to_vec()),
            sensors,
            (any::<usize>(), any::<bool>()),
            metrics,
            option::of(any::<usize>()),
            option::of(vec([figure(), figure()], 0..4)),
            odometry,
            vec(check, 0..4),
            vec("\\PC{0,40}", 0..3),
        )
            .prop_map(
                |(
                    method,
                    sensors,
                    (iterations, converged),
                    metrics,
                    order,
                    landmarks,
                    odometry,
                    checks,
                    notes,
                )| {
                    Calibration {
                        method,
                        sensors,
                        iterations,
                        converged,
                        metrics,
                        order,
                        landmarks,
                        odometry,
                        checks,
                        notes,
                    }
                },
            )
    }

    proptest! {
        #[test]
        fn a_calibration_reads_back_from_its_json_as_it_was(cal in any_calibration()) {
            let text = serde_json::to_string_pretty(&cal.to_json()).unwrap();
            prop_assert_eq!(Calibration::from_json(&text, "cal.json").unwrap(), cal.clone());
            let results = serde_json::json!({"calibrations": [cal.to_json(), cal.to_json()]});
            prop_assert_eq!(
                Calibration::all_from_json(&results.to_string(), "results.json").unwrap(),
                vec![cal.clone(), cal]
            );
        }
    }
}
