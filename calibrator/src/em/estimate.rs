//! The smoothed distance at each sample: what the E-step's smoother pass yields, and what EM
//! and [`crate::smoothing`] return.

use crate::kalman_smoother::RtsSmoother;
use crate::target_samples::TargetSamples;

/// The smoothed distance at one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// The sample instant, seconds.
    pub t_s: f64,
    /// Smoothed distance to the target, metres.
    pub distance_m: f64,
    /// Its posterior variance, m².
    pub variance_m2: f64,
}

impl Estimate {
    /// The posterior standard deviation, metres.
    #[must_use]
    pub fn sd_m(&self) -> f64 {
        self.variance_m2.max(0.0).sqrt()
    }
}

/// The smoothed distance of each sample.
pub(crate) fn estimates(samples: &TargetSamples, smoother: &RtsSmoother<2>) -> Vec<Estimate> {
    samples
        .t_s
        .iter()
        .zip(smoother.smoothed_means())
        .zip(smoother.smoothed_covs())
        .map(|((&t_s, m), p)| Estimate {
            t_s,
            distance_m: m[0],
            variance_m2: p[(0, 0)].max(0.0),
        })
        .collect()
}
