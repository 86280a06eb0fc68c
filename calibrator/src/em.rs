//! Ground-truth-less calibration of a lidar (and optionally an odometer and a sonar) by
//! approximate Expectation–Maximisation over a Kalman/RTS smoother.
//!
//! The robot drives along a line towards or away from a fixed target; the commands it issued
//! are known, its actual speed is not. Each sensor follows the paper's eq. (2),
//! `y = Σ α_i d^i + (Σ β_i d^i) e`; the distance follows `d_{k+1} = d_k + u_k + ν_k` (eq. 3)
//! from a known start. EM alternates a smoother over the redundant state `[1, d, d²]` (E-step)
//! with closed-form per-sensor fits (M-step) until the parameters and the log-likelihood
//! settle.
//!
//! # Requirements
//! - a lidar table whose beam at [`EmOptions::beam_deg`] sees the target in at least
//!   [`MIN_LIDAR_READINGS`] revolutions;
//! - the commands, and the start distance (`meta.world.target_start_distance_m` or
//!   [`EmOptions::start_distance_m`]);
//! - motion: the commanded distance must span at least [`MIN_SPAN_M`].
//!
//! # Reference
//! A. Alhashimi, D. Varagnolo, T. Gustafsson, "Calibrating distance sensors for terrestrial
//! applications without groundtruth information", IEEE Sensors J. 17(12), 2017: model eqs.
//! (2)–(5), E-step Algorithm 1, M-step Sec. IV-C. The filter, smoother and M-step are derived
//! anew from Shumway & Stoffer (1982); where this implementation departs from the paper (and
//! why) is in `docs/em-calibration.md`.
//!
//! ```no_run
//! use hilsim_calibrator::em::{self, EmOptions};
//! use hilsim_recording::Recording;
//! let rec = Recording::read_dir("run".as_ref())?;
//! let calibration = em::calibrate(&rec, &EmOptions::default())?;
//! println!("{}", calibration.to_json());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod model;
mod mstep;

use std::collections::BTreeMap;

use nalgebra::Vector2;

use crate::kalman_smoother::{RtsSmoother, SmootherError};
use crate::smoothing::Estimate;
use crate::target_samples::{self, SampleOptions, TargetSamples};
use crate::{Calibration, CalibrationError, Method, Sensor, SensorModel};

pub(crate) use model::{Data, EmModel, Lin, Params, SensorParams, StepData};
pub(crate) use model::{LIDAR, ODOMETER, SENSORS, SONAR};

/// Fewest valid lidar readings EM accepts: the lidar alone has four parameters (α0..α2, β2);
/// ten readings leave six degrees of freedom for the noise level, the least for which its
/// estimate's relative sd, `1/√(2·6) ≈ 0.29`, is below a third.
pub const MIN_LIDAR_READINGS: usize = 10;

/// Fewest readings for the odometer or sonar to take part (same reasoning, three parameters).
pub const MIN_AUX_READINGS: usize = 10;

/// Least span of commanded distance EM accepts, metres: below it the robot has not really
/// moved (5 cm is 2.5 revolutions at the paper's slowest 0.1 m/s). Separating α1 from α2 needs
/// the bias's curvature to show: over a span Δ the quadratic term departs from a straight line
/// by `α2 Δ²/4`, 0.04 mm here for the paper's α2 ≈ 0.06 /m, far below the XV-11's 1 mm
/// resolution, and the normal equations are numerically singular.
pub const MIN_SPAN_M: f64 = 0.05;

/// How the E-step treats the state-dependent (heteroscedastic) noise.
///
/// The refinements beyond the paper do not lower the error in the paper's setting (measured in
/// `docs/reproduce-em.md`: the paper's variant is as good or marginally better, and cheapest),
/// because the smoothed sd of `d` (millimetres) is tiny against `d` (≥ 0.5 m): `E[d⁴]` differs
/// from `d̂⁴` by `6 Var(d)/d̂² ≈ 1e-5` relative. So the paper's is the default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EStep {
    /// As the paper (Sec. IV-B/C): `R_k = (β · x̂_k^(t−1))²` at the previous iteration's
    /// smoothed redundant state, the same frozen weights in the M-step, and the M-step's
    /// `E[x xᵀ] = x̂ x̂ᵀ + P` from the redundant state (whose `d²` entry is its own variable).
    /// The default.
    #[default]
    Paper,
    /// Second-order moments: `R_k = E[(β·[1, d, d²])²]` (bringing in `E[d⁴]`) under the
    /// smoothed Gaussian of `d`, and the M-step's expectations `E[d^(−2p) φ φᵀ]` taken under
    /// that Gaussian too (weights included), instead of the redundant state's `d²` entry.
    SecondOrder,
    /// [`EStep::SecondOrder`], and the E-step re-evaluates `R_k` and `Q_k` at the *current*
    /// parameters' smoothed state (a second smoother pass) before the M-step, instead of
    /// keeping the previous iteration's.
    Relinearized,
}

