//! A Kalman filter and Rauch–Tung–Striebel smoother for linear-Gaussian state-space models with
//! time-varying dynamics and scalar, possibly missing, observations; it also returns the lag-one
//! smoothed covariances the EM M-step needs.
//!
//! The model, for steps `k = 0..n`:
//!
//! ```text
//! x_0        ~ N(m_0, P_0)                              (the prior of the first step)
//! x_{k+1}    = A_k x_k + b_k + w_k,    w_k ~ N(0, Q_k)
//! y_{k,i}    = c_{k,i} + h_{k,i}ᵀ x_k + v_{k,i},   v_{k,i} ~ N(0, r_{k,i})   (i = 0.. per step)
//! ```
//!
//! Each step may carry any number of scalar observations (none, when every sensor missed); they
//! are independent given the state (diagonal `R_k`), so the measurement update processes them
//! one at a time, which is exact and needs no matrix inverse.
//!
//! The state dimension is a const generic: the EM calibrator runs it on `D = 2` (the stochastic
//! part `[d, d²]` of the paper's redundant state `[1, d, d²]`; see `docs/em-calibration.md`),
//! with fixed-size nalgebra types and no allocation per step once the workspace has grown.
//!
//! # Reference
//! Rauch, Tung, Striebel, "Maximum likelihood estimates of linear dynamic systems", AIAA J. 1965;
//! Shumway, Stoffer, "An approach to time series smoothing and forecasting using the EM
//! algorithm", J. Time Series Anal. 1982 (the lag-one covariance); Särkkä, "Bayesian Filtering
//! and Smoothing", 2013, Thm. 8.2 and eq. (12.5) (the lag-one covariance as `P_{k+1|n} J_kᵀ`).
//!
//! ```
//! use hilsim_calibrator::kalman_smoother::{
//!     Gaussian, Observation, Observations, RtsSmoother, StateSpaceModel, Transition,
//! };
//! use nalgebra::{Matrix1, Vector1};
//!
//! /// A random walk seen directly, with the middle observation missing.
//! struct Walk;
//! impl StateSpaceModel<1> for Walk {
//!     fn steps(&self) -> usize { 3 }
//!     fn prior(&self) -> Gaussian<1> { Gaussian::new(Vector1::new(0.0), Matrix1::new(1.0)) }
//!     fn transition(&self, _k: usize) -> Transition<1> {
//!         Transition { a: Matrix1::new(1.0), b: Vector1::new(0.0), q: Matrix1::new(0.1) }
//!     }
//!     fn observations(&self, k: usize, out: &mut Observations<1>) {
//!         if k != 1 {
//!             out.push(Observation { y: 1.0, offset: 0.0, h: Vector1::new(1.0), r: 0.5 });
//!         }
//!     }
//! }
//! let mut smoother = RtsSmoother::new();
//! let log_likelihood = smoother.run(&Walk)?;
//! assert!(log_likelihood.is_finite());
//! // The missing middle step is pulled towards its observed neighbours.
//! assert!(smoother.smoothed_means()[1][0] > 0.5);
//! # Ok::<(), hilsim_calibrator::kalman_smoother::SmootherError>(())
//! ```

use nalgebra::{SMatrix, SVector};

/// `ln(2π)`, for the Gaussian log-density.
const LN_2PI: f64 = 1.837_877_066_409_345_5;

/// At most this many scalar observations per step (the EM calibrator uses three: lidar,
/// odometer, sonar).
pub const MAX_OBSERVATIONS: usize = 8;

/// A Gaussian: mean and covariance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gaussian<const D: usize> {
    /// Mean.
    pub mean: SVector<f64, D>,
    /// Covariance (symmetric, positive semi-definite).
    pub cov: SMatrix<f64, D, D>,
}

impl<const D: usize> Gaussian<D> {
    /// A Gaussian from its mean and covariance.
    #[must_use]
    pub fn new(mean: SVector<f64, D>, cov: SMatrix<f64, D, D>) -> Self {
        Self { mean, cov }
    }
}

