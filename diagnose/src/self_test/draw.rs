//! What a trial conceals: an effect (or none) and its parameters, drawn from (S, i) alone.

use hilsim_lidar_emulator::effects::speed_of_sound_mps;
use hilsim_sim::scenario::Effects;
use hilsim_sim::Scenario;
use rand_xoshiro::rand_core::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;

use hilsim_reality::form::{
    Blend, Curve, DriveResponse, EchoPick, IncidenceGrowth, LossBy, ReflectivityWalk, Settling,
    Traction, RANGE_CURVE_SPAN_M,
};
use hilsim_reality::{Concealed, Nuisances, Stream};

use crate::catalogue::{range_bias, DrawSource, SelfTestRange, Sensor, REFERENCE_REFLECTIVITY};
use crate::Effect;

/// The trial's draws, from (S, i) alone: SplitMix64 started from a mix of the two.
pub(crate) struct Draws(SplitMix64);

impl Draws {
    pub(crate) fn new(seed: u64, trial: u64) -> Self {
        Self(SplitMix64::seed_from_u64(
            seed ^ trial.wrapping_mul(0xd1b5_4a32_d192_ed03).rotate_left(17),
        ))
    }
    /// A stream started from `seed` alone: a concealment's own draws, made again from its
    /// parameters.
    pub(crate) fn from_seed(seed: u64) -> Self {
        Self(SplitMix64::seed_from_u64(seed))
    }
    pub(crate) fn next(&mut self) -> u64 {
        self.0.next_u64()
    }
    /// Uniform in [0, 1).
    pub(super) fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub(super) fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    pub(super) fn sign(&mut self) -> f64 {
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
    /// A second concealed catalogued effect and its scored parameter's true value (the
    /// independent reality only).
    pub second: Option<(Effect, f64)>,
    /// A concealed effect outside the catalogue (the independent reality only).
    pub outside: bool,
    /// Every effect concealed, as the independent reality takes it.
    pub concealed: Vec<Concealed>,
    /// Each concealed catalogued effect's form, where the varied reality drew one.
    pub forms: Vec<String>,
    /// Draws of the trial discarded before this one: their robot would have passed through an
    /// obstacle (the independent reality only).
    pub redrawn: usize,
}

impl Drawn {
    /// The concealed catalogued effects with their scored parameters' true values.
    #[must_use]
    pub fn catalogued(&self) -> Vec<(Effect, f64)> {
        self.effect
            .zip(self.truth)
            .into_iter()
            .chain(self.second)
            .collect()
    }

