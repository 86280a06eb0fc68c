//! The range model of both papers, eq. (2):
//! `reading = Σ alpha_i d^i + (Σ beta_i d^i) · e`, `e ~ N(0, 1)`, with `d` the true distance in
//! metres. Built once per sensor and shared by every sensor type.
//!
//! Reference: Alhashimi, Varagnolo, Gustafsson, "Calibrating distance sensors for terrestrial
//! applications without groundtruth information", IEEE Sensors J. 2017, eq. (2); Alhashimi et
//! al., Sensors 2021, Sec. 2.

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

/// A polynomial bias with heteroscedastic Gaussian noise.
///
/// ```
/// use hilsim_lidar_emulator::RangeModel;
/// // The landmark paper's XV-11 parameters (Sec. 5): alpha = [0.0525, 0.8838, 0.0584].
/// let model = RangeModel::builder()
///     .bias([0.0525, 0.8838, 0.0584])
///     .noise([0.0, 0.0, 0.0029])
///     .build()?;
/// assert!((model.mean(1.0) - 0.9947).abs() < 1e-12);
/// assert!((model.std_dev(2.0) - 0.0116).abs() < 1e-12);
/// # Ok::<(), hilsim_lidar_emulator::ModelError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct RangeModel {
    bias: Vec<f64>,
    noise: Vec<f64>,
}

/// A range model that makes no sense.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// No bias coefficients: the reading would not depend on the distance.
    #[error("the bias polynomial needs at least one coefficient")]
    EmptyBias,
    /// A coefficient is NaN or infinite.
    #[error("{which} coefficient {index} is not finite ({value})")]
    NotFinite {
        /// `bias` or `noise`.
        which: &'static str,
        /// Which coefficient.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A noise coefficient is negative, so the standard deviation could go negative.
    #[error("noise coefficient {index} is negative ({value}): a standard deviation cannot be")]
    NegativeNoise {
        /// Which coefficient.
        index: usize,
        /// Its value.
        value: f64,
    },
}

/// Builds a [`RangeModel`]; `build` rejects nonsense.
#[derive(Debug, Clone, Default)]
#[must_use]
pub struct RangeModelBuilder {
    bias: Vec<f64>,
    noise: Vec<f64>,
}

impl RangeModel {
    /// A builder with no bias and no noise; set at least the bias.
    pub fn builder() -> RangeModelBuilder {
        RangeModelBuilder::default()
    }

    /// The ideal sensor: reading = d.
    #[must_use]
    pub fn ideal() -> Self {
        Self {
            bias: vec![0.0, 1.0],
            noise: vec![],
        }
    }

    /// alpha_0.., lowest order first.
    #[must_use]
    pub fn bias(&self) -> &[f64] {
        &self.bias
    }

    /// beta_0.., lowest order first.
    #[must_use]
    pub fn noise(&self) -> &[f64] {
        &self.noise
    }

    /// The expected reading at true distance `d`: Σ alpha_i d^i.
    #[must_use]
    pub fn mean(&self, d: f64) -> f64 {
        horner(&self.bias, d)
    }

    /// The noise standard deviation at `d`: Σ beta_i d^i (non-negative for d ≥ 0).
    #[must_use]
    pub fn std_dev(&self, d: f64) -> f64 {
        horner(&self.noise, d).max(0.0)
    }

    /// One reading at true distance `d`.
    pub fn sample<R: Rng + ?Sized>(&self, d: f64, rng: &mut R) -> f64 {
        let e: f64 = StandardNormal.sample(rng);
        self.mean(d) + self.std_dev(d) * e
    }
}

impl RangeModelBuilder {
    /// alpha_0.. of eq. (2), metres, lowest order first.
    pub fn bias(mut self, alpha: impl AsRef<[f64]>) -> Self {
        self.bias = alpha.as_ref().to_vec();
        self
    }

    /// beta_0.. of eq. (2), lowest order first.
    pub fn noise(mut self, beta: impl AsRef<[f64]>) -> Self {
        self.noise = beta.as_ref().to_vec();
        self
    }

    /// The model.
    ///
    /// # Errors
    /// An empty bias, a non-finite coefficient, or a negative noise coefficient.
    pub fn build(self) -> Result<RangeModel, ModelError> {
        if self.bias.is_empty() {
            return Err(ModelError::EmptyBias);
        }
        for (which, coeffs) in [("bias", &self.bias), ("noise", &self.noise)] {
            if let Some((index, &value)) = coeffs.iter().enumerate().find(|(_, c)| !c.is_finite()) {
                return Err(ModelError::NotFinite {
                    which,
                    index,
                    value,
                });
            }
        }
        if let Some((index, &value)) = self.noise.iter().enumerate().find(|(_, c)| **c < 0.0) {
            return Err(ModelError::NegativeNoise { index, value });
        }
        Ok(RangeModel {
            bias: self.bias,
            noise: self.noise,
        })
    }
}

/// Σ c_i x^i by Horner's rule.
fn horner(coeffs: &[f64], x: f64) -> f64 {
    coeffs.iter().rev().fold(0.0, |acc, c| acc * x + c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builder_rejects_nonsense() {
        assert_eq!(RangeModel::builder().build(), Err(ModelError::EmptyBias));
        assert!(matches!(
            RangeModel::builder().bias([0.0, f64::NAN]).build(),
            Err(ModelError::NotFinite {
                which: "bias",
                index: 1,
                ..
            })
        ));
        assert!(matches!(
            RangeModel::builder()
                .bias([0.0, 1.0])
                .noise([0.01, -0.001])
                .build(),
            Err(ModelError::NegativeNoise { index: 1, .. })
        ));
    }

    #[test]
    fn horner_evaluates_lowest_order_first() {
        assert_eq!(horner(&[1.0, 2.0, 3.0], 2.0), 1.0 + 4.0 + 12.0);
        assert_eq!(horner(&[], 2.0), 0.0);
    }
}
