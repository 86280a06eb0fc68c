//! The EM iteration, plain or accelerated by SQUAREM, and its convergence test.

use super::estep::{e_step, update_lin};
use super::model::{Data, Lin, Params};
use super::mstep;
use super::options::EmOptions;
use crate::kalman_smoother::RtsSmoother;
use crate::CalibrationError;

/// The EM iteration: the map θ ↦ M(E(θ)) with its workspace and trace.
pub(super) struct Engine<'a> {
    pub(super) data: &'a Data,
    pub(super) opts: &'a EmOptions,
    pub(super) smoother: RtsSmoother<2>,
    /// The linearisation point of the next E-step (the last smoothed state).
    pub(super) lin: Vec<Lin>,
    /// `log p(y; θ)` of every E-step.
    pub(super) log_likelihoods: Vec<f64>,
    /// E-steps (EM map evaluations) so far.
    pub(super) iterations: usize,
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
        // MAP-EM climbs the log-posterior: the log-likelihood plus the priors' log-density.
        let ll = ll + log_prior(params, &self.opts.priors);
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
            self.opts.free(),
            &self.opts.priors,
        )?;
        update_lin(&mut self.lin, &self.smoother);
        Ok((next, ll))
    }

    fn flat(&self, p: &Params) -> Vec<f64> {
        let mut v = Vec::new();
        p.flat(self.opts.free(), &mut v);
        v
    }

    /// The convergence test between consecutive iterates and log-likelihoods.
    fn settled(&self, old: &Params, new: &Params, ll_old: f64, ll_new: f64) -> bool {
        let tol = self.opts.tolerance;
        relative_change(&self.flat(old), &self.flat(new)) < tol
            && (ll_new - ll_old).abs() <= tol * ll_new.abs().max(1.0)
    }

    /// Plain EM; returns whether it converged.
    pub(super) fn plain(&mut self, params: &mut Params) -> Result<bool, CalibrationError> {
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
    pub(super) fn squarem(&mut self, params: &mut Params) -> Result<bool, CalibrationError> {
        let free = self.opts.free();
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
            let Some(theta_x) = theta0.with_flat(free, &extrapolated) else {
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

/// Largest relative change of any parameter, each against its own size with a floor of 1e-4
/// (a tenth of a millimetre, or 1e-4 of a unit gain: below what any of these sensors resolves).
fn relative_change(old: &[f64], new: &[f64]) -> f64 {
    old.iter()
        .zip(new)
        .map(|(a, b)| (a - b).abs() / a.abs().max(1e-4))
        .fold(0.0, f64::max)
}

/// The priors' log-density at `params` (up to a constant): `−Σ (α_i − μ_i)² / (2 s_i²)`.
pub(super) fn log_prior(params: &Params, priors: &super::prior::Priors) -> f64 {
    let mut sum = 0.0;
    for (slot, sensor) in params.sensors.iter().enumerate() {
        if !sensor.active {
            continue;
        }
        for (i, alpha) in sensor.alpha.iter().enumerate() {
            if let Some((mean, sd)) = priors.get(slot, i) {
                sum -= (alpha - mean).powi(2) / (2.0 * sd * sd);
            }
        }
    }
    sum
}