/// The dynamics from step `k` to step `k + 1`: `x_{k+1} = a x_k + b + w`, `w ~ N(0, q)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition<const D: usize> {
    /// State transition matrix `A_k`.
    pub a: SMatrix<f64, D, D>,
    /// Known input term `B_k u_k` (the paper folds `u_k` into `B_k`).
    pub b: SVector<f64, D>,
    /// Process-noise covariance `Q_k`.
    pub q: SMatrix<f64, D, D>,
}

/// One scalar observation: `y = offset + hᵀ x + v`, `v ~ N(0, r)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation<const D: usize> {
    /// The observed value.
    pub y: f64,
    /// Known offset (the constant column of the paper's `C` acting on the state's leading 1).
    pub offset: f64,
    /// Observation row.
    pub h: SVector<f64, D>,
    /// Noise variance; must be positive unless `hᵀ P h` is.
    pub r: f64,
}

/// The observations of one step: a fixed-capacity list, so that filling it never allocates.
#[derive(Debug, Clone, Copy)]
pub struct Observations<const D: usize> {
    items: [Observation<D>; MAX_OBSERVATIONS],
    len: usize,
}

impl<const D: usize> Observations<D> {
    fn new() -> Self {
        Self {
            items: [Observation {
                y: 0.0,
                offset: 0.0,
                h: SVector::zeros(),
                r: 1.0,
            }; MAX_OBSERVATIONS],
            len: 0,
        }
    }

    /// Adds an observation.
    ///
    /// # Panics
    /// When more than [`MAX_OBSERVATIONS`] are pushed in one step (a programming error).
    pub fn push(&mut self, obs: Observation<D>) {
        assert!(
            self.len < MAX_OBSERVATIONS,
            "too many observations in a step"
        );
        self.items[self.len] = obs;
        self.len += 1;
    }

    /// The observations pushed so far.
    #[must_use]
    pub fn as_slice(&self) -> &[Observation<D>] {
        &self.items[..self.len]
    }
}

/// A linear-Gaussian state-space model as the smoother sees it, step by step.
pub trait StateSpaceModel<const D: usize> {
    /// Number of steps `n` (states `x_0 .. x_{n-1}`).
    fn steps(&self) -> usize;
    /// The distribution of the first state before its observations.
    fn prior(&self) -> Gaussian<D>;
    /// The dynamics from step `k` to `k + 1`, for `k` in `0..n-1`.
    fn transition(&self, k: usize) -> Transition<D>;
    /// Pushes the observations of step `k` (possibly none) into `out`, which arrives empty.
    fn observations(&self, k: usize, out: &mut Observations<D>);
}

/// Why a filter or smoother pass failed. Either means the model's parameters are unusable
/// (e.g. a negative or zero noise variance), never that the data are.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SmootherError {
    /// The model has no steps.
    #[error("the model has no steps")]
    Empty,
    /// An innovation variance `hᵀ P h + r` was not positive and finite.
    #[error("innovation variance {value:e} at step {step} is not positive and finite")]
    Innovation {
        /// The step.
        step: usize,
        /// The offending variance.
        value: f64,
    },
    /// A predicted covariance could not be inverted for the smoother gain.
    #[error("predicted covariance at step {step} is singular")]
    Singular {
        /// The step.
        step: usize,
    },
    /// A mean or covariance became NaN or infinite, or a variance negative.
    #[error("non-finite or negative-variance state at step {step}")]
    NonFinite {
        /// The step.
        step: usize,
    },
}

