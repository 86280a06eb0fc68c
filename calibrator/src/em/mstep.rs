//! The M-step: closed forms per sensor (the paper's Sec. IV-C and Appendix, derived again from
//! the expected complete-data log-likelihood; see `docs/em-calibration.md`).
//!
//! For a sensor `y_k = α · φ(d_k) + β d_k^p e_k` (φ = `[1, d, d²]` or `[1, d]`), the terms of
//! the expected log-likelihood that depend on `(α, β)` are
//!
//! ```text
//! Σ_k  −log β − E[ w(d_k) (y_k − α · φ(d_k))² ] / (2β²),     w(d) = d^(−2p)
//! ```
//!
//! so `α = S_yφ S_φφ⁻¹` with `S_φφ = Σ E[w φ φᵀ]`, `S_yφ = Σ y E[w φ]`, and
//! `β² = (Σ y² E[w] − α · S_yφ) / N`, sums over the steps where the sensor observed.
//! The expectations are taken
//! - as the paper does: `w` frozen at the previous smoothed state (`x̂^(t−1)[3]⁻²` for the
//!   lidar), `E[φ φᵀ] = x̂ x̂ᵀ + P` from the redundant state's smoothed moments;
//! - or (second-order variants) under the smoothed Gaussian of `d` itself, `w` included.

use nalgebra::{Cholesky, Matrix2, Matrix3, Vector2, Vector3};

use super::model::{moment, Data, Free, Lin, Params, SensorParams, StepData, FLOOR_D_M, SENSORS};
use super::prior::Priors;
use crate::CalibrationError;

/// Conditional maximisations of (α, β) per M-step under a prior (they converge in two or three).
const PRIOR_CYCLES: usize = 8;

/// Sensor names for messages, by slot.
pub(crate) const NAMES: [&str; SENSORS] = ["lidar", "odometer", "sonar"];

/// The smoothed moments the M-step reads.
pub(crate) struct Posterior<'a> {
    /// Smoothed means of `[d, d²]`.
    pub means: &'a [Vector2<f64>],
    /// Smoothed covariances.
    pub covs: &'a [Matrix2<f64>],
    /// Lag-one covariances `Cov(z_{k+1}, z_k | Y)` (needed only to estimate q).
    pub lag_one: &'a [Matrix2<f64>],
}

/// One M-step. `lin` is the linearisation point the E-step used (the paper's weights);
/// `second_order` selects the expectation under the Gaussian of `d`.
pub(crate) fn m_step(
    data: &Data,
    params: &Params,
    post: &Posterior<'_>,
    lin: &[Lin],
    second_order: bool,
    free: Free,
    priors: &Priors,
) -> Result<Params, CalibrationError> {
    let mut next = *params;
    let sums = Sums::over(data, params, post, lin, second_order);
    for (slot, sensor) in next.sensors.iter_mut().enumerate() {
        if !sensor.active {
            continue;
        }
        fit_sensor(sensor, slot, &sums, priors)?;
    }
    if free.q {
        next.q_rel = q_step(data, post, params.q_rel, params.speed_scale)?;
    }
    if free.speed_scale {
        next.speed_scale = speed_scale_step(data, post, params)?;
    }
    Ok(next)
}

/// The commands' speed scale: the `s` that maximises the expected log-density of the
/// transitions, `Σ_k −E[(d_{k+1} − d_k − s u_k)²] / (2 σ_k²)`, i.e. the weighted regression of
/// the smoothed displacements on the commanded ones,
/// `s = Σ u_k (E[d_{k+1}] − E[d_k]) / σ_k²  /  Σ u_k² / σ_k²`, with `σ_k² = (q s u_k)² + Q_floor`
/// at the current `s` (an ECM step, Meng & Rubin 1993: it still never lowers the likelihood).
/// Only the `d` row of the transition is used; its `d²` row is the same motion squared.
fn speed_scale_step(
    data: &Data,
    post: &Posterior<'_>,
    params: &Params,
) -> Result<f64, CalibrationError> {
    let (mut num, mut den) = (0.0, 0.0);
    for (k, step) in data.steps.iter().enumerate().take(data.steps.len() - 1) {
        let u = step.u;
        if u == 0.0 {
            continue;
        }
        let sigma = params.q_rel * params.speed_scale * u;
        let w = 1.0 / (sigma * sigma + FLOOR_D_M * FLOOR_D_M);
        num += w * u * (post.means[k + 1][0] - post.means[k][0]);
        den += w * u * u;
    }
    let s = num / den;
    if !(s.is_finite() && s > 0.0) {
        return Err(CalibrationError::Diverged(format!(
            "the commands' speed scale came out {s:e}: the smoothed distance does not follow \
             the commanded motion"
        )));
    }
    Ok(s)
}

