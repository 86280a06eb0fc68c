//! The ground-truth baseline: each sensor's model of eq. (2) fitted by maximum likelihood
//! against the true distances, the bias order chosen by AIC, as in the authors' earlier work.
//!
//! For a sensor reading `y_k = Σ_{i≤n} α_i d_k^i + β d_k^p e_k` with the true `d_k` known, the
//! noise shape `d^p` is known too, so maximum likelihood is weighted least squares with weights
//! `d^(−2p)`, and `β² = (1/N) Σ d^(−2p) r_k²` (closed form). Every bias order `n` in
//! `0..=max_order` and noise power `p ∈ {0, 1, 2}` (constant, proportional, quadratic sd) is
//! fitted, and the pair with the least `AIC = 2 (n + 2) − 2 log L` kept.
//!
//! The true distance of each sample is the start distance minus the lidar's displacement
//! along its initial beam direction, from `truth.csv` (see [`crate::target_samples`]); every
//! sensor (lidar, odometer as a distance, sonar) is regressed on it, as EM models them.
//!
//! # Reference
//! A. Alhashimi, D. Varagnolo, T. Gustafsson, "Statistical modeling and calibration of
//! triangulation lidars", ICINCO 2016 (ML fit, AIC order selection); the EM paper (IEEE
//! Sensors J. 2017) compares against it in Sec. VI.
//!
//! ```
//! use hilsim_calibrator::groundtruth::fit_aic;
//! // Quadratic bias, quadratic noise: y = 0.05 + 0.9 d + 0.06 d² (+ tiny deterministic noise).
//! let d: Vec<f64> = (0..200).map(|k| 0.5 + 3.5 * k as f64 / 199.0).collect();
//! let y: Vec<f64> = d
//!     .iter()
//!     .enumerate()
//!     .map(|(k, &d)| 0.05 + 0.9 * d + 0.06 * d * d + 0.001 * d * d * ((k * 7919 % 13) as f64 - 6.0) / 3.7)
//!     .collect();
//! let fit = fit_aic(&d, &y, 4)?;
//! assert_eq!(fit.order(), 2);
//! # Ok::<(), hilsim_calibrator::CalibrationError>(())
//! ```

use std::collections::BTreeMap;

use hilsim_recording::Recording;
use nalgebra::{DMatrix, DVector};

use crate::landmarks::regression;
use crate::target_samples::{self, SampleOptions};
use crate::{checks, Calibration, CalibrationError, Method, Metrics, Sensor, SensorModel};

/// `ln(2π)`.
const LN_2PI: f64 = 1.837_877_066_409_345_5;

/// Fewest samples per sensor (as EM's [`crate::em::MIN_LIDAR_READINGS`]).
pub const MIN_READINGS: usize = 10;

/// Highest noise power tried: the triangulation lidar's sd grows with d² (the EM paper's
/// Sec. II-A); nothing in these sensors grows faster.
pub const MAX_NOISE_POWER: usize = 2;

/// What the baseline does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Beam angle in the lidar's frame, degrees (0: forward).
    pub beam_deg: f64,
    /// Lidar-to-target distance at t = 0, metres; overrides the recording's `meta.toml`.
    pub start_distance_m: Option<f64>,
    /// Highest bias order tried (the ICINCO 2016 paper went to 4).
    pub max_order: usize,
}

impl Options {
    /// The target these options name.
    #[must_use]
    pub fn sample_options(&self) -> SampleOptions {
        SampleOptions {
            beam_deg: self.beam_deg,
            start_distance_m: self.start_distance_m,
        }
    }
}

impl Default for Options {
    fn default() -> Self {
        Self {
            beam_deg: 0.0,
            start_distance_m: None,
            max_order: 4,
        }
    }
}

/// One maximum-likelihood fit.
#[derive(Debug, Clone, PartialEq)]
pub struct PolyFit {
    /// Bias coefficients α_0..α_n.
    pub alpha: Vec<f64>,
    /// Noise power `p` of `sd = β d^p`.
    pub noise_power: usize,
    /// Noise coefficient β.
    pub beta: f64,
    /// The maximised log-likelihood.
    pub log_likelihood: f64,
    /// `2 (n + 2) − 2 log L`.
    pub aic: f64,
    /// Number of samples.
    pub n: usize,
    /// Standard errors of `alpha`: `β (Φᵀ W Φ)^(−½)` diagonal, the weighted least-squares
    /// covariance `β² (Φᵀ W Φ)⁻¹` (exact for Gaussian noise of known shape, the distances known).
    pub alpha_sd: Vec<f64>,
    /// Standard error of `beta`: `β / √(2N)`, the ML estimate's asymptotic sd (Fisher
    /// information of a Gaussian sd: 2N/β²).
    pub beta_sd: f64,
}