/// The filter and smoother with their workspace. Reuse one across EM iterations: after the
/// first run of a given length nothing is allocated.
#[derive(Debug, Clone, Default)]
pub struct RtsSmoother<const D: usize> {
    filtered_mean: Vec<SVector<f64, D>>,
    filtered_cov: Vec<SMatrix<f64, D, D>>,
    /// `x_{k+1|k}` stored at index `k + 1`; index 0 holds the prior.
    predicted_mean: Vec<SVector<f64, D>>,
    predicted_cov: Vec<SMatrix<f64, D, D>>,
    /// `A_k` of the transition from `k` to `k + 1`, at index `k`.
    transitions: Vec<SMatrix<f64, D, D>>,
    smoothed_mean: Vec<SVector<f64, D>>,
    smoothed_cov: Vec<SMatrix<f64, D, D>>,
    /// `Cov(x_{k+1}, x_k | all data)` at index `k`.
    lag_one_cov: Vec<SMatrix<f64, D, D>>,
}

impl<const D: usize> RtsSmoother<D> {
    /// An empty workspace.
    #[must_use]
    pub fn new() -> Self {
        Self {
            filtered_mean: Vec::new(),
            filtered_cov: Vec::new(),
            predicted_mean: Vec::new(),
            predicted_cov: Vec::new(),
            transitions: Vec::new(),
            smoothed_mean: Vec::new(),
            smoothed_cov: Vec::new(),
            lag_one_cov: Vec::new(),
        }
    }

    fn resize(&mut self, n: usize) {
        let zv = SVector::<f64, D>::zeros();
        let zm = SMatrix::<f64, D, D>::zeros();
        self.filtered_mean.resize(n, zv);
        self.filtered_cov.resize(n, zm);
        self.predicted_mean.resize(n, zv);
        self.predicted_cov.resize(n, zm);
        self.transitions.resize(n, zm);
        self.smoothed_mean.resize(n, zv);
        self.smoothed_cov.resize(n, zm);
        self.lag_one_cov.resize(n, zm);
    }

    /// Runs the forward filter and the backward smoother over `model`; returns the
    /// log-likelihood of all observations, `log p(y_0 .. y_{n-1})`, from the innovations.
    ///
    /// # Errors
    /// A [`SmootherError`] when the model is empty or its noise makes a variance non-positive.
    pub fn run<M: StateSpaceModel<D>>(&mut self, model: &M) -> Result<f64, SmootherError> {
        let log_likelihood = self.filter(model)?;
        self.smooth()?;
        Ok(log_likelihood)
    }

    /// Runs the forward (Kalman) filter only; returns the log-likelihood.
    ///
    /// # Errors
    /// As [`RtsSmoother::run`].
    pub fn filter<M: StateSpaceModel<D>>(&mut self, model: &M) -> Result<f64, SmootherError> {
        let n = model.steps();
        if n == 0 {
            return Err(SmootherError::Empty);
        }
        self.resize(n);
        let prior = model.prior();
        let mut mean = prior.mean;
        let mut cov = prior.cov;
        let mut log_likelihood = 0.0;
        // Σ ln s accumulated as a running product, taking the logarithm only when the product
        // nears the ends of f64's range: `ln` per update was a seventh of the filter's time.
        let mut s_product = 1.0_f64;
        let mut observed = 0usize;
        let mut obs = Observations::new();
        for k in 0..n {
            self.predicted_mean[k] = mean;
            self.predicted_cov[k] = cov;
            obs.len = 0;
            model.observations(k, &mut obs);
            for o in obs.as_slice() {
                // Sequential scalar update (Joseph-free: the symmetric form below keeps P
                // symmetric, and the variance check catches any loss of definiteness).
                let ph = cov * o.h;
                let s = o.h.dot(&ph) + o.r;
                if !(s > 0.0 && s.is_finite()) {
                    return Err(SmootherError::Innovation { step: k, value: s });
                }
                let innovation = o.y - o.offset - o.h.dot(&mean);
                let gain = ph / s;
                mean += gain * innovation;
                cov -= gain * ph.transpose();
                cov = (cov + cov.transpose()) * 0.5;
                log_likelihood -= 0.5 * innovation * innovation / s;
                s_product *= s;
                if !(1e-150..=1e150).contains(&s_product) {
                    log_likelihood -= 0.5 * s_product.ln();
                    s_product = 1.0;
                }
                observed += 1;
            }
            check(&cov, k)?;
            self.filtered_mean[k] = mean;
            self.filtered_cov[k] = cov;
            if k + 1 < n {
                let t = model.transition(k);
                self.transitions[k] = t.a;
                mean = t.a * mean + t.b;
                cov = t.a * cov * t.a.transpose() + t.q;
                cov = (cov + cov.transpose()) * 0.5;
            }
        }
        log_likelihood -= 0.5 * (s_product.ln() + observed as f64 * LN_2PI);
        // NaN propagates: a non-finite state anywhere reaches the last one or the likelihood.
        if !(log_likelihood.is_finite() && all_finite(&mean, &cov)) {
            return Err(SmootherError::NonFinite { step: n - 1 });
        }
        Ok(log_likelihood)
    }