/// The sums of the closed forms, per sensor slot: S_φφ (full 3×3, of which each sensor uses its
/// n_alpha block), S_yφ, Σ w y², N.
struct Sums {
    sxx: [Matrix3<f64>; SENSORS],
    sxy: [Vector3<f64>; SENSORS],
    syy: [f64; SENSORS],
    count: [usize; SENSORS],
}

impl Sums {
    /// One pass over the steps for every sensor.
    fn over(
        data: &Data,
        params: &Params,
        post: &Posterior<'_>,
        lin: &[Lin],
        second_order: bool,
    ) -> Self {
        let mut sums = Self {
            sxx: [Matrix3::<f64>::zeros(); SENSORS],
            sxy: [Vector3::<f64>::zeros(); SENSORS],
            syy: [0.0; SENSORS],
            count: [0usize; SENSORS],
        };
        let active = params.sensors.map(|s| s.active);
        let power = params.sensors.map(|s| s.power as i32);
        for (k, step) in data.steps.iter().enumerate() {
            let (m, cov) = (post.means[k], post.covs[k]);
            if second_order {
                sums.add_second_order(step, m, cov, active, power);
            } else {
                sums.add_paper(step, m, cov, &lin[k], active, power);
            }
        }
        sums
    }

    /// A step's terms with the expectations under the smoothed Gaussian of `d`, `w` included.
    fn add_second_order(
        &mut self,
        step: &StepData,
        m: Vector2<f64>,
        cov: Matrix2<f64>,
        active: [bool; SENSORS],
        power: [i32; SENSORS],
    ) {
        // E[d^j] for j = −4..=4 (index j + 4) under the smoothed Gaussian of d.
        let v = cov[(0, 0)].max(0.0);
        let mut e = [0.0; 9];
        for (i, e) in e.iter_mut().enumerate() {
            *e = moment(m[0], v, i as i32 - 4);
        }
        for slot in 0..SENSORS {
            if !(active[slot] && step.has[slot]) {
                continue;
            }
            let y = step.y[slot];
            // E[w φ_i φ_j] = E[d^(i + j − 2p)].
            let base = (4 - 2 * power[slot]) as usize;
            for i in 0..3 {
                for j in 0..3 {
                    self.sxx[slot][(i, j)] += e[base + i + j];
                }
                self.sxy[slot][i] += y * e[base + i];
            }
            self.syy[slot] += y * y * e[base];
            self.count[slot] += 1;
        }
    }

    /// A step's terms as the paper takes them: `w` frozen at the linearisation point,
    /// `E[φ φᵀ] = x̂ x̂ᵀ + P`.
    fn add_paper(
        &mut self,
        step: &StepData,
        m: Vector2<f64>,
        cov: Matrix2<f64>,
        lin: &Lin,
        active: [bool; SENSORS],
        power: [i32; SENSORS],
    ) {
        let phi = Vector3::new(1.0, m[0], m[1]);
        let mut e = phi * phi.transpose();
        e[(1, 1)] += cov[(0, 0)];
        e[(1, 2)] += cov[(0, 1)];
        e[(2, 1)] += cov[(1, 0)];
        e[(2, 2)] += cov[(1, 1)];
        for slot in 0..SENSORS {
            if !(active[slot] && step.has[slot]) {
                continue;
            }
            let y = step.y[slot];
            // The paper's weight: the noise shape at the previous smoothed state.
            let shape = match power[slot] {
                0 => 1.0,
                1 => lin.m * lin.m,
                _ => lin.d2 * lin.d2,
            };
            let w = 1.0 / shape;
            self.sxx[slot] += w * e;
            self.sxy[slot] += (w * y) * phi;
            self.syy[slot] += w * y * y;
            self.count[slot] += 1;
        }
    }
}

