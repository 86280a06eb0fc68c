//! Explain: fit each catalogued effect's parameters by maximum likelihood on the training half,
//! then compare it with "none" (and with the others) on the held-out half: the held-out
//! log-likelihood gain is the score, the Bayesian information criterion on the training half a
//! second opinion. The fitted model's residuals are located again: an effect that leaves the
//! located structure standing explains only part of the mismatch.

use crate::catalogue::{Effect, Sensor};
use crate::locate::{locate, Evidence};
use crate::optimize::{maximize, standard_errors};
use crate::physics::Hypothesis;
use crate::residuals::{fits, log_likelihood, rmse, Context, SensorData};

/// One candidate effect, fitted and scored.
#[derive(Debug, Clone, PartialEq)]
pub struct CandidateFit {
    /// The effect.
    pub effect: Effect,
    /// Maximum-likelihood parameters (training half).
    pub params: Vec<f64>,
    /// Their standard errors (inverse observed information); NaN where the likelihood is flat.
    pub param_sd: Vec<f64>,
    /// Log-likelihood gain over "none" on the training half.
    pub train_gain: f64,
    /// Log-likelihood gain over "none" on the held-out half: the score.
    pub heldout_gain: f64,
    /// BIC gain over "none": `2 · train_gain − k ln n` (positive favours the effect).
    pub bic_gain: f64,
    /// Held-out RMSE of the sensor's residuals before (nominal) and after the fit, metres.
    pub rmse_before: f64,
    /// See `rmse_before`.
    pub rmse_after: f64,
    /// The noise floor there: RMS of the predicted standard deviations after the fit, metres.
    pub noise_floor: f64,
    /// Held-out readings the RMSEs are over.
    pub heldout_n: usize,
    /// The strongest structure left in the sensor's residuals after the fit.
    pub remaining: Option<Evidence>,
}

/// Training rows for fitting: every `stride`-th, at most `max_rows`.
fn fit_rows(data: &SensorData, max_rows: usize) -> Vec<usize> {
    let train = data.rows(Some(false));
    let stride = train.len().div_ceil(max_rows.max(1)).max(1);
    train.into_iter().step_by(stride).collect()
}

fn total_ll(ctx: &Context<'_>, data: &SensorData, h: &Hypothesis, rows: &[usize]) -> f64 {
    let preds = ctx.predict(data, h, rows);
    rows.iter()
        .zip(&preds)
        .map(|(&i, p)| log_likelihood(data.y[i], p, data.epsilon, data.outlier_density))
        .sum()
}

/// Fits `effect` to its sensor's data and scores it.
pub(crate) fn fit_candidate(
    ctx: &Context<'_>,
    data: &SensorData,
    effect: Effect,
    max_fit_rows: usize,
    names: &dyn Fn(u32) -> String,
) -> CandidateFit {
    let specs = effect.params();
    let train = fit_rows(data, max_fit_rows);
    let nominal = Hypothesis::nominal();
    let train_none = total_ll(ctx, data, &nominal, &train);
    let mut objective =
        |x: &[f64]| total_ll(ctx, data, &Hypothesis::with(effect, x.to_vec()), &train);
    let (params, best) = maximize(specs, &mut objective);
    let param_sd = standard_errors(specs, &params, best, &mut objective, 2e-3);
    let fitted = Hypothesis::with(effect, params.clone());
    let heldout = data.rows(Some(true));
    let before = fits(data, &heldout, &ctx.predict(data, &nominal, &heldout));
    let after = fits(data, &heldout, &ctx.predict(data, &fitted, &heldout));
    let heldout_gain: f64 =
        after.iter().map(|f| f.ll).sum::<f64>() - before.iter().map(|f| f.ll).sum::<f64>();
    // RMSE over the held-out readings the fitted model explains (not outliers to it), before
    // and after: a reading neither model can predict (a rare direction-noise flip past the
    // quadrature's reach) would otherwise dominate both.
    let both = |i: usize| before[i].residual.is_finite() && !after[i].outlier;
    let (rmse_before, _, _) = rmse(&before, both);
    let (rmse_after, noise_floor, heldout_n) = rmse(&after, both);
    // What is left after the fix, over all readings.
    let all = data.rows(None);
    let all_after = fits(data, &all, &ctx.predict(data, &fitted, &all));
    let remaining = locate(data, &all, &all_after, names, !ctx.estimated)
        .into_iter()
        .max_by(|a, b| a.score.total_cmp(&b.score));
    let train_gain = best - train_none;
    CandidateFit {
        effect,
        bic_gain: 2.0 * train_gain - specs.len() as f64 * (train.len() as f64).ln(),
        params,
        param_sd,
        train_gain,
        heldout_gain,
        rmse_before,
        rmse_after,
        noise_floor,
        heldout_n,
        remaining,
    }
}

/// Whether `effect` can be tried on these data at all.
pub(crate) fn applicable(effect: Effect, ctx: &Context<'_>, sensors: &[Sensor]) -> bool {
    if !sensors.contains(&effect.sensor()) {
        return false;
    }
    match effect {
        // A per-reading lidar already takes each reading at its own instant.
        Effect::LidarMotionSkew => ctx.physics.declared().lidar.is_some_and(|l| l.snapshot),
        _ => true,
    }
}
