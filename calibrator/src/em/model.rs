//! The EM paper's state-space model (eqs. 3–5) as the smoother sees it.
//!
//! The paper's redundant state is `x_k = [1, d_k, d_k²]` (`N_max = 3`: the lidar's bias is
//! quadratic). Its first entry is the constant 1, known exactly at every step (zero variance),
//! so the smoother carries only the stochastic part `z_k = [d_k, d_k²]`; the paper's
//! `A_k = [[1,0,0],[u,1,0],[u²,2u,1]]`, `B_k` and `C = [α0, α1, α2]` then read
//!
//! ```text
//! z_{k+1} = [[1, 0], [2u_k, 1]] z_k + [u_k, u_k² + σ_k²] + w_k
//! y^s_k   = α^s_0 + [α^s_1, α^s_2] z_k + v^s_k
//! ```
//!
//! which is the same model with the deterministic row and column of `x` factored out (its
//! covariance row and column are identically zero, which would make the paper's `P_{k+1|k}`
//! singular in the smoother gain `J_k`).
//!
//! Noise, evaluated at a *linearisation point* (the previous smoothed state, as the paper does):
//! - `v^s_k ~ N(0, R^s_k)` with the paper's `r^s(x) = (β^s · x)²`: at the redundant state's
//!   smoothed mean (`EStep::Paper`) or its expectation `E[(β^s · [1, d, d²])²]` under the
//!   smoothed Gaussian of `d` (the second-order variants, which bring in `E[d⁴]`);
//! - `w_k`: the covariance of `[ν, (d+u+ν)² − (d+u)²]` for `ν ~ N(0, σ_k²)` (eq. 3), with
//!   `σ_k = q |u_k|` (the actuation error scales with the commanded motion), linearised at
//!   `d = d̂_k`: `σ_k² [[1, 2a], [2a, 4a² + 2σ_k²]]`, `a = d̂_k + u_k`, plus the paper's small
//!   diagonal `Q` (`FLOOR_D_M`) that keeps `P_{k+1|k}` invertible and lets a robot that stands
//!   still drift by a fraction of a millimetre.

use nalgebra::{Matrix2, Vector2};

use crate::kalman_smoother::{Gaussian, Observation, Observations, StateSpaceModel, Transition};

/// Sensor slots: the lidar, the odometer, the sonar.
pub(crate) const LIDAR: usize = 0;
/// The odometer's slot.
pub(crate) const ODOMETER: usize = 1;
/// The sonar's slot.
pub(crate) const SONAR: usize = 2;
/// Number of sensor slots.
pub(crate) const SENSORS: usize = 3;

/// The paper's "diagonal Q with small entries" (Sec. III): 0.1 mm per step on `d`, the
/// resolution of the XV-11's millimetre ranges and of the Neato's millimetre wheel positions
/// divided by ten, so it never competes with a real motion error. On `d²` the same, scaled by
/// `2d` (the derivative of `d²`).
pub(crate) const FLOOR_D_M: f64 = 1e-4;

/// One sensor's model, eq. (2): bias `Σ alpha_i d^i`, noise sd `Σ beta_i d^i`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SensorParams {
    /// Whether the sensor takes part.
    pub active: bool,
    /// Bias coefficients, padded with zeros.
    pub alpha: [f64; 3],
    /// How many bias coefficients the sensor's order has (3: quadratic; 2: affine).
    pub n_alpha: usize,
    /// Noise sd coefficients, padded with zeros.
    pub beta: [f64; 3],
    /// The single noise power the M-step fits (`sd = beta[power] d^power`): 2 for the
    /// triangulation lidar, 0 for the odometer and sonar (Sec. II).
    pub power: usize,
}

impl SensorParams {
    /// The paper's sensor of this slot, inactive, with placeholder parameters.
    pub(crate) fn paper(slot: usize) -> Self {
        let (n_alpha, power) = if slot == LIDAR { (3, 2) } else { (2, 0) };
        Self {
            active: false,
            alpha: [0.0, 1.0, 0.0],
            n_alpha,
            beta: [0.0; 3],
            power,
        }
    }
}

/// Everything θ holds, plus the process-noise scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Params {
    /// Per sensor slot.
    pub sensors: [SensorParams; SENSORS],
    /// `σ_k = q |u_k|`: sd of the distance's deviation from the commanded motion per metre
    /// commanded.
    pub q_rel: f64,
    /// The commands' speed scale `s`: the distance changes by `s u_k` (1, the paper's model,
    /// unless a prior makes it identifiable).
    pub speed_scale: f64,
}

