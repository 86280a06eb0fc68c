//! Reusing a calibration (the EM paper's Sec. V): with the sensors' parameters trained once,
//! a new recording's distances come from a single Kalman/RTS smoother pass of the EM model,
//! without re-running EM.
//!
//! The pass is the E-step of [`crate::em`] at the trained parameters, linearised (the
//! heteroscedastic `R_k`) at the dead-reckoned distance; [`crate::em::EStep::Relinearized`]
//! adds a second pass linearised at the first one's smoothed distance. The paper linearises at
//! `[1, mean(y), mean(y)²]`; dead reckoning is closer to the truth at every sample.
//!
//! **Start distance.** When it is known (options or `meta.toml`) the first distance is exactly
//! it, as in EM. When not, the calibrated lidar is trusted to supply it: the first valid reading
//! is inverted through the trained bias, with a prior sd ten times the reading's (so that using
//! the reading for both the prior and the update counts it once to within 1 %).
//!
//! **Odometer.** The odometer's "distance" is the start distance plus the encoder travel, so
//! its fitted offset `α0 = (1 − α1) d_0` depends on the training run's start. On a new
//! recording it is recomputed as `(1 − α1) d_0'` from the new start (encoder travel is zero at
//! t = 0 by the recording format); without a known start the odometer is not used.
//!
//! ```no_run
//! use hilsim_calibrator::{em, smoothing};
//! use hilsim_recording::Recording;
//! let train = Recording::read_dir("train".as_ref())?;
//! let test = Recording::read_dir("test".as_ref())?;
//! let opts = em::EmOptions::default();
//! let trained = em::calibrate(&train, &opts)?;
//! for e in smoothing::smooth(&test, &trained, &opts)? {
//!     println!("{},{},{}", e.t_s, e.distance_m, e.sd_m());
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use hilsim_recording::Recording;

use crate::checks::{self, Check};
/// The smoothed distance at one sample (EM's, re-exported here for the smoother's callers).
pub use crate::em::Estimate;
use crate::em::{self, EmOptions, Lin, Params, SensorParams, LIDAR, ODOMETER, SONAR};
use crate::kalman_smoother::RtsSmoother;
use crate::target_samples::{self, TargetSamples};
use crate::{groundtruth, Calibration, CalibrationError, Sensor, SensorModel};

/// Prior sd of the first distance, in units of the first lidar reading's sd, when the start
/// distance is unknown (see the module docs).
const UNKNOWN_START_SD_FACTOR: f64 = 10.0;

/// Smooths a recording's distances with a trained calibration.
///
/// # Errors
/// [`CalibrationError::Missing`] when the calibration has no lidar model or the recording no
/// lidar; [`CalibrationError::Invalid`] for a model outside the paper's orders (bias above
/// quadratic, noise polynomial above quadratic) or with non-finite coefficients; otherwise as
/// [`crate::target_samples::extract`] and [`CalibrationError::Diverged`] if the pass fails.
pub fn smooth(
    rec: &Recording,
    trained: &Calibration,
    opts: &EmOptions,
) -> Result<Vec<Estimate>, CalibrationError> {
    smooth_checked(rec, trained, opts).map(|(estimates, _)| estimates)
}

/// The calibration at `path` for the smoother: read, and holding a sensor model to apply (em's
/// lidar, sonar, odometer).
///
/// # Errors
/// As [`Calibration::read`]; a calibration without a sensor model.
pub fn read_trained(path: &std::path::Path) -> Result<Calibration, CalibrationError> {
    let trained = Calibration::read(path)?;
    if trained.sensors.is_empty() {
        return Err(CalibrationError::Invalid(format!(
            "{}: the {} method's calibration holds no sensor model; smooth applies em's (lidar, \
             sonar, odometer)",
            path.display(),
            trained.method.name()
        )));
    }
    Ok(trained)
}

/// As [`smooth`], with the recording checked against the calibration as EM checks its own
/// ([`crate::checks`]): a straight run at one target, the lidar's innovations of the trained
/// size and white. A recording the calibration does not fit (another lidar, a wrong start
/// distance) fails them instead of giving confident wrong distances.
///
/// # Errors
/// As [`smooth`].
pub fn smooth_checked(
    rec: &Recording,
    trained: &Calibration,
    opts: &EmOptions,
) -> Result<(Vec<Estimate>, Vec<Check>), CalibrationError> {
    let samples = target_samples::extract(rec, &opts.sample_options())?;
    let (estimates, mut checks) = smooth_samples_checked(&samples, trained, opts)?;
    checks.extend(checks::on_a_line(rec));
    Ok((estimates, checks))
}

/// As [`smooth`], on samples already drawn from a recording.
///
/// # Errors
/// As [`smooth`].
pub fn smooth_samples(
    samples: &TargetSamples,
    trained: &Calibration,
    opts: &EmOptions,
) -> Result<Vec<Estimate>, CalibrationError> {
    smooth_samples_checked(samples, trained, opts).map(|(estimates, _)| estimates)
}