impl PolyFit {
    /// The bias order `n` (degree of the polynomial).
    #[must_use]
    pub fn order(&self) -> usize {
        self.alpha.len() - 1
    }

    /// The model in the interface's form (beta padded with zeros below the power).
    #[must_use]
    pub fn model(&self) -> SensorModel {
        let mut beta = vec![0.0; self.noise_power + 1];
        beta[self.noise_power] = self.beta;
        let mut beta_sd = vec![0.0; self.noise_power + 1];
        beta_sd[self.noise_power] = self.beta_sd;
        SensorModel {
            alpha: self.alpha.clone(),
            beta,
            alpha_sd: self.alpha_sd.clone(),
            beta_sd,
        }
    }
}

/// The ML fit of one bias order and noise power to readings `y` at true distances `d`.
///
/// # Errors
/// [`CalibrationError::TooFewSamples`] with no more samples than parameters,
/// [`CalibrationError::Invalid`] for mismatched lengths, non-finite values or a non-positive
/// distance with `noise_power > 0`, [`CalibrationError::Unidentifiable`] when the fit is
/// degenerate (e.g. every distance equal) or leaves no residual.
pub fn fit_ml(
    d: &[f64],
    y: &[f64],
    order: usize,
    noise_power: usize,
) -> Result<PolyFit, CalibrationError> {
    if d.len() != y.len() {
        return Err(CalibrationError::Invalid(format!(
            "{} distances but {} readings",
            d.len(),
            y.len()
        )));
    }
    let n = d.len();
    if n <= order + 2 {
        return Err(CalibrationError::TooFewSamples(format!(
            "{n} samples cannot fit a bias of order {order} and a noise level"
        )));
    }
    if !d.iter().chain(y).all(|v| v.is_finite()) {
        return Err(CalibrationError::Invalid(
            "a non-finite distance or reading".into(),
        ));
    }
    if noise_power > 0 && d.iter().any(|&v| v <= 0.0) {
        return Err(CalibrationError::Invalid(
            "a non-positive true distance: the noise model d^p needs d > 0".into(),
        ));
    }
    let weight_sqrt: Vec<f64> = d.iter().map(|&v| v.powi(-(noise_power as i32))).collect();
    let design = DMatrix::from_fn(n, order + 1, |k, i| weight_sqrt[k] * d[k].powi(i as i32));
    let rhs = DVector::from_fn(n, |k, _| weight_sqrt[k] * y[k]);
    let svd = design.clone().svd(true, true);
    // A design whose columns are dependent (too few distinct distances) has a singular value
    // at rounding level relative to the largest.
    let (smax, smin) = (svd.singular_values.max(), svd.singular_values.min());
    if smin.is_nan() || smin <= 1e-10 * smax {
        return Err(CalibrationError::Unidentifiable(format!(
            "the true distances do not vary enough to fit a bias of order {order}"
        )));
    }
    let alpha = svd
        .solve(&rhs, 0.0)
        .map_err(|e| CalibrationError::Unidentifiable(e.to_string()))?;
    let residual = rhs - design * &alpha;
    let beta2 = residual.norm_squared() / n as f64;
    if !(beta2 > 0.0 && beta2.is_finite()) {
        return Err(CalibrationError::Unidentifiable(format!(
            "the order-{order} fit leaves no residual: the readings carry no noise to model"
        )));
    }
    let sum_ln_d: f64 = if noise_power > 0 {
        d.iter().map(|v| v.ln()).sum()
    } else {
        0.0
    };
    let nf = n as f64;
    // (Φᵀ W Φ)⁻¹ = V Σ⁻² Vᵀ from the weighted design's SVD.
    let v_t = svd
        .v_t
        .as_ref()
        .ok_or_else(|| CalibrationError::Unidentifiable("the design's SVD has no V".into()))?;
    let alpha_sd: Vec<f64> = (0..=order)
        .map(|i| {
            let var: f64 = (0..svd.singular_values.len())
                .map(|j| (v_t[(j, i)] / svd.singular_values[j]).powi(2))
                .sum();
            (beta2 * var).sqrt()
        })
        .collect();
    let log_likelihood =
        -0.5 * (nf * (LN_2PI + beta2.ln()) + 2.0 * noise_power as f64 * sum_ln_d + nf);
    Ok(PolyFit {
        alpha: alpha.iter().copied().collect(),
        noise_power,
        beta: beta2.sqrt(),
        log_likelihood,
        aic: 2.0 * (order as f64 + 2.0) - 2.0 * log_likelihood,
        n,
        alpha_sd,
        beta_sd: (beta2 / (2.0 * nf)).sqrt(),
    })
}