impl Params {
    /// The parameters as one vector (active sensors' alpha and beta, then q and the speed scale
    /// when estimated), for the convergence test.
    pub(crate) fn flat(&self, free: Free, out: &mut Vec<f64>) {
        out.clear();
        for s in self.sensors.iter().filter(|s| s.active) {
            out.extend_from_slice(&s.alpha[..s.n_alpha]);
            out.push(s.beta[s.power]);
        }
        if free.q {
            out.push(self.q_rel);
        }
        if free.speed_scale {
            out.push(self.speed_scale);
        }
    }

    /// The inverse of [`Params::flat`]; `None` when a noise level or `q` would not be positive
    /// and finite (an extrapolation that left the parameter space).
    pub(crate) fn with_flat(&self, free: Free, flat: &[f64]) -> Option<Params> {
        let mut out = *self;
        let mut it = flat.iter().copied();
        for s in out.sensors.iter_mut().filter(|s| s.active) {
            for a in &mut s.alpha[..s.n_alpha] {
                *a = it.next()?;
            }
            s.beta[s.power] = it.next()?;
            if s.beta[s.power].is_nan() || s.beta[s.power] <= 0.0 {
                return None;
            }
        }
        if free.q {
            out.q_rel = it.next()?;
            if out.q_rel.is_nan() || out.q_rel <= 0.0 {
                return None;
            }
        }
        if free.speed_scale {
            out.speed_scale = it.next()?;
            if out.speed_scale.is_nan() || out.speed_scale <= 0.0 {
                return None;
            }
        }
        flat.iter().all(|v| v.is_finite()).then_some(out)
    }
}

/// Which parameters beside the sensors' the M-step estimates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Free {
    /// The process-noise scale `q`.
    pub q: bool,
    /// The commands' speed scale.
    pub speed_scale: bool,
}

/// One step's data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct StepData {
    /// Readings per slot (meaningful where `has` is set).
    pub y: [f64; SENSORS],
    /// Which slots observed at this step.
    pub has: [bool; SENSORS],
    /// Commanded change of distance to the next step.
    pub u: f64,
}

/// The data set and the prior of the first state.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Data {
    /// One entry per sample.
    pub steps: Vec<StepData>,
    /// Mean of `d` at the first sample (start distance + commanded displacement to it).
    pub prior_mean: f64,
    /// Commanded displacement from t = 0 (where the start distance holds) to the first sample;
    /// it sets the prior's spread through the process noise.
    pub prior_u: f64,
    /// Extra prior variance of `d` (0 when the start distance is known, as in the paper).
    pub prior_var: f64,
}

/// The linearisation point of one step: the previous smoothed Gaussian of the state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Lin {
    /// Mean of `d`.
    pub m: f64,
    /// Variance of `d`.
    pub v: f64,
    /// Mean of the redundant state's `d²` entry (the paper's `x̂[3]`).
    pub d2: f64,
}

impl Lin {
    /// A known distance.
    pub(crate) fn exact(d: f64) -> Self {
        Self {
            m: d,
            v: 0.0,
            d2: d * d,
        }
    }

    /// From a smoothed mean and covariance of `[d, d²]`.
    pub(crate) fn from_smoothed(mean: &Vector2<f64>, cov: &Matrix2<f64>) -> Self {
        Self {
            m: mean[0],
            v: cov[(0, 0)].max(0.0),
            d2: mean[1],
        }
    }
}

/// `E[d^j]` for `d ~ N(m, v)`: exact for `0 ≤ j ≤ 4`; for negative `j` the second-order
/// (delta-method) expansion `m^j (1 + j(j−1)/2 · v/m²)`, whose neglected terms are
/// `O(v²/m⁴)`: below 1e-7 for the posterior sd (≲ 1 cm) and distances (≥ 0.2 m, the
/// XV-11's minimum range) of the paper's setting.
#[must_use]
pub(crate) fn moment(m: f64, v: f64, j: i32) -> f64 {
    match j {
        0 => 1.0,
        1 => m,
        2 => m * m + v,
        3 => m * m * m + 3.0 * m * v,
        4 => {
            let m2 = m * m;
            m2 * m2 + 6.0 * m2 * v + 3.0 * v * v
        }
        j => {
            let jf = f64::from(j);
            m.powi(j) * (1.0 + 0.5 * jf * (jf - 1.0) * v / (m * m))
        }
    }
}

