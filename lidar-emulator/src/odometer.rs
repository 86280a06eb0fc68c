//! The wheel encoders: cumulative travel per wheel, over-reported by the wheels' slip, with
//! additive noise (the EM paper's homoscedastic odometer, Sec. II-B) and quantised to ticks.

use hilsim_recording::OdometrySample;
use hilsim_sim::{rng, scenario, StepState};

use crate::effects::{braking_change_mps, slip_travel_m};
use rand_distr::{Distribution, StandardNormal};

/// The emulated encoders.
pub struct Odometer {
    scale: f64,
    noise_m: f64,
    tick_m: f64,
    period_s: f64,
    rng: rng::Rng,
    next: u64,
    /// `[effects.odometer_wheel_slip]`.
    slip: Option<scenario::OdometerWheelSlip>,
    /// Each wheel's speed over the last physics step, m/s.
    wheel_speeds_mps: [f64; 2],
    /// Each wheel's changes of speed while braking, summed since the start, m/s.
    braking_mps: [f64; 2],
    /// `[effects.odometer_wheel_radius]`: each wheel's radius over nominal (1 when off). The
    /// encoders count turns and multiply by the nominal radius: they report travel / scale.
    radius_scale: [f64; 2],
    /// `[effects.sensor_latency]`: how late each reading is stamped, seconds (0 when off).
    latency_s: f64,
}

impl Odometer {
    /// The odometer of a scenario, drawing from the run's `odometer` stream.
    #[must_use]
    pub fn new(config: &scenario::Odometer, seed: u64) -> Self {
        Self::with_effects(config, &scenario::Effects::default(), seed)
    }

    /// The odometer of a scenario with `[effects.odometer_wheel_slip]` when switched on: each
    /// wheel's encoder leads its true travel by `gain_s · v`, v the wheel's speed during the
    /// physics step, and by `(braking_gain_s − gain_s)` times its changes of speed while braking
    /// besides (see `effects`).
    #[must_use]
    pub fn with_effects(
        config: &scenario::Odometer,
        effects: &scenario::Effects,
        seed: u64,
    ) -> Self {
        Self {
            scale: 1.0 + config.slip,
            noise_m: config.noise_m,
            tick_m: config.tick_m,
            period_s: 1.0 / config.rate_hz,
            rng: rng::stream(seed, "odometer"),
            next: 0,
            slip: effects.odometer_wheel_slip,
            wheel_speeds_mps: [0.0; 2],
            braking_mps: [0.0; 2],
            radius_scale: effects
                .odometer_wheel_radius
                .map_or([1.0, 1.0], |r| [r.left_scale, r.right_scale]),
            latency_s: effects.sensor_latency.map_or(0.0, |l| l.odometer_s),
        }
    }

    /// What the encoders report for true cumulative travel `travel_m`.
    fn report(&mut self, travel_m: f64) -> f64 {
        let e: f64 = StandardNormal.sample(&mut self.rng);
        let value = travel_m * self.scale + self.noise_m * e;
        let ticks = (value / self.tick_m).round();
        // Whole ticks per metre (1000 for the Neato's millimetres): dividing gives the exact
        // decimal (`0.018`, not `0.018000000000000002` as multiplying by 0.001 does).
        let per_m = (1.0 / self.tick_m).round();
        if (per_m * self.tick_m - 1.0).abs() < 1e-12 {
            ticks / per_m
        } else {
            ticks * self.tick_m
        }
    }

    /// Readings whose instant falls in `[step.t0, step.t1)`; called once for every physics step.
    pub fn observe(&mut self, step: &StepState, out: &mut Vec<OdometrySample>) {
        // The wheels' speeds during this step, from their true travel.
        let dt = step.t1 - step.t0;
        if self.slip.is_some() && dt > 0.0 {
            for w in 0..2 {
                let speed = (step.wheels1[w] - step.wheels0[w]) / dt;
                self.braking_mps[w] += braking_change_mps(self.wheel_speeds_mps[w], speed);
                self.wheel_speeds_mps[w] = speed;
            }
        }
        loop {
            let t = self.next as f64 * self.period_s;
            if t >= step.t1 {
                return;
            }
            self.next += 1;
            if t < step.t0 {
                continue;
            }
            let [mut left, mut right] = step.wheels_at(t);
            if let Some(slip) = &self.slip {
                let [v, braking] = [self.wheel_speeds_mps, self.braking_mps];
                left += slip_travel_m(slip, v[0], braking[0]);
                right += slip_travel_m(slip, v[1], braking[1]);
            }
            let [left_scale, right_scale] = self.radius_scale;
            out.push(OdometrySample {
                t_s: crate::effects::stamped_s(t, self.latency_s),
                left_m: self.report(left / left_scale),
                right_m: self.report(right / right_scale),
            });
        }
    }
}