/// The fit of least AIC over bias orders `0..=max_order` and noise powers `0..=2`.
///
/// # Errors
/// As [`fit_ml`] when no candidate can be fitted.
pub fn fit_aic(d: &[f64], y: &[f64], max_order: usize) -> Result<PolyFit, CalibrationError> {
    let mut best: Option<PolyFit> = None;
    let mut first_error = None;
    for order in 0..=max_order {
        for power in 0..=MAX_NOISE_POWER {
            match fit_ml(d, y, order, power) {
                Ok(fit) if fit.aic.is_finite() => {
                    if best.as_ref().is_none_or(|b| fit.aic < b.aic) {
                        best = Some(fit);
                    }
                }
                Ok(_) => {}
                Err(e) => {
                    first_error.get_or_insert(e);
                }
            }
        }
    }
    best.ok_or_else(|| {
        first_error.unwrap_or_else(|| CalibrationError::Unidentifiable("no model fits".into()))
    })
}

/// The distance whose expected reading is `y`: the root of `Σ α_i d^i = y` nearest `y` (a
/// sensor's reading is close to the distance it measures), by Newton's method with a bracketing
/// fallback. `None` when there is none within `[0, 4 |y| + 10]` m or the bias does not depend
/// on `d`.
#[must_use]
pub fn invert(alpha: &[f64], y: f64) -> Option<f64> {
    if !y.is_finite() || alpha.len() < 2 || alpha.iter().any(|a| !a.is_finite()) {
        return None;
    }
    let f = |d: f64| alpha.iter().rev().fold(0.0, |acc, a| acc * d + a) - y;
    let df = |d: f64| {
        alpha
            .iter()
            .enumerate()
            .skip(1)
            .rev()
            .fold(0.0, |acc, (i, a)| acc * d + i as f64 * a)
    };
    let tolerance = 1e-12 * (1.0 + y.abs());
    let mut d = y;
    for _ in 0..50 {
        let slope = df(d);
        if slope == 0.0 || !slope.is_finite() {
            break;
        }
        let step = f(d) / slope;
        d -= step;
        if step.abs() <= tolerance {
            return (d.is_finite() && d >= 0.0).then_some(d);
        }
    }
    // Fallback: the sign change nearest y on a 1 mm grid, then bisection.
    let hi = 4.0 * y.abs() + 10.0;
    let steps = (hi / 1e-3) as usize;
    let mut best: Option<(f64, f64)> = None;
    let mut prev = (0.0, f(0.0));
    for i in 1..=steps {
        let x = i as f64 * 1e-3;
        let fx = f(x);
        if prev.1 == 0.0 || prev.1.signum() != fx.signum() {
            let (mut a, mut b) = (prev.0, x);
            for _ in 0..60 {
                let mid = 0.5 * (a + b);
                if f(a).signum() == f(mid).signum() {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            let root = 0.5 * (a + b);
            if best.is_none_or(|(r, _)| (root - y).abs() < (r - y).abs()) {
                best = Some((root, 0.0));
            }
        }
        prev = (x, fx);
    }
    best.map(|(r, _)| r)
}

/// Fits every sensor of the recording against the truth.
///
/// # Errors
/// [`CalibrationError::Missing`] without `truth.csv`, a lidar or the start distance;
/// [`CalibrationError::TooFewSamples`] with fewer than [`MIN_READINGS`] valid lidar readings;
/// otherwise as [`fit_ml`].
pub fn calibrate(rec: &Recording, opts: &Options) -> Result<Calibration, CalibrationError> {
    if rec.truth.as_ref().is_none_or(Vec::is_empty) {
        return Err(CalibrationError::Missing(
            "no truth.csv: the ground-truth baseline needs the true pose".into(),
        ));
    }
    let samples = target_samples::extract(rec, &opts.sample_options())?;
    let Some(truth) = samples.truth_m.as_ref() else {
        return Err(CalibrationError::Missing(
            "no start distance: none was given (--start-distance), and meta.toml's [world] \
             target_start_distance_m, when present, is the frontal target's (beam 0°) only; \
             the true distances are measured from it"
                .into(),
        ));
    };
    let pairs = |readings: &[Option<f64>]| -> (Vec<f64>, Vec<f64>) {
        truth
            .iter()
            .zip(readings)
            .filter_map(|(&d, y)| y.map(|y| (d, y)))
            .unzip()
    };
    let (d, y) = pairs(&samples.lidar_m);
    if d.len() < MIN_READINGS {
        return Err(CalibrationError::TooFewSamples(format!(
            "{} valid lidar readings of the target; the baseline needs at least {MIN_READINGS}",
            d.len()
        )));
    }
    let lidar = fit_aic(&d, &y, opts.max_order)?;
    let mut notes = vec![format!(
        "lidar: AIC chose bias order {} with noise sd = β d^{} (AIC {:.1}, {} samples)",
        lidar.order(),
        lidar.noise_power,
        lidar.aic,
        lidar.n
    )];
    let mut sensors = BTreeMap::new();
    sensors.insert(Sensor::Lidar, lidar.model());
    let odometer: Option<Vec<Option<f64>>> = samples.odometer_travel_m.as_ref().map(|_| {
        (0..samples.len())
            .map(|k| samples.odometer_distance(k))
            .collect()
    });
    for (sensor, readings) in [
        (Sensor::Odometer, odometer.as_deref()),
        (Sensor::Sonar, samples.sonar_m.as_deref()),
    ] {
        let Some(readings) = readings else { continue };
        let (d, y) = pairs(readings);
        if d.len() < MIN_READINGS {
            notes.push(format!(
                "{sensor:?}: {} readings, too few to fit (at least {MIN_READINGS})",
                d.len()
            ));
            continue;
        }
        let fit = fit_aic(&d, &y, opts.max_order)?;
        notes.push(format!(
            "{sensor:?}: AIC chose bias order {} with noise sd = β d^{}",
            fit.order(),
            fit.noise_power
        ));
        sensors.insert(sensor, fit.model());
    }
    let calibrated: Vec<Option<f64>> = samples
        .lidar_m
        .iter()
        .map(|y| y.and_then(|y| invert(&lidar.alpha, y)))
        .collect();
    // Its estimates are the lidar model's own: the two figures agree.
    let metrics =
        target_samples::distance_metrics(truth, &samples.lidar_m, &calibrated).map(|m| Metrics {
            lidar_model: target_samples::lidar_model_metrics(truth, &samples.lidar_m, &lidar.alpha),
            ..m
        });
    let mut checks = Vec::new();
    for (sensor, model) in &sensors {
        checks.extend(checks::bias_plausible(sensor.name(), model));
    }
    // The lidar's residuals against the truth, standardised by the fitted noise, in time order.
    let residuals: Vec<f64> = truth
        .iter()
        .zip(&samples.lidar_m)
        .filter_map(|(&d, y)| {
            let y = (*y)?;
            let sd = lidar.beta * d.powi(lidar.noise_power as i32);
            (sd > 0.0).then(|| (y - regression::horner(&lidar.alpha, d)) / sd)
        })
        .collect();
    checks.extend(checks::white(
        "lidar.residuals_white",
        "lidar's standardised residuals against the truth",
        &residuals,
    ));
    Ok(Calibration {
        method: Method::Groundtruth,
        sensors,
        iterations: 1,
        converged: true,
        metrics,
        order: Some(lidar.order()),
        odometry: None,
        landmarks: None,
        checks,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inversion_undoes_the_bias() {
        let alpha = [0.0525, 0.8838, 0.0584];
        for d in [0.3, 1.0, 2.5, 4.0] {
            let y = alpha[0] + alpha[1] * d + alpha[2] * d * d;
            assert!((invert(&alpha, y).unwrap() - d).abs() < 1e-10);
        }
        assert_eq!(
            invert(&[1.0], 2.0),
            None,
            "a constant bias says nothing of d"
        );
    }

    #[test]
    fn exact_linear_data_is_recovered() {
        let d: Vec<f64> = (0..50).map(|k| 0.5 + 0.07 * k as f64).collect();
        let y: Vec<f64> = d
            .iter()
            .enumerate()
            .map(|(k, d)| 0.02 + 1.03 * d + 1e-3 * if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let fit = fit_ml(&d, &y, 1, 0).unwrap();
        assert!((fit.alpha[1] - 1.03).abs() < 1e-3);
        assert!((fit.beta - 1e-3).abs() < 1e-4);
    }
}