    /// The backward (RTS) pass over the last [`RtsSmoother::filter`] run.
    fn smooth(&mut self) -> Result<(), SmootherError> {
        let n = self.filtered_mean.len();
        self.smoothed_mean[n - 1] = self.filtered_mean[n - 1];
        self.smoothed_cov[n - 1] = self.filtered_cov[n - 1];
        self.lag_one_cov[n - 1] = SMatrix::zeros();
        for k in (0..n - 1).rev() {
            let a = self.transitions[k];
            let p_pred = self.predicted_cov[k + 1];
            let Some(p_pred_inv) = p_pred.try_inverse() else {
                return Err(SmootherError::Singular { step: k + 1 });
            };
            // J_k = P_{k|k} A_kᵀ P_{k+1|k}⁻¹ (the smoother gain).
            let j = self.filtered_cov[k] * a.transpose() * p_pred_inv;
            let next_mean = self.smoothed_mean[k + 1];
            let next_cov = self.smoothed_cov[k + 1];
            let mean = self.filtered_mean[k] + j * (next_mean - self.predicted_mean[k + 1]);
            let mut cov = self.filtered_cov[k] + j * (next_cov - p_pred) * j.transpose();
            cov = (cov + cov.transpose()) * 0.5;
            check(&cov, k)?;
            self.smoothed_mean[k] = mean;
            self.smoothed_cov[k] = cov;
            // Cov(x_{k+1}, x_k | Y) = P_{k+1|n} J_kᵀ: equal to Shumway–Stoffer's recursion for
            // P_{k+1,k|n} (Särkkä 2013, eq. 12.5), without its extra matrix products.
            self.lag_one_cov[k] = next_cov * j.transpose();
        }
        if !all_finite(&self.smoothed_mean[0], &self.smoothed_cov[0]) {
            return Err(SmootherError::NonFinite { step: 0 });
        }
        Ok(())
    }

    /// Filtered means `x_{k|k}`.
    #[must_use]
    pub fn filtered_means(&self) -> &[SVector<f64, D>] {
        &self.filtered_mean
    }

    /// Filtered covariances `P_{k|k}`.
    #[must_use]
    pub fn filtered_covs(&self) -> &[SMatrix<f64, D, D>] {
        &self.filtered_cov
    }

    /// Predicted means `x_{k|k-1}` (index 0: the prior).
    #[must_use]
    pub fn predicted_means(&self) -> &[SVector<f64, D>] {
        &self.predicted_mean
    }

    /// Predicted covariances `P_{k|k-1}` (index 0: the prior).
    #[must_use]
    pub fn predicted_covs(&self) -> &[SMatrix<f64, D, D>] {
        &self.predicted_cov
    }

    /// Smoothed means `x_{k|n}`.
    #[must_use]
    pub fn smoothed_means(&self) -> &[SVector<f64, D>] {
        &self.smoothed_mean
    }

    /// Smoothed covariances `P_{k|n}`.
    #[must_use]
    pub fn smoothed_covs(&self) -> &[SMatrix<f64, D, D>] {
        &self.smoothed_cov
    }