impl EStep {
    /// A short name for notes and tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            EStep::Paper => "paper",
            EStep::SecondOrder => "second-order",
            EStep::Relinearized => "relinearized",
        }
    }

    fn second_order(self) -> bool {
        self != EStep::Paper
    }
}

/// What EM does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmOptions {
    /// Beam angle in the lidar's frame, degrees (0: the lidar's forward axis).
    pub beam_deg: f64,
    /// Lidar-to-target distance at t = 0, metres; overrides `meta.world.target_start_distance_m`.
    pub start_distance_m: Option<f64>,
    /// Use the odometer when the recording has one.
    pub use_odometer: bool,
    /// Use the sonar when the recording has one.
    pub use_sonar: bool,
    /// Iteration cap, in E-steps (default 5000: plain EM with all three sensors needs up to
    /// ~3,400 to reach the default tolerance; SQUAREM a few hundred at most).
    pub max_iterations: usize,
    /// Convergence: every parameter's relative change (scale floor 1e-4) and the
    /// log-likelihood's relative change below this.
    pub tolerance: f64,
    /// The E-step variant.
    pub e_step: EStep,
    /// The paper's `σ_d` (eq. 3), assumed known, expressed per metre commanded: the sd of the
    /// distance's deviation from the commanded motion over one step is `q |u_k|`. It models a
    /// speed-scale actuation error; the paper gives no value, so the default 0.02 is the
    /// reproduction's simulated drive error (`scale_sd = 0.02`); with such an error the result
    /// hardly depends on it from 0.005 to 0.05 (`docs/reproduce-em.md`, "Process-noise scale").
    pub process_noise_rel: f64,
    /// Estimate `q` in the M-step (Shumway–Stoffer, with the lag-one covariances) instead of
    /// keeping it fixed, as the paper does.
    pub estimate_process_noise: bool,
    /// Accelerate EM with SQUAREM extrapolation (beyond the paper); the fixed point is the
    /// same, reached in fewer iterations. Plain EM when false.
    pub accelerate: bool,
}

impl Default for EmOptions {
    fn default() -> Self {
        Self {
            beam_deg: 0.0,
            start_distance_m: None,
            use_odometer: true,
            use_sonar: true,
            max_iterations: 5000,
            tolerance: 1e-6,
            e_step: EStep::default(),
            process_noise_rel: 0.02,
            estimate_process_noise: false,
            accelerate: true,
        }
    }
}

impl EmOptions {
    fn validate(&self) -> Result<(), CalibrationError> {
        if self.max_iterations == 0 {
            return Err(CalibrationError::Invalid(
                "max_iterations must be at least 1".into(),
            ));
        }
        if !(self.tolerance > 0.0 && self.tolerance.is_finite()) {
            return Err(CalibrationError::Invalid(format!(
                "tolerance must be positive, got {}",
                self.tolerance
            )));
        }
        if !(self.process_noise_rel >= 0.0 && self.process_noise_rel.is_finite()) {
            return Err(CalibrationError::Invalid(format!(
                "process_noise_rel must be non-negative, got {}",
                self.process_noise_rel
            )));
        }
        Ok(())
    }