/// The measurement noise variance of a sensor at a linearisation point: the paper's
/// `(β · x̂)²` with `x̂ = [1, d̂, x̂[3]]`, or its expectation under the Gaussian of `d`.
#[must_use]
pub(crate) fn noise_variance(beta: &[f64; 3], lin: &Lin, second_order: bool) -> f64 {
    if second_order {
        let mut r = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                if beta[i] != 0.0 && beta[j] != 0.0 {
                    r += beta[i] * beta[j] * moment(lin.m, lin.v, (i + j) as i32);
                }
            }
        }
        r
    } else {
        let sd = beta[0] + beta[1] * lin.m + beta[2] * lin.d2;
        sd * sd
    }
}

/// The prior and dynamics' process-noise covariance of `[d, d²]` for a step of commanded
/// length `u` from a distance whose mean is `m`; see the module docs.
#[must_use]
pub(crate) fn process_noise(q_rel: f64, u: f64, a: f64) -> (f64, Matrix2<f64>) {
    let s2 = (q_rel * u) * (q_rel * u);
    let f2 = FLOOR_D_M * FLOOR_D_M;
    let two_a = 2.0 * a;
    // The floor on d² is independent of the one on d (the paper's Q is diagonal); below 0.1 m
    // (nearer than any lidar reads) it stops shrinking so that P stays invertible.
    let floor_d2 = 4.0 * a.abs().max(0.1).powi(2) * f2;
    let q = Matrix2::new(
        s2 + f2,
        two_a * s2,
        two_a * s2,
        two_a * two_a * s2 + 2.0 * s2 * s2 + floor_d2,
    );
    (s2, q)
}

/// The model of one E-step pass: data, parameters and linearisation points.
pub(crate) struct EmModel<'a> {
    pub data: &'a Data,
    pub params: &'a Params,
    pub lin: &'a [Lin],
    pub second_order: bool,
}

impl StateSpaceModel<2> for EmModel<'_> {
    fn steps(&self) -> usize {
        self.data.steps.len()
    }

    fn prior(&self) -> Gaussian<2> {
        // d_0 = start + u_first + ν with ν from the motion before the first sample; its d² entry
        // gets the Gaussian's exact second moments.
        // The commanded displacement to the first sample, at the speed scale.
        let m = self.data.prior_mean + (self.params.speed_scale - 1.0) * self.data.prior_u;
        let (s2, mut cov) = process_noise(
            self.params.q_rel,
            self.params.speed_scale * self.data.prior_u,
            m,
        );
        let v = self.data.prior_var;
        cov += Matrix2::new(
            v,
            2.0 * m * v,
            2.0 * m * v,
            4.0 * m * m * v + 2.0 * v * v + 4.0 * s2 * v,
        );
        Gaussian::new(Vector2::new(m, m * m + s2 + v), cov)
    }

    fn transition(&self, k: usize) -> Transition<2> {
        let u = self.params.speed_scale * self.data.steps[k].u;
        let a = self.lin[k].m + u;
        let (s2, q) = process_noise(self.params.q_rel, u, a);
        Transition {
            // (d + u)² = d² + 2u d + u²: the paper's binomial rows of A_k and B_k (eq. 5),
            // plus E[ν²] = σ² in the d² entry.
            a: Matrix2::new(1.0, 0.0, 2.0 * u, 1.0),
            b: Vector2::new(u, u * u + s2),
            q,
        }
    }

    fn observations(&self, k: usize, out: &mut Observations<2>) {
        let step = &self.data.steps[k];
        let lin = &self.lin[k];
        for (slot, sensor) in self.params.sensors.iter().enumerate() {
            if !(sensor.active && step.has[slot]) {
                continue;
            }
            out.push(Observation {
                y: step.y[slot],
                offset: sensor.alpha[0],
                h: Vector2::new(sensor.alpha[1], sensor.alpha[2]),
                r: noise_variance(&sensor.beta, lin, self.second_order),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moments_match_the_gaussian() {
        let (m, v) = (2.0_f64, 0.01_f64);
        assert_eq!(moment(m, v, 2), 4.01);
        assert!((moment(m, v, 4) - (16.0 + 6.0 * 4.0 * 0.01 + 3.0e-4)).abs() < 1e-12);
        // E[1/d²] ≈ (1/m²)(1 + 3 v/m²) to second order.
        assert!((moment(m, v, -2) - 0.25 * (1.0 + 3.0 * 0.01 / 4.0)).abs() < 1e-15);
    }

    #[test]
    fn the_process_noise_is_positive_definite() {
        let (_, q) = process_noise(0.02, 0.02, 4.0);
        assert!(q.determinant() > 0.0 && q[(0, 0)] > 0.0);
    }
}