    /// Lag-one smoothed covariances `Cov(x_{k+1}, x_k | y_0..y_{n-1})` at index `k`
    /// (the last entry is zero).
    #[must_use]
    pub fn lag_one_covs(&self) -> &[SMatrix<f64, D, D>] {
        &self.lag_one_cov
    }
}

/// Fails on a clearly negative variance (NaN fails too). A variance may dip below zero by
/// rounding when it is (near) zero, e.g. under the paper's exactly known start (`Σ_d = 0`), so
/// the test has a slack of 1e-12 of the variance scale of a metre-sized state. Non-finite
/// values elsewhere are caught once per pass: NaN propagates to the last state.
fn check<const D: usize>(cov: &SMatrix<f64, D, D>, step: usize) -> Result<(), SmootherError> {
    for i in 0..D {
        if cov[(i, i)].is_nan() || cov[(i, i)] < -1e-12 {
            return Err(SmootherError::NonFinite { step });
        }
    }
    Ok(())
}

fn all_finite<const D: usize>(mean: &SVector<f64, D>, cov: &SMatrix<f64, D, D>) -> bool {
    mean.iter().chain(cov.iter()).all(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix1, Vector1};

    struct Scalar {
        ys: Vec<Option<f64>>,
    }

    impl StateSpaceModel<1> for Scalar {
        fn steps(&self) -> usize {
            self.ys.len()
        }
        fn prior(&self) -> Gaussian<1> {
            Gaussian::new(Vector1::new(0.0), Matrix1::new(4.0))
        }
        fn transition(&self, _k: usize) -> Transition<1> {
            Transition {
                a: Matrix1::new(1.0),
                b: Vector1::new(0.0),
                q: Matrix1::new(0.0),
            }
        }
        fn observations(&self, k: usize, out: &mut Observations<1>) {
            if let Some(y) = self.ys[k] {
                out.push(Observation {
                    y,
                    offset: 0.0,
                    h: Vector1::new(1.0),
                    r: 1.0,
                });
            }
        }
    }

    #[test]
    fn constant_state_smooths_to_the_posterior_of_all_data() {
        // With Q = 0 every smoothed state is the posterior of one constant given all data:
        // precision 1/4 + 3, mean (Σ y) / precision.
        let model = Scalar {
            ys: vec![Some(1.0), None, Some(2.0), Some(3.0)],
        };
        let mut s = RtsSmoother::new();
        s.filter(&model).unwrap();
        // Q = 0 makes P_{k+1|k} = P_{k|k} regular here (prior variance 4 > 0).
        s.smooth().unwrap();
        let precision = 0.25 + 3.0;
        for k in 0..4 {
            assert!((s.smoothed_means()[k][0] - 6.0 / precision).abs() < 1e-12);
            assert!((s.smoothed_covs()[k][(0, 0)] - 1.0 / precision).abs() < 1e-12);
        }
    }

    #[test]
    fn bad_noise_is_an_error_not_a_nan() {
        struct Bad;
        impl StateSpaceModel<1> for Bad {
            fn steps(&self) -> usize {
                2
            }
            fn prior(&self) -> Gaussian<1> {
                Gaussian::new(Vector1::new(0.0), Matrix1::new(0.0))
            }
            fn transition(&self, _k: usize) -> Transition<1> {
                Transition {
                    a: Matrix1::new(1.0),
                    b: Vector1::new(0.0),
                    q: Matrix1::new(0.0),
                }
            }
            fn observations(&self, _k: usize, out: &mut Observations<1>) {
                out.push(Observation {
                    y: 1.0,
                    offset: 0.0,
                    h: Vector1::new(1.0),
                    r: -1.0,
                });
            }
        }
        let err = RtsSmoother::new().run(&Bad).unwrap_err();
        assert!(matches!(err, SmootherError::Innovation { step: 0, .. }));
    }
}
