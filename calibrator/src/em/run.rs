//! A run of EM: the samples checked, θ^(0) from dead reckoning, the iteration, and the
//! calibration with its notes.

use std::collections::BTreeMap;

use nalgebra::Vector2;

use super::engine::Engine;
use super::estep::{build_data, e_step};
use super::estimate::{estimates, Estimate};
use super::information;
use super::model::{Data, Free, Lin, Params, SensorParams, LIDAR, ODOMETER, SONAR};
use super::mstep;
use super::options::{EmOptions, MIN_LIDAR_READINGS, MIN_SPAN_M};
use crate::kalman_smoother::RtsSmoother;
use crate::target_samples::{self, TargetSamples};
use crate::{checks, Calibration, CalibrationError, Method, Metrics, Sensor, SensorModel};

/// Everything a run of EM produced.
#[derive(Debug, Clone)]
pub struct EmOutcome {
    /// The calibration (what [`calibrate`] returns).
    pub calibration: Calibration,
    /// The samples it was computed from.
    pub samples: TargetSamples,
    /// The smoothed distance of every sample under the final parameters.
    pub estimates: Vec<Estimate>,
    /// Log-likelihood `log p(y; θ^(t))` from each E-step, the last one at the final
    /// parameters (under the linearisation in force at that step; see [`EStep`]).
    pub log_likelihoods: Vec<f64>,
    /// The process-noise scale used at the end (estimated or as given).
    pub process_noise_rel: f64,
}

/// Calibrates the recording's lidar (and odometer, sonar) without ground truth.
///
/// # Errors
/// [`CalibrationError`] for bad input (see the module's requirements) or a diverging estimate.
pub fn calibrate(
    rec: &hilsim_recording::Recording,
    opts: &EmOptions,
) -> Result<Calibration, CalibrationError> {
    run(rec, opts).map(|o| o.calibration)
}

/// As [`calibrate`], returning the smoothed distances and the log-likelihood trace too.
///
/// # Errors
/// As [`calibrate`].
pub fn run(
    rec: &hilsim_recording::Recording,
    opts: &EmOptions,
) -> Result<EmOutcome, CalibrationError> {
    opts.validate()?;
    let samples = target_samples::extract(rec, &opts.sample_options())?;
    let mut outcome = run_samples(samples, opts)?;
    // The paper's experiment: straight towards or away from one target.
    outcome.calibration.checks.extend(checks::on_a_line(rec));
    Ok(outcome)
}

/// EM on samples already drawn from a recording.
///
/// # Errors
/// As [`calibrate`].
pub fn run_samples(
    samples: TargetSamples,
    opts: &EmOptions,
) -> Result<EmOutcome, CalibrationError> {
    opts.validate()?;
    let (start, valid) = check_samples(&samples)?;
    let mut notes = Vec::new();
    let (data, params, lin) = initial_params(&samples, start, opts, &mut notes)?;
    let fit = iterate(&data, opts, params, lin)?;
    let estimates = estimates(&samples, &fit.smoother);
    push_notes(&mut notes, &samples, opts, &fit, valid, start);
    let lidar_alpha = fit.params.sensors[super::model::LIDAR].alpha;
    let metrics = samples.truth_m.as_ref().and_then(|truth| {
        let calibrated: Vec<Option<f64>> = estimates.iter().map(|e| Some(e.distance_m)).collect();
        target_samples::distance_metrics(truth, &samples.lidar_m, &calibrated).map(|m| Metrics {
            lidar_model: target_samples::lidar_model_metrics(truth, &samples.lidar_m, &lidar_alpha),
            ..m
        })
    });
    let standard_errors = information::standard_errors(&data, &fit.params, &fit.lin, opts);
    if standard_errors.is_none() {
        notes.push(
            "standard errors unavailable: the observed information is not positive definite \
             (a parameter the data does not determine)"
                .into(),
        );
    }
    let sensors = sensor_models(&fit.params, standard_errors.as_deref());
    let mut checks = Vec::new();
    for (sensor, model) in &sensors {
        checks.extend(checks::bias_plausible(sensor.name(), model));
    }
    checks.extend(checks::target_follows_commands(
        &samples.commanded_m,
        &samples.lidar_m,
    ));
    let innovations = lidar_innovations(&data, &fit.params, &fit.smoother, opts);
    checks.extend(checks::lidar_innovations(&innovations));
    let calibration = Calibration {
        method: Method::Em,
        sensors,
        iterations: fit.iterations,
        converged: fit.converged,
        metrics,
        order: None,
        odometry: None,
        landmarks: None,
        checks,
        notes,
    };
    Ok(EmOutcome {
        calibration,
        samples,
        estimates,
        log_likelihoods: fit.log_likelihoods,
        process_noise_rel: fit.params.q_rel,
    })
}

