//! Standard errors of EM's estimates from the observed information (Louis 1982 computes it from
//! the complete-data quantities; here it is taken directly): the negative Hessian of the
//! log-posterior `log p(Y | θ) + log p(θ)` at the final θ, by central differences of the
//! Kalman filter's exact log-likelihood of the model (the noise linearised at the final
//! smoothed state, as EM's last E-step). Its inverse is the asymptotic covariance of θ̂
//! (Efron & Hinkley 1978 prefer the observed to the expected information for exactly this).
//! The nuisance parameters EM estimates (`q`, the speed scale) are in θ, so each sd accounts for
//! them.

use nalgebra::DMatrix;

use super::engine::log_prior;
use super::model::{Data, EmModel, Lin, Params};
use super::options::EmOptions;
use crate::kalman_smoother::RtsSmoother;

/// Relative step of the differences: the log-likelihood is smooth in θ, and at 1e-4 of a
/// parameter its curvature (~1/sd²) dwarfs both the truncation (∝ h²) and the rounding
/// (~1e-16 |log L| / h²) errors.
const RELATIVE_STEP: f64 = 1e-4;

/// The standard error of each entry of `params.flat(opts.free())`; `None` when the information
/// matrix is not positive definite (a parameter the data does not determine).
pub(crate) fn standard_errors(
    data: &Data,
    params: &Params,
    lin: &[Lin],
    opts: &EmOptions,
) -> Option<Vec<f64>> {
    let free = opts.free();
    let mut theta = Vec::new();
    params.flat(free, &mut theta);
    let mut smoother = RtsSmoother::<2>::new();
    let mut log_posterior = |flat: &[f64]| -> Option<f64> {
        let p = params.with_flat(free, flat)?;
        let model = EmModel {
            data,
            params: &p,
            lin,
            second_order: opts.e_step.second_order(),
        };
        let ll = smoother.filter(&model).ok()?;
        Some(ll + log_prior(&p, &opts.priors))
    };
    let n = theta.len();
    let steps: Vec<f64> = theta
        .iter()
        .map(|v| RELATIVE_STEP * v.abs().max(1e-3))
        .collect();
    let at = |moves: &[(usize, f64)]| {
        let mut t = theta.clone();
        for &(i, h) in moves {
            t[i] += h;
        }
        t
    };
    let centre = log_posterior(&theta)?;
    let mut info = DMatrix::<f64>::zeros(n, n);
    for i in 0..n {
        let hi = steps[i];
        let plus = log_posterior(&at(&[(i, hi)]))?;
        let minus = log_posterior(&at(&[(i, -hi)]))?;
        info[(i, i)] = -(plus - 2.0 * centre + minus) / (hi * hi);
        for j in 0..i {
            let hj = steps[j];
            let pp = log_posterior(&at(&[(i, hi), (j, hj)]))?;
            let pm = log_posterior(&at(&[(i, hi), (j, -hj)]))?;
            let mp = log_posterior(&at(&[(i, -hi), (j, hj)]))?;
            let mm = log_posterior(&at(&[(i, -hi), (j, -hj)]))?;
            let v = -(pp - pm - mp + mm) / (4.0 * hi * hj);
            info[(i, j)] = v;
            info[(j, i)] = v;
        }
    }
    let covariance = info.cholesky()?.inverse();
    (0..n)
        .map(|i| {
            let v = covariance[(i, i)];
            (v.is_finite() && v > 0.0).then(|| v.sqrt())
        })
        .collect()
}