    fn sample_options(&self) -> SampleOptions {
        SampleOptions {
            beam_deg: self.beam_deg,
            start_distance_m: self.start_distance_m,
        }
    }
}

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
    run_samples(samples, opts)
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

    let mut notes = Vec::new();
    let mut params = Params {
        sensors: [
            SensorParams::paper(LIDAR),
            SensorParams::paper(ODOMETER),
            SensorParams::paper(SONAR),
        ],
        q_rel: opts.process_noise_rel,
    };
    params.sensors[LIDAR].active = true;
    let mut data = build_data(&samples, start, &mut params, opts, &mut notes);
    // The start distance is known exactly, as in the paper (Σ_d = 0).
    data.prior_var = 0.0;

    // θ^(0): each sensor regressed on the dead-reckoned distance (the commands taken as truth);
    // the paper leaves θ^(0) open.
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
    params = mstep::m_step(&data, &params, &dead_reckoning, &lin, true, false)?;

    let mut engine = Engine {
        data: &data,
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
        &data,
        &params,
        &mut engine.lin,
        opts.e_step,
    )?;
    engine.log_likelihoods.push(ll);
    let Engine {
        smoother,
        log_likelihoods,
        ..
    } = engine;
    let estimates = estimates(&samples, &smoother);

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
        opts.beam_deg.round().rem_euclid(360.0)
    ));
    if samples.turns {
        notes.push(
            "warning: the commands turn the robot; EM assumes motion along a line".to_string(),
        );
    }
    let metrics = samples.truth_m.as_ref().and_then(|truth| {
        let calibrated: Vec<Option<f64>> = estimates.iter().map(|e| Some(e.distance_m)).collect();
        target_samples::distance_metrics(truth, &samples.lidar_m, &calibrated)
    });
    let calibration = Calibration {
        method: Method::Em,
        sensors: sensor_models(&params),
        iterations,
        converged,
        metrics,
        order: None,
        landmarks: None,
        notes,
    };
    Ok(EmOutcome {
        calibration,
        samples,
        estimates,
        log_likelihoods,
        process_noise_rel: params.q_rel,
    })
}

/// The EM iteration: the map θ ↦ M(E(θ)) with its workspace and trace.
struct Engine<'a> {
    data: &'a Data,
    opts: &'a EmOptions,
    smoother: RtsSmoother<2>,
    /// The linearisation point of the next E-step (the last smoothed state).
    lin: Vec<Lin>,
    /// `log p(y; θ)` of every E-step.
    log_likelihoods: Vec<f64>,
    /// E-steps (EM map evaluations) so far.
    iterations: usize,
}