/// The lidar's standardised innovations `ν_k / √S_k` at the fitted parameters, in time order:
/// the lidar is the first observation of each step, so the prediction `x_{k|k−1}` is its prior.
/// The noise is linearised at the smoothed state (as the next E-step would).
pub(crate) fn lidar_innovations(
    data: &Data,
    params: &Params,
    smoother: &RtsSmoother<2>,
    opts: &EmOptions,
) -> Vec<f64> {
    let lidar = &params.sensors[LIDAR];
    let h = Vector2::new(lidar.alpha[1], lidar.alpha[2]);
    let moments = smoother
        .predicted_means()
        .iter()
        .zip(smoother.predicted_covs())
        .zip(
            smoother
                .smoothed_means()
                .iter()
                .zip(smoother.smoothed_covs()),
        );
    data.steps
        .iter()
        .zip(moments)
        .filter(|(step, _)| step.has[LIDAR])
        .filter_map(|(step, ((m, p), (sm, sp)))| {
            let r = super::model::noise_variance(
                &lidar.beta,
                &Lin::from_smoothed(sm, sp),
                opts.e_step.second_order(),
            );
            let s = h.dot(&(p * h)) + r;
            let nu = step.y[LIDAR] - lidar.alpha[0] - h.dot(m);
            (s > 0.0 && s.is_finite()).then(|| nu / s.sqrt())
        })
        .collect()
}

/// Checks the samples can anchor and identify the model: a start distance, enough lidar
/// readings, enough motion. Returns the start distance and the valid lidar readings' count.
fn check_samples(samples: &TargetSamples) -> Result<(f64, usize), CalibrationError> {
    let Some(start) = samples.start_distance_m else {
        return Err(CalibrationError::Missing(
            "no start distance: none was given (--start-distance), and meta.toml's [world] \
             target_start_distance_m, when present, is the frontal target's (beam 0°) only; \
             EM needs it to anchor the distance"
                .into(),
        ));
    };
    let valid = samples.lidar_count();
    if valid < MIN_LIDAR_READINGS {
        return Err(CalibrationError::TooFewSamples(format!(
            "{valid} valid lidar readings of the target in {} revolutions; EM needs at least \
             {MIN_LIDAR_READINGS}",
            samples.len()
        )));
    }
    let span = samples
        .commanded_m
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &c| {
            (lo.min(c), hi.max(c))
        });
    let spanned = span.1 - span.0;
    if spanned.is_nan() || spanned < MIN_SPAN_M {
        return Err(CalibrationError::Unidentifiable(format!(
            "the commanded motion changes the distance by only {:.3} m (at least {MIN_SPAN_M} m \
             needed): with no motion the bias cannot be told from the distance",
            (span.1 - span.0).max(0.0)
        )));
    }
    Ok((start, valid))
}

/// The smoother's data set (activating the sensors it can use, noting any dropped) and θ^(0):
/// each sensor regressed on the dead-reckoned distance (the commands taken as truth; the paper
/// leaves θ^(0) open). Returns the data, θ^(0) and the dead-reckoned linearisation.
fn initial_params(
    samples: &TargetSamples,
    start: f64,
    opts: &EmOptions,
    notes: &mut Vec<String>,
) -> Result<(Data, Params, Vec<Lin>), CalibrationError> {
    let mut params = Params {
        sensors: [
            SensorParams::paper(LIDAR),
            SensorParams::paper(ODOMETER),
            SensorParams::paper(SONAR),
        ],
        q_rel: opts.process_noise_rel,
        speed_scale: 1.0,
    };
    params.sensors[LIDAR].active = true;
    let mut data = build_data(samples, start, &mut params, opts, notes);
    // The start distance is known exactly, as in the paper (Σ_d = 0).
    data.prior_var = 0.0;

    let lin: Vec<Lin> = (0..samples.len())
        .map(|k| Lin::exact(start + samples.commanded_m[k]))
        .collect();
    let dr_means: Vec<Vector2<f64>> = lin.iter().map(|l| Vector2::new(l.m, l.d2)).collect();
    let zeros = vec![nalgebra::Matrix2::zeros(); lin.len()];
    let dead_reckoning = mstep::Posterior {
        means: &dr_means,
        covs: &zeros,
        lag_one: &zeros,
    };
    // θ^(0): the speed scale stays 1 (the commands taken as truth).
    let free = Free::default();
    let params = mstep::m_step(
        &data,
        &params,
        &dead_reckoning,
        &lin,
        true,
        free,
        &opts.priors,
    )?;
    Ok((data, params, lin))
}

