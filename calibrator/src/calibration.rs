//! The result every calibration method returns, serialised exactly as `hilsim calibrate --json`
//! prints it (interfaces.md).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

pub(crate) mod lenient;

/// The calibration methods and the sensors they calibrate (one definition each, shared with
/// the scenario files: `hilsim_recording::names`).
pub use hilsim_recording::{Method, Sensor};

/// The fitted model of one sensor, eq. (2) of both papers:
/// `reading = Σ alpha_i d^i + (Σ beta_i d^i) e`, lowest order first, metres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorModel {
    /// Bias coefficients alpha_0..
    pub alpha: Vec<f64>,
    /// Noise coefficients beta_0..
    pub beta: Vec<f64>,
    /// One standard error per alpha coefficient (each method's own: see its docs); empty when
    /// unknown (a model read back from JSON without them).
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        deserialize_with = "lenient::null_as_default"
    )]
    pub alpha_sd: Vec<f64>,
    /// One standard error per beta coefficient (0 for a coefficient the method holds at 0).
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        deserialize_with = "lenient::null_as_default"
    )]
    pub beta_sd: Vec<f64>,
}

impl SensorModel {
    /// A model whose standard errors are not known.
    #[must_use]
    pub fn without_sd(alpha: Vec<f64>, beta: Vec<f64>) -> Self {
        Self {
            alpha,
            beta,
            alpha_sd: Vec::new(),
            beta_sd: Vec::new(),
        }
    }
}

/// A differential drive's wheels and the lidar's pose on it, as `--method odometry` estimates
/// them (Censi, Franchi, Marchionni, Oriolo, IEEE T-RO 29(2), 2013).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OdometryModel {
    /// The left wheel's radius, metres.
    pub left_wheel_radius_m: f64,
    /// The right wheel's radius, metres.
    pub right_wheel_radius_m: f64,
    /// The distance between the wheels' contact points, metres.
    pub wheel_base_m: f64,
    /// The lidar's position on the robot, forward of the axle's centre, metres.
    pub lidar_x_m: f64,
    /// The lidar's position on the robot, left of the axle's centre, metres.
    pub lidar_y_m: f64,
    /// The lidar's yaw on the robot, counter-clockwise, radians.
    pub lidar_yaw_rad: f64,
    /// The estimate's covariance, in the order of the fields above (m², m·rad, rad²).
    pub covariance: [[f64; 6]; 6],
    /// Each wheel's radius over the nominal one the recording's travel was reported with
    /// (`meta.toml`'s `[robot] wheel_radius_m`): the factor the recorded travel is short by.
    /// Absent for tuples, whose wheel speeds are angular already.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wheel_scale: Option<[f64; 2]>,
    /// How late the lidar's stamps are against the encoders', seconds, as the intervals were cut
    /// with (estimated unless given). Absent for tuples.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lidar_latency_s: Option<f64>,
    /// The estimated latency's standard deviation, seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lidar_latency_sd_s: Option<f64>,
}

impl OdometryModel {
    /// The standard deviations, in the covariance's order.
    #[must_use]
    pub fn standard_deviations(&self) -> [f64; 6] {
        std::array::from_fn(|i| self.covariance[i][i].max(0.0).sqrt())
    }

    /// The parameters, in the covariance's order.
    #[must_use]
    pub fn parameters(&self) -> [f64; 6] {
        [
            self.left_wheel_radius_m,
            self.right_wheel_radius_m,
            self.wheel_base_m,
            self.lidar_x_m,
            self.lidar_y_m,
            self.lidar_yaw_rad,
        ]
    }
}

/// Distance-estimate quality against the truth, when the recording has truth.
///
/// `mse_*` is the mean squared error of the distance estimates (raw: the sensor's readings as
/// distances; calibrated: the method's estimates), metres²; `nmse_*` is the EM paper's
/// normalised MSE (Fig. 3): the mean over samples of each squared error divided by that
/// sample's squared true distance (dimensionless).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// MSE of the raw readings.
    pub mse_raw: f64,
    /// MSE of the calibrated estimates.
    pub mse_calibrated: f64,
    /// Normalised MSE of the raw readings.
    pub nmse_raw: f64,
    /// Normalised MSE of the calibrated estimates.
    pub nmse_calibrated: f64,
    /// The lidar model alone: each raw reading inverted through the fitted lidar model. For
    /// EM the figures above measure the smoothed distance, which also fuses the commands, the
    /// odometer and the sonar, and can look good while the lidar model is wrong.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "lenient::or_none"
    )]
    pub lidar_model: Option<LidarModelMetrics>,
}

