//! What a trial conceals: an effect (or none) and its parameters, drawn from (S, i) alone.

use hilsim_sim::scenario::{self, Effects};
use hilsim_sim::Scenario;
use rand_xoshiro::rand_core::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;

use crate::Effect;

/// The trial's draws, from (S, i) alone: SplitMix64 started from a mix of the two.
pub(crate) struct Draws(SplitMix64);

impl Draws {
    pub(crate) fn new(seed: u64, trial: u64) -> Self {
        Self(SplitMix64::seed_from_u64(
            seed ^ trial.wrapping_mul(0xd1b5_4a32_d192_ed03).rotate_left(17),
        ))
    }
    pub(crate) fn next(&mut self) -> u64 {
        self.0.next_u64()
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn sign(&mut self) -> f64 {
        if self.next() & 1 == 0 {
            1.0
        } else {
            -1.0
        }
    }
}

/// A drawn effect: the scenario tables to switch it on, and the parameter scored (its value).
#[derive(Debug, Clone, PartialEq)]
pub struct Drawn {
    /// The concealed effect (`None`: the nominal scenario).
    pub effect: Option<Effect>,
    /// The scenario's `[effects]` with it switched on.
    pub effects: Effects,
    /// The scored parameter's true value (`None`: nothing to recover).
    pub truth: Option<f64>,
    /// Every parameter drawn, for the report.
    pub params: Vec<(String, f64)>,
}

/// Draws trial `i`'s effect. The moderate ranges (× `strength`):
/// incidence κ ±[0.01, 0.03]; reflectivity c ±[0.008, 0.02] m; mixed pixels half-width
/// [0.5, 1.5]°; motion skew (the head's own period); warm-up k ±[0.004, 0.01] /m with τ in
/// [5, 20] s; sonar cone [8, 20]°; air temperature 20 °C ± [15, 30] °C; slip gain
/// [0.03, 0.1] s; motor lag τ [0.1, 0.4] s.
pub(crate) fn draw(d: &mut Draws, strength: f64, nominal: &Scenario, only: Option<usize>) -> Drawn {
    let drawn_class = (d.unit() * 10.0).floor() as usize;
    // 0: none; 1..=9: the catalogue in order.
    let k = only.unwrap_or(drawn_class);
    let mut effects = nominal.effects.clone();
    let (effect, truth, params) = if (1..=5).contains(&k) {
        draw_lidar(k, d, strength, nominal, &mut effects)
    } else {
        draw_other(k, d, strength, &mut effects)
    };
    Drawn {
        effect,
        effects,
        truth,
        params,
    }
}

/// The concealed effect, its scored parameter's true value and every parameter drawn.
type Concealed = (Option<Effect>, Option<f64>, Vec<(String, f64)>);

/// Draws lidar effect `k` (1..=5, the catalogue's order) into `effects`.
fn draw_lidar(
    k: usize,
    d: &mut Draws,
    s: f64,
    nominal: &Scenario,
    effects: &mut Effects,
) -> Concealed {
    match k {
        1 => {
            let v = d.sign() * d.between(0.01, 0.03) * s;
            effects.lidar_incidence_angle = Some(scenario::LidarIncidenceAngle { coefficient: v });
            (
                Some(Effect::LidarIncidenceAngle),
                Some(v),
                vec![("coefficient".into(), v)],
            )
        }
        2 => {
            let v = d.sign() * d.between(0.008, 0.02) * s;
            effects.lidar_reflectivity = Some(scenario::LidarReflectivity {
                coefficient_m: v,
                reference: 0.8,
            });
            (
                Some(Effect::LidarReflectivity),
                Some(v),
                vec![("coefficient_m".into(), v)],
            )
        }
        3 => {
            let v = (d.between(0.5, 1.5) * s).min(5.0);
            effects.lidar_mixed_pixels = Some(scenario::LidarMixedPixels { half_width_deg: v });
            (
                Some(Effect::LidarMixedPixels),
                Some(v),
                vec![("half_width_deg".into(), v)],
            )
        }
        4 => {
            effects.lidar_motion_skew = Some(scenario::LidarMotionSkew {});
            let rpm = nominal.sensors.lidar.as_ref().map_or(300.0, |l| l.rpm);
            let period = 60.0 / rpm;
            (
                Some(Effect::LidarMotionSkew),
                Some(period),
                vec![("revolution_s".into(), period)],
            )
        }
        5 => {
            let v = d.sign() * d.between(0.004, 0.01) * s;
            let tau = d.between(5.0, 20.0);
            effects.lidar_warmup_drift = Some(scenario::LidarWarmupDrift {
                coefficient_per_m: v,
                time_constant_s: tau,
            });
            (
                Some(Effect::LidarWarmupDrift),
                Some(v),
                vec![
                    ("coefficient_per_m".into(), v),
                    ("time_constant_s".into(), tau),
                ],
            )
        }
        _ => (None, None, Vec::new()),
    }
}

/// Draws effect `k` (6..=9, the catalogue's order; anything else: none) into `effects`.
fn draw_other(k: usize, d: &mut Draws, s: f64, effects: &mut Effects) -> Concealed {
    match k {
        6 => {
            let v = (d.between(8.0, 20.0) * s).min(60.0);
            effects.sonar_beam_width = Some(scenario::SonarBeamWidth { half_angle_deg: v });
            (
                Some(Effect::SonarBeamWidth),
                Some(v),
                vec![("half_angle_deg".into(), v)],
            )
        }
        7 => {
            let dt = d.sign() * d.between(15.0, 30.0) * s;
            let t = (20.0 + dt).clamp(-50.0, 60.0);
            effects.sonar_speed_of_sound = Some(scenario::SonarSpeedOfSound {
                air_temperature_c: t,
                calibrated_at_c: 20.0,
            });
            // Scored: the departure from the calibration temperature.
            (
                Some(Effect::SonarSpeedOfSound),
                Some(t - 20.0),
                vec![("air_temperature_c".into(), t)],
            )
        }
        8 => {
            let v = d.between(0.03, 0.1) * s;
            effects.odometer_wheel_slip = Some(scenario::OdometerWheelSlip { gain_s: v });
            (
                Some(Effect::OdometerWheelSlip),
                Some(v),
                vec![("gain_s".into(), v)],
            )
        }
        9 => {
            let v = (d.between(0.1, 0.4) * s).min(10.0);
            effects.drive_motor_lag = Some(scenario::DriveMotorLag { time_constant_s: v });
            (
                Some(Effect::DriveMotorLag),
                Some(v),
                vec![("time_constant_s".into(), v)],
            )
        }
        _ => (None, None, Vec::new()),
    }
}

/// Trial `i`'s "real" scenario: the nominal one with the drawn effect and its own noise seed.
pub(crate) fn real_scenario(
    nominal: &Scenario,
    seed: u64,
    i: u64,
    strength: f64,
    only: Option<usize>,
) -> (Scenario, Drawn) {
    let mut d = Draws::new(seed, i);
    let drawn = draw(&mut d, strength, nominal, only);
    let mut real = nominal.clone();
    real.effects = drawn.effects.clone();
    real.seed = d.next() >> 1;
    (real, drawn)
}