/// What the iteration ended with.
struct Fit {
    params: Params,
    converged: bool,
    iterations: usize,
    /// The log-likelihood of the last E-step, at the final parameters.
    ll: f64,
    /// The smoother after that E-step (the smoothed distances under the final parameters).
    smoother: RtsSmoother<2>,
    /// The linearisation of that E-step.
    lin: Vec<Lin>,
    log_likelihoods: Vec<f64>,
}

/// Iterates EM (plain or SQUAREM) from θ^(0) to convergence or the cap, then runs one more
/// E-step for the smoothed distances under the final parameters.
fn iterate(
    data: &Data,
    opts: &EmOptions,
    mut params: Params,
    lin: Vec<Lin>,
) -> Result<Fit, CalibrationError> {
    let mut engine = Engine {
        data,
        opts,
        smoother: RtsSmoother::new(),
        lin,
        log_likelihoods: Vec::new(),
        iterations: 0,
    };
    let converged = if opts.accelerate {
        engine.squarem(&mut params)?
    } else {
        engine.plain(&mut params)?
    };
    let iterations = engine.iterations;
    // The smoothed distances under the final parameters.
    let ll = e_step(
        &mut engine.smoother,
        data,
        &params,
        &mut engine.lin,
        opts.e_step,
    )?;
    engine.log_likelihoods.push(ll);
    let Engine {
        smoother,
        log_likelihoods,
        lin,
        ..
    } = engine;
    Ok(Fit {
        params,
        converged,
        iterations,
        ll,
        smoother,
        lin,
        log_likelihoods,
    })
}

/// The calibration's notes on the iteration, the process noise and the samples.
fn push_notes(
    notes: &mut Vec<String>,
    samples: &TargetSamples,
    opts: &EmOptions,
    fit: &Fit,
    valid: usize,
    start: f64,
) {
    let (ll, iterations, converged, params) = (fit.ll, fit.iterations, fit.converged, &fit.params);
    notes.push(format!(
        "E-step: {}; log-likelihood {ll:.3} after {iterations} iterations ({})",
        opts.e_step.name(),
        if converged {
            "converged"
        } else {
            "iteration cap reached"
        }
    ));
    notes.push(format!(
        "process noise: {:.4} m per metre commanded ({})",
        params.q_rel,
        if opts.estimate_process_noise {
            "estimated"
        } else {
            "fixed"
        }
    ));
    notes.push(format!(
        "samples: {} revolutions, {valid} valid lidar readings at beam {}°, start distance {start} m",
        samples.len(),
        opts.beam_deg.rem_euclid(360.0)
    ));
    if !opts.priors.is_empty() {
        let list: Vec<String> = opts.priors.list().iter().map(ToString::to_string).collect();
        notes.push(format!("priors (MAP-EM): {}", list.join(", ")));
    }
    if opts.estimates_speed_scale() {
        notes.push(format!(
            "the commands' speed scale: {:.4} (estimated: a prior pins a sensor's scale, so a \
             speed error of the drive is told from the sensors' scales)",
            params.speed_scale
        ));
    }
    if samples.turns {
        notes.push(
            "warning: the commands turn the robot; EM assumes motion along a line".to_string(),
        );
    }
}

/// The active sensors' models in the interface's form, with their standard errors (`sds`, in
/// the order of [`Params::flat`]) when known.
fn sensor_models(params: &Params, sds: Option<&[f64]>) -> BTreeMap<Sensor, SensorModel> {
    let mut out = BTreeMap::new();
    let mut next = sds.map(|s| s.iter().copied());
    for (slot, sensor) in [Sensor::Lidar, Sensor::Odometer, Sensor::Sonar]
        .into_iter()
        .enumerate()
    {
        let p = &params.sensors[slot];
        if !p.active {
            continue;
        }
        let mut model =
            SensorModel::without_sd(p.alpha[..p.n_alpha].to_vec(), p.beta[..=p.power].to_vec());
        if let Some(it) = next.as_mut() {
            model.alpha_sd = it.by_ref().take(p.n_alpha).collect();
            // Only beta[power] is fitted; the lower coefficients are held at 0.
            model.beta_sd = vec![0.0; p.power + 1];
            model.beta_sd[p.power] = it.next().unwrap_or(f64::NAN);
        }
        out.insert(sensor, model);
    }
    out
}