/// As [`smooth_samples`], with the checks that need only the samples.
fn smooth_samples_checked(
    samples: &TargetSamples,
    trained: &Calibration,
    opts: &EmOptions,
) -> Result<(Vec<Estimate>, Vec<Check>), CalibrationError> {
    if !(opts.process_noise_rel >= 0.0 && opts.process_noise_rel.is_finite()) {
        return Err(CalibrationError::Invalid(format!(
            "process_noise_rel must be non-negative, got {}",
            opts.process_noise_rel
        )));
    }
    let Some(lidar_model) = trained.sensors.get(&Sensor::Lidar) else {
        return Err(CalibrationError::Missing(
            "the calibration has no lidar model to smooth with".into(),
        ));
    };
    let mut params = Params {
        sensors: [
            to_params(LIDAR, lidar_model)?,
            SensorParams::paper(ODOMETER),
            SensorParams::paper(SONAR),
        ],
        q_rel: opts.process_noise_rel,
        // The speed scale EM estimated belongs to the training run's drive, not this one's.
        speed_scale: 1.0,
    };
    let (start, prior_var) = match samples.start_distance_m {
        Some(d0) => (d0, 0.0),
        None => unknown_start(samples, &params.sensors[LIDAR])?,
    };
    if let Some(model) = trained.sensors.get(&Sensor::Odometer) {
        if opts.use_odometer && samples.start_distance_m.is_some() {
            let mut p = to_params(ODOMETER, model)?;
            p.alpha[0] = (1.0 - p.alpha[1]) * start;
            params.sensors[ODOMETER] = p;
        }
    }
    if let Some(model) = trained.sensors.get(&Sensor::Sonar) {
        if opts.use_sonar {
            params.sensors[SONAR] = to_params(SONAR, model)?;
        }
    }
    // `build_data` activates a slot only if the recording has that sensor; keep the trained
    // parameters and let it decide.
    let wanted = params.sensors.map(|s| s.active);
    for s in &mut params.sensors[1..] {
        s.active = false;
    }
    let mut notes = Vec::new();
    let mut data_params = params;
    let opts_data = EmOptions {
        use_odometer: wanted[ODOMETER],
        use_sonar: wanted[SONAR],
        ..*opts
    };
    let mut data = em::build_data(samples, start, &mut data_params, &opts_data, &mut notes);
    for slot in [ODOMETER, SONAR] {
        params.sensors[slot].active = data_params.sensors[slot].active;
    }
    data.prior_var = prior_var;
    let mut lin: Vec<Lin> = (0..samples.len())
        .map(|k| Lin::exact(start + samples.commanded_m[k]))
        .collect();
    let mut smoother = RtsSmoother::<2>::new();
    em::e_step(&mut smoother, &data, &params, &mut lin, opts.e_step)?;
    let innovations = em::lidar_innovations(&data, &params, &smoother, opts);
    let mut checks: Vec<Check> =
        checks::target_follows_commands(&samples.commanded_m, &samples.lidar_m)
            .into_iter()
            .collect();
    checks.extend(checks::lidar_innovations(&innovations));
    Ok((em::estimates(samples, &smoother), checks))
}

/// The EM model's parameters from a fitted model, if its orders fit the paper's state.
fn to_params(slot: usize, model: &SensorModel) -> Result<SensorParams, CalibrationError> {
    let name = ["lidar", "odometer", "sonar"][slot];
    let mut p = SensorParams::paper(slot);
    let max_alpha = if slot == LIDAR { 3 } else { 2 };
    if model.alpha.len() < 2 || model.alpha.len() > max_alpha {
        return Err(CalibrationError::Invalid(format!(
            "the {name} bias has {} coefficients; smoothing takes 2..={max_alpha} (the EM \
             paper's state is [1, d, d²])",
            model.alpha.len()
        )));
    }
    if model.beta.is_empty() || model.beta.len() > 3 {
        return Err(CalibrationError::Invalid(format!(
            "the {name} noise has {} coefficients; smoothing takes 1..=3",
            model.beta.len()
        )));
    }
    if !model.alpha.iter().chain(&model.beta).all(|v| v.is_finite()) {
        return Err(CalibrationError::Invalid(format!(
            "the {name} model has a non-finite coefficient"
        )));
    }
    p.active = true;
    p.alpha = [0.0; 3];
    p.alpha[..model.alpha.len()].copy_from_slice(&model.alpha);
    p.beta[..model.beta.len()].copy_from_slice(&model.beta);
    Ok(p)
}

/// Start distance and prior variance from the first invertible lidar reading.
fn unknown_start(
    samples: &TargetSamples,
    lidar: &SensorParams,
) -> Result<(f64, f64), CalibrationError> {
    for (k, y) in samples.lidar_m.iter().enumerate() {
        let Some(y) = *y else { continue };
        let Some(d) = groundtruth::invert(&lidar.alpha, y) else {
            continue;
        };
        let slope = lidar.alpha[1] + 2.0 * lidar.alpha[2] * d;
        let sd_y = lidar.beta[0] + lidar.beta[1] * d + lidar.beta[2] * d * d;
        let sd_d = UNKNOWN_START_SD_FACTOR * sd_y.abs() / slope.abs().max(1e-6);
        // Back to t = 0 along the commanded motion.
        let start = d - samples.commanded_m[k];
        if start > 0.0 && sd_d.is_finite() {
            return Ok((start, sd_d * sd_d));
        }
    }
    Err(CalibrationError::Missing(
        "no start distance, and no lidar reading the calibration can invert to supply one".into(),
    ))
}