impl Engine<'_> {
    /// One EM map evaluation: E-step at `params` (returning its log-likelihood) and M-step.
    fn step(&mut self, params: &Params) -> Result<(Params, f64), CalibrationError> {
        let ll = e_step(
            &mut self.smoother,
            self.data,
            params,
            &mut self.lin,
            self.opts.e_step,
        )?;
        self.log_likelihoods.push(ll);
        self.iterations += 1;
        let post = mstep::Posterior {
            means: self.smoother.smoothed_means(),
            covs: self.smoother.smoothed_covs(),
            lag_one: self.smoother.lag_one_covs(),
        };
        let next = mstep::m_step(
            self.data,
            params,
            &post,
            &self.lin,
            self.opts.e_step.second_order(),
            self.opts.estimate_process_noise,
        )?;
        update_lin(&mut self.lin, &self.smoother);
        Ok((next, ll))
    }

    fn flat(&self, p: &Params) -> Vec<f64> {
        let mut v = Vec::new();
        p.flat(self.opts.estimate_process_noise, &mut v);
        v
    }

    /// The convergence test between consecutive iterates and log-likelihoods.
    fn settled(&self, old: &Params, new: &Params, ll_old: f64, ll_new: f64) -> bool {
        let tol = self.opts.tolerance;
        relative_change(&self.flat(old), &self.flat(new)) < tol
            && (ll_new - ll_old).abs() <= tol * ll_new.abs().max(1.0)
    }

    /// Plain EM; returns whether it converged.
    fn plain(&mut self, params: &mut Params) -> Result<bool, CalibrationError> {
        let mut ll_old = f64::NAN;
        while self.iterations < self.opts.max_iterations {
            let (next, ll) = self.step(params)?;
            let done = self.settled(params, &next, ll_old, ll);
            *params = next;
            ll_old = ll;
            if done {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// EM accelerated by SQUAREM (Varadhan & Roland, Scand. J. Statist. 2008, scheme S3): two
    /// EM steps θ0 → θ1 → θ2 give `r = θ1 − θ0`, `v = θ2 − 2θ1 + θ0`; the extrapolation
    /// `θ' = θ0 − 2a r + a² v` with `a = −‖r‖/‖v‖` (never shorter than plain EM, `a ≤ −1`) is
    /// stabilised by one more EM step and kept only if its log-likelihood is no lower than
    /// θ0's; otherwise θ2 (plain EM) is kept. Convergence is tested on the plain steps. The
    /// step length is not bounded: bounding it (as the authors' R package can) tripled the
    /// iterations here.
    fn squarem(&mut self, params: &mut Params) -> Result<bool, CalibrationError> {
        let with_q = self.opts.estimate_process_noise;
        while self.iterations + 2 <= self.opts.max_iterations {
            let theta0 = *params;
            let (theta1, ll0) = self.step(&theta0)?;
            let (theta2, ll1) = self.step(&theta1)?;
            if self.settled(&theta1, &theta2, ll0, ll1) {
                *params = theta2;
                return Ok(true);
            }
            *params = theta2;
            if self.iterations + 1 > self.opts.max_iterations {
                break;
            }
            let (f0, f1, f2) = (self.flat(&theta0), self.flat(&theta1), self.flat(&theta2));
            let r: Vec<f64> = f1.iter().zip(&f0).map(|(a, b)| a - b).collect();
            let v: Vec<f64> = f2
                .iter()
                .zip(&f1)
                .zip(&r)
                .map(|((a, b), r)| a - b - r)
                .collect();
            let (nr, nv) = (norm(&r), norm(&v));
            if !(nv > 0.0 && nr.is_finite() && nv.is_finite()) {
                continue;
            }
            let a = -(nr / nv).max(1.0);
            if a == -1.0 {
                continue;
            }
            let extrapolated: Vec<f64> = f0
                .iter()
                .zip(&r)
                .zip(&v)
                .map(|((t, r), v)| t - 2.0 * a * r + a * a * v)
                .collect();
            let Some(theta_x) = theta0.with_flat(with_q, &extrapolated) else {
                continue;
            };
            let saved_lin = self.lin.clone();
            // An extrapolation may leave the region where the smoother and M-step are
            // defined; that only means it is rejected.
            // The log-likelihood is compared with a slack of the convergence tolerance: the
            // linearisation moves between E-steps, so at that level it is not a function of θ
            // alone, and a strict test rejects every extrapolation near the fixed point.
            let slack = self.opts.tolerance * ll0.abs().max(1.0);
            match self.step(&theta_x) {
                Ok((theta3, ll_x)) if ll_x >= ll0 - slack => *params = theta3,
                _ => self.lin = saved_lin,
            }
        }
        Ok(false)
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The data set of the smoother; activates the odometer and sonar slots the options and the
/// recording allow (with enough readings), noting any dropped.
pub(crate) fn build_data(
    samples: &TargetSamples,
    start: f64,
    params: &mut Params,
    opts: &EmOptions,
    notes: &mut Vec<String>,
) -> Data {
    let n = samples.len();
    let odometer: Vec<Option<f64>> = (0..n).map(|k| samples.odometer_distance(k)).collect();
    let sonar: Vec<Option<f64>> = samples.sonar_m.clone().unwrap_or_else(|| vec![None; n]);
    let mut use_slot = |slot: usize, wanted: bool, present: bool, readings: &[Option<f64>]| {
        let count = readings.iter().filter(|y| y.is_some()).count();
        if wanted && present {
            if count >= MIN_AUX_READINGS {
                params.sensors[slot].active = true;
            } else {
                notes.push(format!(
                    "{} not used: {count} readings at the sample instants (at least \
                     {MIN_AUX_READINGS} needed)",
                    mstep::NAMES[slot]
                ));
            }
        }
    };
    use_slot(
        ODOMETER,
        opts.use_odometer,
        samples.odometer_travel_m.is_some(),
        &odometer,
    );
    use_slot(SONAR, opts.use_sonar, samples.sonar_m.is_some(), &sonar);
    let steps = (0..n)
        .map(|k| {
            let readings = [samples.lidar_m[k], odometer[k], sonar[k]];
            let mut y = [0.0; SENSORS];
            let mut has = [false; SENSORS];
            for slot in 0..SENSORS {
                if let (true, Some(v)) = (params.sensors[slot].active, readings[slot]) {
                    y[slot] = v;
                    has[slot] = true;
                }
            }
            StepData {
                y,
                has,
                u: samples.u(k),
            }
        })
        .collect();
    Data {
        steps,
        prior_mean: start + samples.commanded_m[0],
        prior_u: samples.commanded_m[0],
        prior_var: 0.0,
    }
}

/// One E-step: a smoother pass at the linearisation `lin` (and for [`EStep::Relinearized`] a
/// second at the first pass's smoothed state, which then becomes `lin`). Returns the
/// log-likelihood of the last pass.
pub(crate) fn e_step(
    smoother: &mut RtsSmoother<2>,
    data: &Data,
    params: &Params,
    lin: &mut [Lin],
    variant: EStep,
) -> Result<f64, CalibrationError> {
    let pass = |smoother: &mut RtsSmoother<2>, lin: &[Lin]| {
        smoother
            .run(&EmModel {
                data,
                params,
                lin,
                second_order: variant.second_order(),
            })
            .map_err(diverged)
    };
    let mut ll = pass(smoother, lin)?;
    if variant == EStep::Relinearized {
        update_lin(lin, smoother);
        ll = pass(smoother, lin)?;
    }
    Ok(ll)
}

fn update_lin(lin: &mut [Lin], smoother: &RtsSmoother<2>) {
    for ((l, m), p) in lin
        .iter_mut()
        .zip(smoother.smoothed_means())
        .zip(smoother.smoothed_covs())
    {
        *l = Lin::from_smoothed(m, p);
    }
}

pub(crate) fn diverged(err: SmootherError) -> CalibrationError {
    CalibrationError::Diverged(format!("the Kalman smoother failed: {err}"))
}

/// The smoothed distance of each sample.
pub(crate) fn estimates(samples: &TargetSamples, smoother: &RtsSmoother<2>) -> Vec<Estimate> {
    samples
        .t_s
        .iter()
        .zip(smoother.smoothed_means())
        .zip(smoother.smoothed_covs())
        .map(|((&t_s, m), p)| Estimate {
            t_s,
            distance_m: m[0],
            variance_m2: p[(0, 0)].max(0.0),
        })
        .collect()
}

/// Largest relative change of any parameter, each against its own size with a floor of 1e-4
/// (a tenth of a millimetre, or 1e-4 of a unit gain: below what any of these sensors resolves).
fn relative_change(old: &[f64], new: &[f64]) -> f64 {
    old.iter()
        .zip(new)
        .map(|(a, b)| (a - b).abs() / a.abs().max(1e-4))
        .fold(0.0, f64::max)
}

/// The active sensors' models in the interface's form.
pub(crate) fn sensor_models(params: &Params) -> BTreeMap<Sensor, SensorModel> {
    let mut out = BTreeMap::new();
    for (slot, sensor) in [Sensor::Lidar, Sensor::Odometer, Sensor::Sonar]
        .into_iter()
        .enumerate()
    {
        let p = &params.sensors[slot];
        if p.active {
            out.insert(
                sensor,
                SensorModel {
                    alpha: p.alpha[..p.n_alpha].to_vec(),
                    beta: p.beta[..=p.power].to_vec(),
                },
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic standard normal sequence (Box–Muller on a 64-bit LCG), so that the
    /// unit tests need no random-number crate features.
    fn normals(n: usize) -> Vec<f64> {
        let mut state: u64 = 0x853c_49e6_748f_ea9b;
        let mut uniform = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| {
                let (u1, u2) = (uniform(), uniform());
                (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
            })
            .collect()
    }

    /// The paper's model with every noise variance frozen at a linearisation point is linear
    /// and Gaussian, and EM on it must never lower its likelihood: this checks the M-step's
    /// closed forms (with the paper's weights) against the E-step's likelihood to rounding.
    #[test]
    fn the_paper_m_step_is_exact_em_for_the_frozen_model() {
        let n = 150;
        let e = normals(3 * n);
        let u = 0.02;
        let mut params = Params {
            sensors: [
                SensorParams::paper(LIDAR),
                SensorParams::paper(ODOMETER),
                SensorParams::paper(SONAR),
            ],
            q_rel: 0.01,
        };
        params.sensors[LIDAR].active = true;
        params.sensors[ODOMETER].active = true;
        let steps = (0..n)
            .map(|k| {
                // The true distance wanders off the commanded one by ~1 cm.
                let d = 0.5 + u * k as f64 + 0.01 * (k as f64 / 20.0).sin();
                let lidar = 0.05 + 0.88 * d + 0.06 * d * d + 0.004 * d * d * e[k];
                let odometer = -0.01 + 1.02 * d + 0.003 * e[n + k];
                StepData {
                    y: [lidar, odometer, 0.0],
                    // Every fifth lidar reading missing.
                    has: [k % 5 != 3, true, false],
                    u,
                }
            })
            .collect();
        let data = Data {
            steps,
            prior_mean: 0.5,
            prior_u: 0.0,
            prior_var: 0.0,
        };
        let lin: Vec<Lin> = (0..n).map(|k| Lin::exact(0.5 + u * k as f64)).collect();
        let dr: Vec<Vector2<f64>> = lin.iter().map(|l| Vector2::new(l.m, l.d2)).collect();
        let zeros = vec![nalgebra::Matrix2::zeros(); n];
        let init = mstep::Posterior {
            means: &dr,
            covs: &zeros,
            lag_one: &zeros,
        };
        params = mstep::m_step(&data, &params, &init, &lin, false, false).unwrap();
        let mut smoother = RtsSmoother::<2>::new();
        fn model<'a>(data: &'a Data, params: &'a Params, lin: &'a [Lin]) -> EmModel<'a> {
            EmModel {
                data,
                params,
                lin,
                second_order: false,
            }
        }
        let mut ll = smoother.run(&model(&data, &params, &lin)).unwrap();
        let first = ll;
        for iteration in 0..30 {
            let post = mstep::Posterior {
                means: smoother.smoothed_means(),
                covs: smoother.smoothed_covs(),
                lag_one: smoother.lag_one_covs(),
            };
            let next = mstep::m_step(&data, &params, &post, &lin, false, false).unwrap();
            let ll_next = smoother.run(&model(&data, &next, &lin)).unwrap();
            // Rounding: ~1e-13 relative per operation over a few thousand.
            assert!(
                ll_next >= ll - 1e-10 * ll.abs(),
                "iteration {iteration}: {ll} -> {ll_next}"
            );
            params = next;
            ll = ll_next;
        }
        assert!(ll > first);
        // Run to the fixed point (q = 0.01 keeps EM's rate low enough for 400 iterations to
        // reach it); there the likelihood must be at a maximum: moving any parameter by 1e-3
        // of its size (or 1e-6) either way must not raise it beyond rounding. Wrong M-step
        // weights leave the fixed point off the maximum (checked: weights 1/d² instead of
        // 1/d⁴ fail here).
        for _ in 0..400 {
            let post = mstep::Posterior {
                means: smoother.smoothed_means(),
                covs: smoother.smoothed_covs(),
                lag_one: smoother.lag_one_covs(),
            };
            params = mstep::m_step(&data, &params, &post, &lin, false, false).unwrap();
            ll = smoother.run(&model(&data, &params, &lin)).unwrap();
        }
        let mut flat = Vec::new();
        params.flat(false, &mut flat);
        for i in 0..flat.len() {
            for sign in [-1.0, 1.0] {
                let mut moved = flat.clone();
                moved[i] += sign * (1e-3 * flat[i].abs()).max(1e-6);
                let p = params.with_flat(false, &moved).unwrap();
                let ll_moved = smoother.run(&model(&data, &p, &lin)).unwrap();
                assert!(
                    ll_moved <= ll + 1e-9 * ll.abs(),
                    "parameter {i} moved {sign}: {ll} -> {ll_moved}"
                );
            }
        }
    }

    #[test]
    fn parameters_round_trip_through_their_flat_form() {
        let mut p = Params {
            sensors: [
                SensorParams::paper(LIDAR),
                SensorParams::paper(ODOMETER),
                SensorParams::paper(SONAR),
            ],
            q_rel: 0.02,
        };
        p.sensors[LIDAR].active = true;
        p.sensors[LIDAR].beta[2] = 0.004;
        p.sensors[SONAR].active = true;
        p.sensors[SONAR].beta[0] = 0.008;
        let mut flat = Vec::new();
        p.flat(true, &mut flat);
        assert_eq!(flat.len(), 3 + 1 + 2 + 1 + 1);
        assert_eq!(p.with_flat(true, &flat), Some(p));
        flat[3] = -1.0;
        assert_eq!(
            p.with_flat(true, &flat),
            None,
            "a negative noise level is outside"
        );
    }
}
