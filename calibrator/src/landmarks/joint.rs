//! Beyond the paper: the joint refinement of the landmark positions, the stop positions and the
//! range model from bearings and ranges together.
//!
//! The paper estimates the landmarks from bearings alone at the *nominal* stops (eq. (23)) and
//! then regresses the ranges on distances computed from those estimates (eq. (28)): the ranges
//! never inform the geometry, and the stops' actual positions are never estimated. Here every
//! unknown is adjusted at once, by Levenberg–Marquardt on the weighted least-squares cost
//!
//! ```text
//!   Σ wrap(θ̃ₗₖ − ∠(cₗ − sₖ))² / σθ²                  bearings (eq. (5))
//! + Σ (d̃ₗₖ − Σᵢ αᵢ (|cₗ − sₖ| − R)ⁱ)² / σ²ₗₖ          ranges (eq. (3)), σ²ₗₖ = σ(d)²/nₗₖ
//! + Σ |sₖ − s̄ₖ|² / σₖ²                                 stops about their nominal s̄ₖ (eq. (8))
//! ```
//!
//! the maximum-likelihood problem of the paper's model with σθ, σs and σ(d) held at their
//! estimates (the paper's Sec. 3 sets it aside as too costly for an embedded system; it is a few
//! milliseconds here). Scale is fixed by the stops' prior only: scaling every position by λ
//! leaves the bearings unchanged and α absorbs λ in the ranges, exactly as in the paper, whose
//! scale comes from the commanded displacement.

use nalgebra::{DMatrix, DVector};

use super::regression::{horner, horner_derivative};
use hilsim_recording::wrap_angle;

/// One bearing-and-range observation for the refinement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointObservation {
    /// Landmark index.
    pub landmark: usize,
    /// Stop index.
    pub stop: usize,
    /// Bearing, radians, start-pose frame.
    pub bearing_rad: f64,
    /// Raw range d̃, metres.
    pub range_m: f64,
    /// Standard deviation of the range, metres.
    pub range_sd_m: f64,
}

/// The refinement problem.
#[derive(Debug, Clone, PartialEq)]
pub struct JointProblem {
    /// Observations.
    pub observations: Vec<JointObservation>,
    /// Initial landmark centres.
    pub landmarks: Vec<[f64; 2]>,
    /// Nominal stop (sensor) positions.
    pub stops: Vec<[f64; 2]>,
    /// Prior standard deviation of each stop about its nominal position, metres.
    pub stop_sd_m: Vec<f64>,
    /// Initial α.
    pub alpha: Vec<f64>,
    /// Standard deviation of a bearing, radians.
    pub bearing_sd_rad: f64,
    /// Landmark radius, metres.
    pub radius_m: f64,
}

/// The refined estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct JointSolution {
    /// Landmark centres.
    pub landmarks: Vec<[f64; 2]>,
    /// Stop positions.
    pub stops: Vec<[f64; 2]>,
    /// α.
    pub alpha: Vec<f64>,
    /// Iterations run.
    pub iterations: usize,
    /// The relative cost decrease fell below the tolerance.
    pub converged: bool,
    /// Cost at the start and at the end.
    pub cost: (f64, f64),
    /// Covariance of each landmark centre, (JᵀJ)⁻¹ at the solution (the weights being inverse
    /// variances), m².
    pub landmark_cov: Vec<[[f64; 2]; 2]>,
    /// Standard errors of α: the square roots of (JᵀJ)⁻¹'s α block, scaled by the residual
    /// variance per degree of freedom (cost / (m − n); about 1 when the weights are right), so
    /// they carry the landmarks' and the stops' uncertainty (infinite when JᵀJ is singular).
    pub alpha_sd: Vec<f64>,
}

impl JointProblem {
    fn unpack(&self, p: &DVector<f64>) -> (Vec<[f64; 2]>, Vec<[f64; 2]>, Vec<f64>) {
        let l = self.landmarks.len();
        let k = self.stops.len();
        let c = (0..l).map(|i| [p[2 * i], p[2 * i + 1]]).collect();
        let s = (0..k)
            .map(|i| [p[2 * l + 2 * i], p[2 * l + 2 * i + 1]])
            .collect();
        let a = (0..self.alpha.len())
            .map(|i| p[2 * l + 2 * k + i])
            .collect();
        (c, s, a)
    }