    /// What was concealed, in words.
    #[must_use]
    pub fn label(&self) -> String {
        let mut names: Vec<&str> = self.catalogued().iter().map(|(e, _)| e.name()).collect();
        if self.outside {
            names.push(OUTSIDE);
        }
        if names.is_empty() {
            "none".to_string()
        } else {
            names.join("+")
        }
    }
}

/// The name of the outside-the-catalogue effect the independent reality conceals.
pub const OUTSIDE: &str = "lidar_periodic_range";

/// Share of the independent reality's trials that conceal two catalogued effects.
const TWO_EFFECTS: f64 = 0.2;

/// The catalogue effect `effect` with `values` as the independent reality takes it.
pub(crate) fn concealed(effect: Effect, values: &[f64]) -> Concealed {
    let p = |i: usize| values.get(i).copied().unwrap_or(0.0);
    match effect {
        Effect::LidarIncidenceAngle => Concealed::LidarIncidence {
            coefficient: p(0),
            collimated_m: p(1),
            growth: IncidenceGrowth::Tangent,
        },
        Effect::LidarReflectivity => Concealed::LidarReflectivity {
            coefficient_m: p(0),
            reference: REFERENCE_REFLECTIVITY,
            walk: ReflectivityWalk::Inverse,
        },
        Effect::LidarMixedPixels => Concealed::LidarMixedPixels {
            half_width_deg: p(0),
            blend: Blend::TopHatHarmonic,
        },
        Effect::LidarMotionSkew => Concealed::LidarMotionSkew,
        Effect::LidarWarmupDrift => Concealed::LidarWarmup {
            coefficient_per_m: p(0),
            time_constant_s: p(1),
            offset_m: p(2),
            settling: Settling::Exponential,
        },
        Effect::SonarBeamWidth => Concealed::SonarBeamWidth {
            half_angle_deg: p(0),
            pick: EchoPick::Nearest,
        },
        Effect::SonarSpeedOfSound => Concealed::SonarSpeedOfSound {
            air_temperature_c: p(0),
            calibrated_at_c: 20.0,
        },
        Effect::OdometerWheelSlip => Concealed::WheelSlip {
            gain_s: p(0),
            braking_share: p(1),
            traction: Traction::Linear,
        },
        Effect::DriveMotorLag => Concealed::MotorLag {
            time_constant_s: p(0),
            response: DriveResponse::FirstOrder,
        },
        Effect::LidarMountOffset => Concealed::LidarMountOffset {
            yaw_deg: p(0),
            x_m: p(1),
            y_m: p(2),
        },
        Effect::SensorLatency(sensor) => Concealed::SensorLatency {
            sensor: match sensor {
                Sensor::Lidar => hilsim_reality::Stamped::Lidar,
                Sensor::Sonar => hilsim_reality::Stamped::Sonar,
                Sensor::Odometer | Sensor::Drive => hilsim_reality::Stamped::Odometer,
            },
            delay_s: p(0),
        },
        Effect::OdometerWheelRadius => Concealed::WheelRadius {
            left_scale: p(0),
            right_scale: p(1),
        },
        Effect::DriveWheelBase => Concealed::WheelBase { scale: p(0) },
        // The triangulation geometry whose reading's first orders in d are `c + s d + q d²`:
        // `d / r` is `(1 + s) d` for `r = 1 / (1 + s)`, and `d / (r + d p)` adds `−p d² / r²`.
        // The echo detected late by the round trip of the offset at 20 °C's speed of sound.
        Effect::SonarRangeBias => Concealed::SonarEchoDelay {
            delay_s: 2.0 * p(0) / speed_of_sound_mps(20.0),
            calibrated_at_c: 20.0,
        },
        // The same loss written as a power threshold: a logistic of scale s in the log power
        // has the standard deviation `s π / √3`, given here to a log-normal scatter.
        Effect::LidarDropout => Concealed::LidarWeakReturns {
            half_loss_range_m: p(0),
            log_power_sd: p(1) * std::f64::consts::PI / 3f64.sqrt(),
            reference: REFERENCE_REFLECTIVITY,
            loss: LossBy::Power,
        },
        Effect::LidarRangeBias => {
            let [c, s, q] = range_bias(values).coefficients();
            let ratio = 1.0 / (1.0 + s).max(0.1);
            Concealed::LidarTriangulation {
                origin_m: c,
                baseline_ratio: ratio,
                pointing_per_m: -q * ratio * ratio,
            }
        }
    }
}

/// `c`, a catalogued mechanism in the catalogue's form, in a form the catalogue does not write
/// (the varied reality), with the form's name. Where a mechanism has a variable to shape, on a
/// fair coin a random smooth monotone curve of it ([`Curve::random`]), else one of the
/// physical forms of [`hilsim_reality::form`] other than the catalogue's. A mechanism with no
/// shape to vary (a mount, a delay, a scale, the speed of sound's, a skew, a constant echo
/// delay) is kept.
pub(crate) fn vary(c: Concealed, d: &mut Draws, nominal: &Scenario) -> (Concealed, String) {
    let curve = d.unit() < 0.5;
    let pick = d.unit();
    let mut unit = || d.unit();
    match c {
        Concealed::LidarIncidence {
            coefficient,
            collimated_m,
            ..
        } => {
            let (growth, name) = if curve {
                let c = Curve::random(0.0, 80f64.to_radians(), &mut unit);
                (
                    IncidenceGrowth::Curve(c),
                    "a random curve of the incidence angle".to_string(),
                )
            } else if pick < 0.5 {
                (IncidenceGrowth::Secant, "sec θ − 1".to_string())
            } else {
                let onset = (20.0 + 18.0 * unit()).to_radians();
                (
                    IncidenceGrowth::Onset { onset_rad: onset },
                    format!("tan θ past an onset at {:.0}°", onset.to_degrees()),
                )
            };
            (
                Concealed::LidarIncidence {
                    coefficient,
                    collimated_m,
                    growth,
                },
                name,
            )
        }
        Concealed::LidarReflectivity {
            coefficient_m,
            reference,
            ..
        } => {
            let (walk, name) = if curve {
                let c = Curve::random(-1.0, 3.0, &mut unit);
                (
                    ReflectivityWalk::Curve(c),
                    "a random curve of ln(ρ_ref/ρ)".to_string(),
                )
            } else {
                (ReflectivityWalk::Logarithmic, "log₂(ρ_ref/ρ)".to_string())
            };
            (
                Concealed::LidarReflectivity {
                    coefficient_m,
                    reference,
                    walk,
                },
                name,
            )
        }
        Concealed::LidarMixedPixels { half_width_deg, .. } => {
            let (blend, name) = if curve {
                let c = Curve::random(0.0, 1.0, &mut unit);
                let harmonic = pick < 0.5;
                (
                    Blend::Profile { curve: c, harmonic },
                    "a footprint of a random profile".to_string(),
                )
            } else {
                (
                    Blend::GaussianMean,
                    "a Gaussian footprint's mean range".to_string(),
                )
            };
            (
                Concealed::LidarMixedPixels {
                    half_width_deg,
                    blend,
                },
                name,
            )
        }
        Concealed::LidarWarmup {
            coefficient_per_m,
            time_constant_s,
            offset_m,
            ..
        } => {
            let (settling, name) = if curve {
                let c = Curve::random(0.0, 4.0, &mut unit);
                (Settling::Curve(c), "a random settling curve".to_string())
            } else if pick < 0.5 {
                let share = 0.3 + 0.4 * unit();
                (
                    Settling::TwoMasses { fast_share: share },
                    format!("two thermal masses, {:.0} % of it fast", 100.0 * share),
                )
            } else {
                (Settling::Ramp, "a thermostat's ramp".to_string())
            };
            (
                Concealed::LidarWarmup {
                    coefficient_per_m,
                    time_constant_s,
                    offset_m,
                    settling,
                },
                name,
            )
        }
        Concealed::SonarBeamWidth { half_angle_deg, .. } => {
            let (pick, name) = if pick < 0.5 {
                (
                    EchoPick::BeamCentroid,
                    "the echoes' centroid across the beam".to_string(),
                )
            } else {
                (
                    EchoPick::Threshold,
                    "a detection threshold across the lobe".to_string(),
                )
            };
            (
                Concealed::SonarBeamWidth {
                    half_angle_deg,
                    pick,
                },
                name,
            )
        }
        Concealed::WheelSlip { gain_s, .. } => {
            // Speeding up and braking apart: the braking share anywhere in [−1, 1].
            let braking_share = 2.0 * unit() - 1.0;
            let top = largest_acceleration(nominal);
            let (traction, name) = if curve {
                let c = Curve::random(0.0, top, &mut unit);
                (
                    Traction::Curve {
                        top_mps2: top,
                        curve: c,
                    },
                    "a random curve of the acceleration".to_string(),
                )
            } else {
                let accel = top * (0.1 + 0.5 * unit());
                (
                    Traction::Saturating {
                        accel_mps2: accel,
                        top_mps2: top,
                    },
                    format!("a saturating tyre (a_s {accel:.1} m/s²)"),
                )
            };
            (
                Concealed::WheelSlip {
                    gain_s,
                    braking_share,
                    traction,
                },
                name,
            )
        }
        Concealed::MotorLag {
            time_constant_s, ..
        } => {
            let (response, name) = if pick < 1.0 / 3.0 {
                let damping = 0.5 + 0.5 * unit();
                (
                    DriveResponse::SecondOrder { damping },
                    format!("second order, damping {damping:.2}"),
                )
            } else if pick < 2.0 / 3.0 {
                // The largest step reaches 1 − 1/e at τ.
                let accel = (1.0 - (-1.0f64).exp()) * top_speed(nominal) / time_constant_s;
                (
                    DriveResponse::SlewLimited { accel_mps2: accel },
                    "a slew-rate limit".to_string(),
                )
            } else {
                let share = 0.3 + 0.4 * unit();
                (
                    DriveResponse::DeadTime { share },
                    format!("a dead time of {:.0} % of τ and a lag", 100.0 * share),
                )
            };
            (
                Concealed::MotorLag {
                    time_constant_s,
                    response,
                },
                name,
            )
        }
        Concealed::LidarTriangulation { .. } if curve => {
            // The same error at 2 m and mean slope as the catalogue's draw.
            let (at_2m, slope) = range_at_2m_and_scale(c);
            let curve = Curve::random(0.0, RANGE_CURVE_SPAN_M, &mut unit);
            (
                Concealed::LidarRangeCurve {
                    at_2m_m: at_2m,
                    slope,
                    curve,
                },
                "a random curve of the range".to_string(),
            )
        }
        Concealed::LidarTriangulation { .. } => (c, "a triangulation unit's geometry".to_string()),
        Concealed::LidarWeakReturns {
            half_loss_range_m,
            log_power_sd,
            reference,
            ..
        } if curve => {
            let c = Curve::random(-1.5, 1.5, &mut unit);
            (
                Concealed::LidarWeakReturns {
                    half_loss_range_m,
                    log_power_sd,
                    reference,
                    loss: LossBy::RangeCurve(c),
                },
                "a random curve of the range".to_string(),
            )
        }
        // The catalogue writes a logistic in the log power; this, a probit.
        Concealed::LidarWeakReturns { .. } => (c, "a log-normal power threshold".to_string()),
        other => (other, "its only form".to_string()),
    }
}

/// A triangulation unit's range error at 2 m and its scale error (`1/r − 1`, its baseline's).
fn range_at_2m_and_scale(c: Concealed) -> (f64, f64) {
    match c {
        Concealed::LidarTriangulation {
            origin_m,
            baseline_ratio,
            pointing_per_m,
        } => (
            origin_m + 2.0 / (baseline_ratio + 2.0 * pointing_per_m) - 2.0,
            1.0 / baseline_ratio - 1.0,
        ),
        _ => (0.0, 0.0),
    }
}

/// The largest wheel speed the nominal drive commands, m/s: each wheel's `speed_mps` on a
/// straight step, half the base times the turn rate on a turn.
fn top_speed(nominal: &Scenario) -> f64 {
    let turn = nominal.robot.turn_rate_deg_s.to_radians() * nominal.robot.wheel_base_m / 2.0;
    nominal
        .drive
        .iter()
        .map(|s| s.speed_mps.map_or(turn, f64::abs))
        .fold(0.0, f64::max)
        .max(1e-3)
}

/// The largest acceleration the encoders see between two samples: the top speed reached
/// within one sample period.
fn largest_acceleration(nominal: &Scenario) -> f64 {
    let rate = nominal
        .sensors
        .odometer
        .as_ref()
        .map_or(50.0, |o| o.rate_hz);
    top_speed(nominal) * rate
}

/// The effect of catalogue entry `k` (0-based, [`Effect::entries`] order): `sensor_latency`
/// on one of the sensors the scenario has, drawn uniformly (a draw is taken only then).
fn entry_effect(k: usize, d: &mut Draws, nominal: &Scenario) -> Option<Effect> {
    let name = *Effect::entries().get(k)?;
    let s = &nominal.sensors;
    let has = |e: &Effect| match e.sensor() {
        Sensor::Lidar => s.lidar.is_some(),
        Sensor::Sonar => s.sonar.is_some(),
        Sensor::Odometer => s.odometer.is_some(),
        Sensor::Drive => true,
    };
    let mut effects = Effect::named(name);
    if effects.len() > 1 {
        effects.retain(has);
        let i = (d.unit() * effects.len() as f64).floor() as usize;
        return effects.get(i.min(effects.len().saturating_sub(1))).copied();
    }
    effects.first().copied()
}

/// What a trial of the independent reality conceals, before its parameters are drawn.
pub(crate) struct Classes {
    /// The catalogued effects (none, one or two).
    effects: Vec<Effect>,
    /// A periodic range error outside the catalogue.
    outside: bool,
}

/// Trial `i`'s classes in the independent reality: with probability 1/5 two different
/// catalogued entries, else one of eighteen classes (none, the sixteen entries, a periodic
/// range error outside the catalogue), or the `only` one (0 none, 1..=16 the catalogue's
/// entries, 17 outside).
pub(crate) fn draw_classes(d: &mut Draws, nominal: &Scenario, only: Option<usize>) -> Classes {
    let entries = Effect::entries().len();
    let two = only.is_none() && d.unit() < TWO_EFFECTS;
    let class = only.unwrap_or_else(|| (d.unit() * (entries + 2) as f64).floor() as usize);
    let mut effects: Vec<Effect> = Vec::new();
    if two {
        let a = ((d.unit() * entries as f64).floor() as usize).min(entries - 1);
        let b = (a + 1 + (d.unit() * (entries - 1) as f64).floor() as usize) % entries;
        effects.extend(entry_effect(a, d, nominal));
        effects.extend(entry_effect(b, d, nominal));
    } else if let Some(e) = class
        .checked_sub(1)
        .and_then(|k| entry_effect(k, d, nominal))
    {
        effects.push(e);
    }
    Classes {
        effects,
        outside: !two && class == entries + 1,
    }
}

/// The concealment of `classes` in the independent reality: each effect's parameters (the
/// periodic range error outside the catalogue: amplitude ±[1, 4] cm × strength, period
/// [0.3, 1] m), in a form the catalogue does not write where `varied` ([`vary`]), and the
/// run's nuisances.
pub(crate) fn draw_independent(
    classes: &Classes,
    d: &mut Draws,
    strength: f64,
    nominal: &Scenario,
    varied: bool,
) -> (Drawn, Nuisances) {
    let mut drawn = Drawn {
        effect: None,
        effects: nominal.effects.clone(),
        truth: None,
        params: Vec::new(),
        second: None,
        outside: classes.outside,
        concealed: Vec::new(),
        forms: Vec::new(),
        redrawn: 0,
    };
    for (k, e) in classes.effects.iter().enumerate() {
        let specs = e.params();
        let values = draw_values(*e, d, strength, nominal);
        let truth = e.scored(&values);
        if k == 0 {
            drawn.effect = Some(*e);
            drawn.truth = Some(truth);
        } else {
            drawn.second = Some((*e, truth));
        }
        let mechanism = concealed(*e, &values);
        if varied {
            let (mechanism, form) = vary(mechanism, d, nominal);
            drawn.concealed.push(mechanism);
            drawn.forms.push(format!("{}: {form}", e.name()));
        } else {
            drawn.concealed.push(mechanism);
        }
        for (spec, v) in specs.iter().zip(&values) {
            drawn
                .params
                .push((format!("{}.{}", e.name(), spec.name), *v));
        }
    }
    if drawn.outside {
        let amplitude = d.sign() * d.between(0.01, 0.04) * strength;
        let period = d.between(0.3, 1.0);
        drawn.concealed.push(Concealed::LidarPeriodicRange {
            amplitude_m: amplitude,
            period_m: period,
        });
        drawn
            .params
            .push((format!("{OUTSIDE}.amplitude_m"), amplitude));
        drawn.params.push((format!("{OUTSIDE}.period_m"), period));
    }
    let mut nuisance_draws = Stream::new(d.next(), "nuisances");
    (drawn, Nuisances::draw(&mut nuisance_draws))
}

/// Draws trial `i`'s effect: none, or one of the catalogue's entries (each with probability
/// 1/17, or the `only` one: 0 none, 1..=16 the entries in order; `sensor_latency` on a sensor
/// drawn among the scenario's), and its parameters from their [`SelfTestRange`]s (the
/// documented moderate ranges × `strength`; [`Effect::params`]).
pub(crate) fn draw(d: &mut Draws, strength: f64, nominal: &Scenario, only: Option<usize>) -> Drawn {
    let drawn_class = (d.unit() * (Effect::entries().len() + 1) as f64).floor() as usize;
    let k = only.unwrap_or(drawn_class);
    let mut effects = nominal.effects.clone();
    let effect = k.checked_sub(1).and_then(|i| entry_effect(i, d, nominal));
    let Some(effect) = effect else {
        return Drawn {
            effect: None,
            effects,
            truth: None,
            params: Vec::new(),
            second: None,
            outside: false,
            concealed: Vec::new(),
            forms: Vec::new(),
            redrawn: 0,
        };
    };
    let specs = effect.params();
    let values = draw_values(effect, d, strength, nominal);
    effect.apply(&values, &mut effects);
    Drawn {
        effect: Some(effect),
        effects,
        truth: Some(effect.scored(&values)),
        params: specs
            .iter()
            .zip(&values)
            .map(|(spec, &v)| (spec.name.to_string(), v))
            .collect(),
        second: None,
        outside: false,
        concealed: vec![concealed(effect, &values)],
        forms: Vec::new(),
        redrawn: 0,
    }
}

/// `effect`'s parameters' true values, each from its [`SelfTestRange`]; the warm-up's drift
/// then, on a fair coin, all in its constant term (the same error at 2 m at power-on, what
/// the self-test scores it by): a unit whose housing drifts rather than its pointing, or
/// another simulator's reading of "the range bias drifts"; the incidence's likewise in its
/// collimated term (the same error at 2 m and 45°).
fn draw_values(effect: Effect, d: &mut Draws, strength: f64, nominal: &Scenario) -> Vec<f64> {
    let mut values: Vec<f64> = effect
        .params()
        .iter()
        .map(|spec| draw_value(&spec.self_test, d, strength, nominal))
        .collect();
    // An effect of two shapes (the warm-up's constant, the incidence's collimated beam): the
    // parameter of the second that the first does not have.
    let shapes = effect.shapes();
    let second = shapes
        .get(1)
        .and_then(|s| s.iter().find(|i| !shapes[0].contains(i)));
    if let Some(&i) = second {
        if d.next() & 1 == 0 {
            let scored = effect.scored(&values);
            values[0] = 0.0;
            values[i] = scored;
        }
    }
    values
}

/// One parameter's true value, drawn from `range`.
fn draw_value(range: &SelfTestRange, d: &mut Draws, strength: f64, nominal: &Scenario) -> f64 {
    let (lo, hi) = match range.source {
        DrawSource::Uniform { lo, hi } => (lo, hi),
        DrawSource::LidarRevolution => {
            return 60.0 / nominal.sensors.lidar.as_ref().map_or(300.0, |l| l.rpm);
        }
        DrawSource::Zero => return range.around.unwrap_or(0.0),
    };
    // The sign is drawn before the magnitude.
    let sign = if range.signed { d.sign() } else { 1.0 };
    let mut v = sign * d.between(lo, hi);
    if range.scaled {
        v *= strength;
    }
    if let Some(centre) = range.around {
        v += centre;
    }
    v.clamp(range.min, range.max)
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

#[cfg(test)]
mod tests {
    use std::path::Path;

    use hilsim_fixtures::rooms::ROOM_4X3;

    use super::*;

    fn room() -> Scenario {
        let robot = "[robot]\nstart = { x = 1.0, y = 1.0 }\nwheel_base_m = 0.23\n";
        let sensors = "[sensors.odometer]\nnoise_m = 0.001\n";
        Scenario::from_toml(
            &format!("name = \"room\"\nduration_s = 4.0\n{ROOM_4X3}{robot}{sensors}"),
            Path::new("room.toml"),
        )
        .expect("the test's scenario")
    }

    /// The varied reality never conceals a shaped mechanism in the catalogue's form, and draws
    /// a random curve in about half of them: 400 draws per mechanism, a curve's share within
    /// 0.35–0.65 (a fair coin's 400 tosses stay within it with probability 1 − 10⁻⁹).
    #[test]
    fn the_varied_reality_draws_forms_the_catalogue_does_not_write() {
        let nominal = room();
        for effect in [
            Effect::LidarIncidenceAngle,
            Effect::LidarReflectivity,
            Effect::LidarMixedPixels,
            Effect::LidarWarmupDrift,
            Effect::SonarBeamWidth,
            Effect::OdometerWheelSlip,
            Effect::DriveMotorLag,
            Effect::LidarRangeBias,
            Effect::LidarDropout,
        ] {
            let mut d = Draws::new(5, 0);
            let mut curves = 0;
            for _ in 0..400 {
                let values = draw_values(effect, &mut d, 1.0, &nominal);
                let (varied, form) = vary(concealed(effect, &values), &mut d, &nominal);
                for catalogue_form in [
                    "Tangent",
                    "Inverse",
                    "TopHatHarmonic",
                    "Exponential",
                    "Nearest",
                    "Linear",
                    "FirstOrder",
                ] {
                    assert!(
                        !format!("{varied:?}").contains(catalogue_form),
                        "{effect:?}: {varied:?}"
                    );
                }
                curves += usize::from(form.contains("random"));
            }
            let curved = [
                Effect::LidarIncidenceAngle,
                Effect::LidarReflectivity,
                Effect::LidarMixedPixels,
                Effect::LidarWarmupDrift,
                Effect::OdometerWheelSlip,
                Effect::LidarRangeBias,
                Effect::LidarDropout,
            ]
            .contains(&effect);
            if curved {
                assert!((140..=260).contains(&curves), "{effect:?}: {curves}/400");
            } else {
                assert_eq!(curves, 0, "{effect:?}");
            }
        }
    }
}
