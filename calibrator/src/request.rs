//! What a user asks of the calibrator, as typed (`hilsim calibrate`'s and `hilsim smooth`'s
//! flags), checked into [`Settings`] before any recording is read. Its errors name the flags,
//! since a user reads them as the answer to what they typed.

use std::path::Path;

use crate::landmarks::StopOptions;
use crate::odometry::{RecordingOptions, MAX_INTERVAL_S, MAX_LIDAR_LATENCY_S};
use crate::{em, Calibration, CalibrationError, Method, SampleOptions, Sensor, Settings};

/// A calibration as asked for: the method, whether the input is a tuples file, and each option
/// as given (`None`: the method's default).
#[derive(Debug, Clone, Copy)]
pub struct Request<'a> {
    /// The calibration method.
    pub method: Method,
    /// Whether the input is the paper's tuples rather than a recording (odometry only).
    pub tuples: bool,
    /// The lidar beam facing the target, degrees (EM, ground truth).
    pub beam_deg: Option<f64>,
    /// Lidar-to-target distance at t = 0, metres (EM, ground truth).
    pub start_distance_m: Option<f64>,
    /// How long the robot settles after its wheels stop, seconds (landmarks).
    pub settle_s: Option<f64>,
    /// Lidar revolutions at rest that make a stop usable (landmarks).
    pub min_revolutions: Option<f64>,
    /// Priors on bias coefficients, as `SENSOR.COEF=VALUE±SD` (EM).
    pub priors: &'a [String],
    /// The wheels' nominal radius, metres (odometry).
    pub wheel_radius_m: Option<f64>,
    /// The interval between matched scans, seconds (odometry).
    pub interval_s: Option<f64>,
    /// The lidar's stamps' lateness against the encoders', seconds (odometry).
    pub lidar_latency_s: Option<f64>,
    /// A calibration whose lidar model unbiases the ranges before scan matching (odometry).
    pub lidar_model: Option<&'a Path>,
}

impl Request<'_> {
    /// The calibrator's settings, each option checked in its range and against the method (given
    /// to another method, an option would be silently ignored); the lidar model's calibration is
    /// the one file read.
    ///
    /// # Errors
    /// [`CalibrationError::Invalid`] naming the flag; the lidar model's calibration's error.
    pub fn settings(&self) -> Result<Settings, CalibrationError> {
        let target = target(self.beam_deg, self.start_distance_m)?;
        self.check_ranges()?;
        let odometry_options = self.wheel_radius_m.is_some()
            || self.interval_s.is_some()
            || self.lidar_latency_s.is_some();
        if odometry_options && (self.method != Method::Odometry || self.tuples) {
            return invalid(
                "--wheel-radius-m, --interval-s and --lidar-latency-s are for --method odometry \
                 on a recording",
            );
        }
        if !self.priors.is_empty() && self.method != Method::Em {
            return invalid("--prior: priors are for --method em");
        }
        let stop_options = self.settle_s.is_some() || self.min_revolutions.is_some();
        if stop_options && self.method != Method::Landmarks {
            return invalid("--settle-s and --min-revolutions are for --method landmarks");
        }
        let priors: Vec<em::Prior> = self
            .priors
            .iter()
            .map(|p| p.parse())
            .collect::<Result<_, _>>()?;
        let priors = em::Priors::new(&priors)?;
        let lidar_bias = self.lidar_model.map(lidar_bias).transpose()?;
        if self.tuples && self.method != Method::Odometry {
            return invalid("--tuples: tuples are for --method odometry");
        }
        let (stops, recording) = (StopOptions::default(), RecordingOptions::default());
        Ok(Settings {
            target,
            stops: StopOptions {
                settle_s: self.settle_s,
                min_revolutions: self.min_revolutions.unwrap_or(stops.min_revolutions),
                ..stops
            },
            priors,
            odometry: RecordingOptions {
                nominal_wheel_radius_m: self.wheel_radius_m,
                interval_s: self.interval_s.unwrap_or(recording.interval_s),
                lidar_latency_s: self.lidar_latency_s,
                lidar_bias,
            },
        })
    }

    /// The numbers given, each in its range.
    fn check_ranges(&self) -> Result<(), CalibrationError> {
        let (max_interval, max_latency) = (MAX_INTERVAL_S, MAX_LIDAR_LATENCY_S);
        check(
            self.settle_s,
            |s| (0.0..=86_400.0).contains(&s),
            "--settle-s: expected a settling time in seconds, from 0 to 86400",
        )?;
        check(
            self.min_revolutions,
            |n| (1.0..=1e6).contains(&n),
            "--min-revolutions: expected a number of revolutions from 1 to 1000000",
        )?;
        check(
            self.wheel_radius_m,
            |r| r > 0.0 && r <= 10.0,
            "--wheel-radius-m: expected a radius in metres, more than 0 and at most 10",
        )?;
        check(
            self.interval_s,
            |s| s > 0.0 && s <= max_interval,
            &format!("--interval-s: expected seconds, more than 0 and at most {max_interval}"),
        )?;
        check(
            self.lidar_latency_s,
            |s| s.abs() <= max_latency,
            &format!("--lidar-latency-s: expected seconds from -{max_latency} to {max_latency}"),
        )
    }
}

/// The target's beam (`--beam`, default 0) and start distance (`--start-distance`), checked.
///
/// # Errors
/// [`CalibrationError::Invalid`] for an angle that is not finite or a distance out of
/// [`START_DISTANCE_RANGE_M`](crate::START_DISTANCE_RANGE_M).
pub fn target(
    beam_deg: Option<f64>,
    start_distance_m: Option<f64>,
) -> Result<SampleOptions, CalibrationError> {
    let beam_deg = beam_deg.unwrap_or(0.0);
    if !beam_deg.is_finite() {
        return invalid("--beam: expected a finite angle in degrees");
    }
    let range = crate::START_DISTANCE_RANGE_M;
    if let Some(d) = start_distance_m.filter(|d| !range.contains(d)) {
        let (lo, hi) = (range.start(), range.end());
        return invalid(&format!(
            "--start-distance: expected a distance from {lo} to {hi} m, found {d:?}"
        ));
    }
    Ok(SampleOptions {
        beam_deg,
        start_distance_m,
    })
}

/// Refuses a `value` that `ok` does not accept, saying `expected`.
fn check(
    value: Option<f64>,
    ok: impl Fn(f64) -> bool,
    expected: &str,
) -> Result<(), CalibrationError> {
    match value {
        Some(v) if !(v.is_finite() && ok(v)) => invalid(expected),
        _ => Ok(()),
    }
}

fn invalid<T>(message: &str) -> Result<T, CalibrationError> {
    Err(CalibrationError::Invalid(message.to_owned()))
}

/// The range bias of the lidar model in the calibration at `path` (`--lidar-model`).
fn lidar_bias(path: &Path) -> Result<Vec<f64>, CalibrationError> {
    let model = Calibration::read(path)?;
    let Some(lidar) = model.sensors.get(&Sensor::Lidar) else {
        let method = model.method.name();
        return invalid(&format!(
            "{}: the {method} method's calibration has no lidar model",
            path.display()
        ));
    };
    Ok(lidar.alpha.clone())
}