    /// Residuals and (optionally) the Jacobian at `p`.
    fn residuals(&self, p: &DVector<f64>, jac: Option<&mut DMatrix<f64>>) -> DVector<f64> {
        let (c, s, a) = self.unpack(p);
        let l = c.len();
        let k = s.len();
        let m = 2 * self.observations.len() + 2 * k;
        let mut r = DVector::zeros(m);
        let mut j = jac;
        if let Some(j) = j.as_deref_mut() {
            j.fill(0.0);
        }
        let ca = 2 * l;
        let aa = 2 * l + 2 * k;
        for (o, ob) in self.observations.iter().enumerate() {
            let (cl, sk) = (c[ob.landmark], s[ob.stop]);
            let (dx, dy) = (cl[0] - sk[0], cl[1] - sk[1]);
            let rho2 = (dx * dx + dy * dy).max(1e-12);
            let rho = rho2.sqrt();
            let sb = self.bearing_sd_rad;
            r[2 * o] = wrap_angle(ob.bearing_rad - dy.atan2(dx)) / sb;
            let d = rho - self.radius_m;
            let sr = ob.range_sd_m;
            r[2 * o + 1] = (ob.range_m - horner(&a, d)) / sr;
            if let Some(j) = j.as_deref_mut() {
                let (bx, by) = (dy / (sb * rho2), -dx / (sb * rho2));
                let fp = horner_derivative(&a, d);
                let (rx, ry) = (-fp * dx / (rho * sr), -fp * dy / (rho * sr));
                let ci = 2 * ob.landmark;
                let si = ca + 2 * ob.stop;
                j[(2 * o, ci)] = bx;
                j[(2 * o, ci + 1)] = by;
                j[(2 * o, si)] = -bx;
                j[(2 * o, si + 1)] = -by;
                j[(2 * o + 1, ci)] = rx;
                j[(2 * o + 1, ci + 1)] = ry;
                j[(2 * o + 1, si)] = -rx;
                j[(2 * o + 1, si + 1)] = -ry;
                let mut pw = 1.0;
                for i in 0..a.len() {
                    j[(2 * o + 1, aa + i)] = -pw / sr;
                    pw *= d;
                }
            }
        }
        let base = 2 * self.observations.len();
        for (i, (sk, nom)) in s.iter().zip(&self.stops).enumerate() {
            let sd = self.stop_sd_m[i];
            r[base + 2 * i] = (sk[0] - nom[0]) / sd;
            r[base + 2 * i + 1] = (sk[1] - nom[1]) / sd;
            if let Some(j) = j.as_deref_mut() {
                j[(base + 2 * i, ca + 2 * i)] = 1.0 / sd;
                j[(base + 2 * i + 1, ca + 2 * i + 1)] = 1.0 / sd;
            }
        }
        r
    }

    /// The weighted squared residuals at a solution, by group: bearings, ranges, stop priors;
    /// with the number of residuals of each.
    #[must_use]
    pub fn chi2_by_group(&self, sol: &JointSolution) -> [(f64, usize); 3] {
        let p = self.pack(&sol.landmarks, &sol.stops, &sol.alpha);
        let r = self.residuals(&p, None);
        let n = self.observations.len();
        let sum = |a: usize, b: usize| r.rows(a, b - a).norm_squared();
        [
            ((0..n).map(|o| r[2 * o].powi(2)).sum(), n),
            ((0..n).map(|o| r[2 * o + 1].powi(2)).sum(), n),
            (sum(2 * n, r.len()), r.len() - 2 * n),
        ]
    }

    /// Number of parameters.
    #[must_use]
    pub fn parameters(&self) -> usize {
        2 * self.landmarks.len() + 2 * self.stops.len() + self.alpha.len()
    }

    fn pack(&self, landmarks: &[[f64; 2]], stops: &[[f64; 2]], alpha: &[f64]) -> DVector<f64> {
        let l = landmarks.len();
        let k = stops.len();
        let mut p = DVector::zeros(2 * l + 2 * k + alpha.len());
        for (i, c) in landmarks.iter().enumerate() {
            p[2 * i] = c[0];
            p[2 * i + 1] = c[1];
        }
        for (i, s) in stops.iter().enumerate() {
            p[2 * l + 2 * i] = s[0];
            p[2 * l + 2 * i + 1] = s[1];
        }
        for (i, a) in alpha.iter().enumerate() {
            p[2 * l + 2 * k + i] = *a;
        }
        p
    }