/// How well the fitted lidar model alone turns raw readings into distances: each raw reading
/// inverted through it (the landmark paper's eq. 30) against the true distance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LidarModelMetrics {
    /// MSE of the raw readings, m².
    pub mse_raw: f64,
    /// MSE of the inverted readings, m².
    pub mse_calibrated: f64,
    /// Raw over calibrated: eq. (31) for the lidar model alone. Larger is better.
    pub mse_ratio: f64,
    /// Readings scored.
    pub readings: usize,
}

impl LidarModelMetrics {
    /// The figures of `raw` readings and their `inverted` distances against `truth`, over the
    /// triples where all three are finite; `None` when there is none.
    #[must_use]
    pub fn score(triples: impl IntoIterator<Item = (f64, f64, f64)>) -> Option<Self> {
        let (mut raw, mut inverted, mut n) = (0.0, 0.0, 0usize);
        for (r, i, d) in triples {
            if r.is_finite() && i.is_finite() && d.is_finite() {
                raw += (r - d).powi(2);
                inverted += (i - d).powi(2);
                n += 1;
            }
        }
        (n > 0).then(|| {
            let (mse_raw, mse_calibrated) = (raw / n as f64, inverted / n as f64);
            Self {
                mse_raw,
                mse_calibrated,
                mse_ratio: mse_raw / mse_calibrated,
                readings: n,
            }
        })
    }
}

impl Metrics {
    /// The landmark paper's MSE ratio (31): raw over calibrated. Larger is better.
    #[must_use]
    pub fn mse_ratio(&self) -> f64 {
        self.mse_raw / self.mse_calibrated
    }
}

/// What a calibration found.
///
/// Read back from its JSON, only `method` and the sensor models must be there and well formed
/// (and `odometry`, when there); the figures that only describe the result read as absent (or
/// 0 iterations, converged) where they are missing or malformed (`calibration/lenient.rs`).
/// Keys it does not know are ignored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// The method used.
    #[serde(deserialize_with = "lenient::method")]
    pub method: Method,
    /// One model per calibrated sensor; sensors absent from the recording are absent here.
    #[serde(default, deserialize_with = "lenient::sensors")]
    pub sensors: BTreeMap<Sensor, SensorModel>,
    /// Iterations the method ran (1 for closed-form methods).
    #[serde(default, deserialize_with = "lenient::or_default")]
    pub iterations: usize,
    /// Whether it met its convergence criterion.
    #[serde(
        default = "lenient::yes",
        deserialize_with = "lenient::true_unless_false"
    )]
    pub converged: bool,
    /// Quality against the truth; present only when the recording has truth.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "lenient::or_none"
    )]
    pub metrics: Option<Metrics>,
    /// The selected polynomial order (landmarks).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "lenient::or_none"
    )]
    pub order: Option<usize>,
    /// Estimated landmark centres, metres, in the frame of the robot's pose at the start of the
    /// recording (x forward, y left) (landmarks).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "lenient::or_none"
    )]
    pub landmarks: Option<Vec<[f64; 2]>>,
    /// The wheels and the lidar's mount (odometry).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub odometry: Option<OdometryModel>,
    /// The method's assumptions tested on the data ([`crate::checks`]); a failed one makes
    /// `hilsim calibrate` exit 1 with the result still printed.
    #[serde(default, deserialize_with = "lenient::readable_items")]
    pub checks: Vec<crate::checks::Check>,
    /// Further method-specific facts for people: what was skipped and why (stops too short, a
    /// landmark track dropped), choices made (AIC and cross-validation). In the JSON as `notes`
    /// when there are any; their wording is not an interface.
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        deserialize_with = "lenient::readable_items"
    )]
    pub notes: Vec<String>,
}

impl Calibration {
    /// The checks that failed.
    pub fn failed_checks(&self) -> impl Iterator<Item = &crate::checks::Check> {
        self.checks.iter().filter(|c| !c.pass)
    }

    /// When a check failed, why the result is not to be trusted, as one line naming the
    /// failed checks.
    #[must_use]
    pub fn untrusted(&self) -> Option<String> {
        let failed: Vec<&str> = self.failed_checks().map(|c| c.name.as_str()).collect();
        (!failed.is_empty()).then(|| {
            format!(
                "the recording does not fit the method's assumptions ({}); the result above is \
                 not to be trusted",
                failed.join(", ")
            )
        })
    }

    /// The JSON object of `hilsim calibrate --json`.
    #[must_use]
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }
}
