//! How well a prediction fits a reading: log-likelihood, normal score, residual; and their
//! summaries.

use super::data::{Predictive, SensorData, Z_CLIP};
use crate::physics::Gaussian;
use hilsim_lidar_emulator::normal;

/// How well one prediction fits one reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Fit {
    /// Log-likelihood of the reading.
    pub ll: f64,
    /// Normal score (probability integral transform), clipped to ±[`Z_CLIP`].
    pub z: f64,
    /// Reading minus the mean of the component that explains it best, metres (NaN: no
    /// prediction).
    pub residual: f64,
    /// That component's standard deviation, metres.
    pub sd: f64,
    /// Whether the outlier component explains the reading better than the prediction does
    /// (posterior probability above ½).
    pub outlier: bool,
}

/// The fit of reading `y` to `pred` with an outlier component of weight `epsilon` and density
/// `outlier_density`.
pub(crate) fn fit(y: f64, pred: &[Gaussian], epsilon: f64, outlier_density: f64) -> Fit {
    if pred.is_empty() {
        // Nothing was expected: only the outlier component explains it.
        return Fit {
            ll: outlier_density.ln(),
            z: Z_CLIP,
            residual: f64::NAN,
            sd: f64::NAN,
            outlier: true,
        };
    }
    let mut density = 0.0;
    let mut cdf = 0.0;
    let mut best = (f64::NEG_INFINITY, 0usize);
    for (k, g) in pred.iter().enumerate() {
        let ln = g.weight.ln() + g.ln_density(y);
        density += ln.exp();
        cdf += g.weight * g.cdf(y);
        if ln > best.0 {
            best = (ln, k);
        }
    }
    let total = (1.0 - epsilon) * density + outlier_density;
    let ll = if total > 0.0 {
        total.ln()
    } else {
        f64::MIN_POSITIVE.ln()
    };
    // The uniform part's CDF is taken as ½ (its span is not centred on the reading): it adds at
    // most ε/2 to the probability, 0.001 here, invisible in the tests.
    let u = ((1.0 - epsilon) * cdf + epsilon * 0.5).clamp(1e-300, 1.0 - 1e-16);
    let (mean, sd) = pred[best.1].moments();
    Fit {
        ll,
        z: normal::quantile(u).clamp(-Z_CLIP, Z_CLIP),
        residual: y - mean,
        sd,
        outlier: outlier_density > (1.0 - epsilon) * density,
    }
}

/// The log-likelihood of reading `y` alone (what the fits maximise; no normal score).
pub(crate) fn log_likelihood(y: f64, pred: &[Gaussian], epsilon: f64, outlier_density: f64) -> f64 {
    let density: f64 = pred.iter().map(|g| g.weight * g.ln_density(y).exp()).sum();
    let total = (1.0 - epsilon) * density + outlier_density;
    if total > 0.0 {
        total.ln()
    } else {
        f64::MIN_POSITIVE.ln()
    }
}

/// The fits of `rows` of `data` under predictions `preds` (one per row).
pub(crate) fn fits(data: &SensorData, rows: &[usize], preds: &[Predictive]) -> Vec<Fit> {
    rows.iter()
        .zip(preds)
        .map(|(&i, p)| fit(data.y[i], p, data.epsilon, data.outlier_density))
        .collect()
}

/// Root mean square of the residuals of `fits` that have one (and that `keep` keeps), and the
/// noise floor there (the root mean square of the predicted standard deviations).
pub(crate) fn rmse(fits: &[Fit], keep: impl Fn(usize) -> bool) -> (f64, f64, usize) {
    let (mut se, mut var, mut n) = (0.0, 0.0, 0usize);
    for (i, f) in fits.iter().enumerate() {
        if f.residual.is_finite() && keep(i) {
            se += f.residual * f.residual;
            var += f.sd * f.sd;
            n += 1;
        }
    }
    if n == 0 {
        return (f64::NAN, f64::NAN, 0);
    }
    ((se / n as f64).sqrt(), (var / n as f64).sqrt(), n)
}
