//! The gap between the wheel speeds commanded and those achieved: a fixed scale error per run
//! plus an Ornstein–Uhlenbeck wander, both from the run's `actuation` random stream.

use rand_distr::{Distribution, StandardNormal};

use crate::rng;
use crate::scenario::Actuation;

/// The speed-scale error process of one run.
pub(crate) struct ActuationError {
    fixed: f64,
    wander: f64,
    wander_sd: f64,
    tau_s: f64,
    rng: rng::Rng,
}

impl ActuationError {
    pub(crate) fn new(config: &Actuation, seed: u64) -> Self {
        let mut rng = rng::stream(seed, "actuation");
        let fixed_e: f64 = StandardNormal.sample(&mut rng);
        let wander_e: f64 = StandardNormal.sample(&mut rng);
        Self {
            fixed: config.scale_sd * fixed_e,
            // Start in the stationary distribution, so the run has no transient.
            wander: config.wander_sd * wander_e,
            wander_sd: config.wander_sd,
            tau_s: config.wander_tau_s,
            rng,
        }
    }

    /// The factor the commanded speeds are multiplied by during the next `dt_s`, then advances
    /// the wander by the exact discretisation of the OU process:
    /// `w' = a w + sd √(1 − a²) e`, `a = exp(−dt/τ)`.
    pub(crate) fn next_factor(&mut self, dt_s: f64) -> f64 {
        let factor = 1.0 + self.fixed + self.wander;
        if self.wander_sd > 0.0 {
            let a = (-dt_s / self.tau_s).exp();
            let e: f64 = StandardNormal.sample(&mut self.rng);
            self.wander = a * self.wander + self.wander_sd * (1.0 - a * a).sqrt() * e;
        }
        factor
    }
}
