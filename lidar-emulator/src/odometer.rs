//! The wheel encoders: cumulative travel per wheel, over-reported by the wheels' slip, with
//! additive noise (the EM paper's homoscedastic odometer, Sec. II-B) and quantised to ticks.

use hilsim_recording::OdometrySample;
use hilsim_sim::{rng, scenario, StepState};
use rand_distr::{Distribution, StandardNormal};

/// The emulated encoders.
pub struct Odometer {
    scale: f64,
    noise_m: f64,
    tick_m: f64,
    period_s: f64,
    rng: rng::Rng,
    next: u64,
}

impl Odometer {
    /// The odometer of a scenario, drawing from the run's `odometer` stream.
    #[must_use]
    pub fn new(config: &scenario::Odometer, seed: u64) -> Self {
        Self {
            scale: 1.0 + config.slip,
            noise_m: config.noise_m,
            tick_m: config.tick_m,
            period_s: 1.0 / config.rate_hz,
            rng: rng::stream(seed, "odometer"),
            next: 0,
        }
    }

    /// What the encoders report for true cumulative travel `travel_m`.
    fn report(&mut self, travel_m: f64) -> f64 {
        let e: f64 = StandardNormal.sample(&mut self.rng);
        let value = travel_m * self.scale + self.noise_m * e;
        (value / self.tick_m).round() * self.tick_m
    }

    /// Readings whose instant falls in `[step.t0, step.t1)`.
    pub fn observe(&mut self, step: &StepState, out: &mut Vec<OdometrySample>) {
        loop {
            let t = self.next as f64 * self.period_s;
            if t >= step.t1 {
                return;
            }
            self.next += 1;
            if t < step.t0 {
                continue;
            }
            let [left, right] = step.wheels_at(t);
            out.push(OdometrySample {
                t_s: t,
                left_m: self.report(left),
                right_m: self.report(right),
            });
        }
    }
}