    /// Levenberg–Marquardt from the initial values. `None` when the cost is not finite at the
    /// start.
    #[must_use]
    pub fn solve(&self, max_iterations: usize, tolerance: f64) -> Option<JointSolution> {
        let l = self.landmarks.len();
        let k = self.stops.len();
        let np = 2 * l + 2 * k + self.alpha.len();
        let mut p = self.pack(&self.landmarks, &self.stops, &self.alpha);
        let m = 2 * self.observations.len() + 2 * k;
        let mut jac = DMatrix::zeros(m, np);
        let mut r = self.residuals(&p, Some(&mut jac));
        let mut cost = r.norm_squared();
        if !cost.is_finite() {
            return None;
        }
        let cost0 = cost;
        let mut lambda = 1e-3;
        let mut iterations = 0;
        let mut converged = false;
        while iterations < max_iterations {
            iterations += 1;
            let jt = jac.transpose();
            let a = &jt * &jac;
            let g = &jt * &r;
            let mut accepted = false;
            for _ in 0..20 {
                let mut damped = a.clone();
                for i in 0..np {
                    damped[(i, i)] += lambda * a[(i, i)].max(1e-12);
                }
                let Some(step) = damped.cholesky().map(|ch| ch.solve(&g)) else {
                    lambda *= 10.0;
                    continue;
                };
                let trial = &p - &step;
                let rt = self.residuals(&trial, None);
                let ct = rt.norm_squared();
                if ct.is_finite() && ct <= cost {
                    let decrease = (cost - ct) / cost.max(1e-300);
                    p = trial;
                    r = self.residuals(&p, Some(&mut jac));
                    cost = ct;
                    lambda = (lambda / 3.0).max(1e-12);
                    accepted = true;
                    if decrease < tolerance {
                        converged = true;
                    }
                    break;
                }
                lambda *= 4.0;
            }
            if !accepted {
                // No step lowers the cost: a minimum to working precision.
                converged = true;
            }
            if converged {
                break;
            }
        }
        let (landmarks, stops, alpha) = self.unpack(&p);
        let info = jac.transpose() * &jac;
        let inverse = info.clone().try_inverse();
        let dof = m.saturating_sub(np).max(1) as f64;
        let alpha_sd = (0..alpha.len())
            .map(|i| {
                let j = 2 * l + 2 * k + i;
                inverse.as_ref().map_or(f64::INFINITY, |inv| {
                    (inv[(j, j)] * cost / dof).max(0.0).sqrt()
                })
            })
            .collect();
        let landmark_cov = match inverse {
            Some(inv) => (0..l)
                .map(|i| {
                    let j = 2 * i;
                    [
                        [inv[(j, j)], inv[(j, j + 1)]],
                        [inv[(j + 1, j)], inv[(j + 1, j + 1)]],
                    ]
                })
                .collect(),
            None => vec![[[f64::INFINITY, 0.0], [0.0, f64::INFINITY]]; l],
        };
        Some(JointSolution {
            landmarks,
            stops,
            alpha,
            iterations,
            converged,
            cost: (cost0, cost),
            landmark_cov,
            alpha_sd,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_data_is_a_fixed_point_and_a_perturbed_start_returns() {
        let alpha = vec![0.0525, 0.8838, 0.0584];
        let stops: Vec<[f64; 2]> = (0..10).map(|k| [0.3 * k as f64, 0.0]).collect();
        let lms = vec![[1.0, 1.2], [2.0, -1.1], [4.2, -0.5]];
        let mut obs = Vec::new();
        for (l, c) in lms.iter().enumerate() {
            for (k, s) in stops.iter().enumerate() {
                let (dx, dy) = (c[0] - s[0], c[1] - s[1]);
                obs.push(JointObservation {
                    landmark: l,
                    stop: k,
                    bearing_rad: dy.atan2(dx),
                    range_m: horner(&alpha, dx.hypot(dy) - 0.12),
                    range_sd_m: 0.01,
                });
            }
        }
        let problem = JointProblem {
            observations: obs,
            landmarks: lms.iter().map(|c| [c[0] + 0.05, c[1] - 0.04]).collect(),
            stop_sd_m: vec![0.01; stops.len()],
            stops,
            alpha: vec![0.0, 1.0, 0.0],
            bearing_sd_rad: 0.01,
            radius_m: 0.12,
        };
        let sol = problem.solve(100, 1e-14).unwrap();
        assert!(sol.converged);
        for (a, b) in sol.landmarks.iter().zip(&lms) {
            assert!(
                (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6,
                "{a:?}"
            );
        }
        for (a, b) in sol.alpha.iter().zip(&alpha) {
            assert!((a - b).abs() < 1e-5, "{:?}", sol.alpha);
        }
    }
}