/// One sensor's α and β from the sums: `α = S_yφ S_φφ⁻¹` (an affine sensor's d² coefficient
/// pinned to 0), `β² = (Σ y² E[w] − α · S_yφ) / N`.
///
/// With priors `alpha_i ~ N(μ_i, s_i²)` on some coefficients (MAP-EM) the M-step maximises the
/// expected log-likelihood plus the log prior. For a fixed β that is the ridge-like system
/// `(S_φφ + β² Λ) α = S_yφ + β² Λ μ`, Λ = diag(1/s_i²) on the coefficients with a prior; for a
/// fixed α, `β² = (Σ w y² − 2 α·S_yφ + αᵀ S_φφ α) / N` (equal to the unpenalised form when
/// there is no prior). The two are alternated from the current β to a fixed point (a few
/// conditional maximisations: ECM, Meng & Rubin 1993).
fn fit_sensor(
    sensor: &mut SensorParams,
    slot: usize,
    sums: &Sums,
    priors: &Priors,
) -> Result<(), CalibrationError> {
    let (n_alpha, n, name) = (sensor.n_alpha, sums.count[slot], NAMES[slot]);
    if n <= n_alpha {
        return Err(CalibrationError::TooFewSamples(format!(
            "{n} {name} readings cannot fit {n_alpha} bias coefficients and a noise level"
        )));
    }
    let (mut a, mut b) = (sums.sxx[slot], sums.sxy[slot]);
    // An affine sensor: pin the unused d² coefficient to 0 with an identity row.
    for i in n_alpha..3 {
        for j in 0..3 {
            a[(i, j)] = 0.0;
            a[(j, i)] = 0.0;
        }
        a[(i, i)] = 1.0;
        b[i] = 0.0;
    }
    let singular = || {
        CalibrationError::Diverged(format!(
            "the {name} normal equations are singular (the distances do not vary enough to \
             separate the bias coefficients)"
        ))
    };
    let prior: Vec<(usize, f64, f64)> = (0..n_alpha)
        .filter_map(|i| priors.get(slot, i).map(|(mean, sd)| (i, mean, sd)))
        .collect();
    let residual_sq = |alpha: &Vector3<f64>| {
        (sums.syy[slot] - 2.0 * alpha.dot(&sums.sxy[slot]) + alpha.dot(&(sums.sxx[slot] * alpha)))
            / n as f64
    };
    let mut alpha = Cholesky::new(a).map(|c| c.solve(&b)).ok_or_else(singular)?;
    let mut beta2 = (sums.syy[slot] - alpha.dot(&b)) / n as f64;
    if !prior.is_empty() {
        // Start from the current β (θ^(t)); θ^(0)'s is 0, where the prior has no weight yet.
        let current = sensor.beta[sensor.power];
        let mut b2 = if current > 0.0 {
            current * current
        } else {
            beta2
        };
        for _ in 0..PRIOR_CYCLES {
            let (mut ap, mut bp) = (a, b);
            for &(i, mean, sd) in &prior {
                let weight = b2 / (sd * sd);
                ap[(i, i)] += weight;
                bp[i] += weight * mean;
            }
            // The data alone were solvable: a failure here is the priors' weight.
            let next = Cholesky::new(ap).map(|c| c.solve(&bp)).ok_or_else(|| {
                CalibrationError::Diverged(format!(
                    "the {name} normal equations with the priors are singular (a prior's sd \
                     is too small against the readings' noise)"
                ))
            })?;
            let next_b2 = residual_sq(&next);
            let done = (next - alpha).amax() < 1e-12 && (next_b2 - b2).abs() < 1e-15;
            alpha = next;
            b2 = next_b2;
            if done {
                break;
            }
        }
        beta2 = b2;
    }
    sensor.alpha = [alpha[0], alpha[1], alpha[2]];
    sensor.beta = [0.0; 3];
    sensor.beta[sensor.power] = beta2.sqrt();
    Ok(())
}

/// The M-step for `q` in `σ_k = q |u_k|` (Shumway–Stoffer's `Q` update, restricted to this
/// structure): `q² = mean over moving steps of (E[(d_{k+1} − d_k − u_k)²] − f²) / u_k²`, with
/// `u_k` the commanded motion at the speed scale (`s u_k`: the motion the model expects), where
/// the expectation needs the lag-one covariance:
/// `E[(Δ)²] = (m_{k+1} − m_k − u_k)² + P_{k+1} + P_k − 2 P_{k+1,k}`. The floor `f²` is
/// subtracted so that it is not counted twice; this is the exact M-step when every `|u_k|` is
/// equal (constant speed, the paper's runs) and a moment estimate otherwise.
fn q_step(
    data: &Data,
    post: &Posterior<'_>,
    previous: f64,
    speed_scale: f64,
) -> Result<f64, CalibrationError> {
    let f2 = FLOOR_D_M * FLOOR_D_M;
    let (mut sum, mut count) = (0.0, 0usize);
    for k in 0..data.steps.len().saturating_sub(1) {
        // The motion the model expects: the command at the speed scale.
        let u = speed_scale * data.steps[k].u;
        // Steps shorter than the floor carry no information about a speed-scale error.
        if u.abs() < 10.0 * FLOOR_D_M {
            continue;
        }
        let r = post.means[k + 1][0] - post.means[k][0] - u;
        let e =
            r * r + post.covs[k + 1][(0, 0)] + post.covs[k][(0, 0)] - 2.0 * post.lag_one[k][(0, 0)];
        sum += (e - f2) / (u * u);
        count += 1;
    }
    if count == 0 {
        return Ok(previous);
    }
    let q2 = sum / count as f64;
    if !q2.is_finite() {
        return Err(CalibrationError::Diverged(
            "the process-noise estimate is not finite".into(),
        ));
    }
    // Never exactly zero: a vanishing q would make the commands infallible, and EM could not
    // grow it back (a fixed point of the update).
    Ok(q2.max(1e-12).sqrt())
}
