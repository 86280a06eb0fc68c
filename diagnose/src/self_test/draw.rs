//! What a trial conceals: an effect (or none) and its parameters, drawn from (S, i) alone.

use hilsim_sim::scenario::Effects;
use hilsim_sim::Scenario;
use rand_xoshiro::rand_core::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;

use crate::catalogue::{DrawSource, SelfTestRange};
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

/// Draws trial `i`'s effect: none, or one of the catalogue (each with probability 1/10, or the
/// `only` one: 0 none, 1..=9 the catalogue in order), and its parameters from their
/// [`SelfTestRange`]s (the documented moderate ranges × `strength`; [`Effect::params`]).
pub(crate) fn draw(d: &mut Draws, strength: f64, nominal: &Scenario, only: Option<usize>) -> Drawn {
    let drawn_class = (d.unit() * 10.0).floor() as usize;
    let k = only.unwrap_or(drawn_class);
    let mut effects = nominal.effects.clone();
    let effect = k.checked_sub(1).and_then(|i| Effect::ALL.get(i).copied());
    let Some(effect) = effect else {
        return Drawn {
            effect: None,
            effects,
            truth: None,
            params: Vec::new(),
        };
    };
    let specs = effect.params();
    let values: Vec<f64> = specs
        .iter()
        .map(|spec| draw_value(&spec.self_test, d, strength, nominal))
        .collect();
    effect.apply(&values, &mut effects);
    Drawn {
        effect: Some(effect),
        effects,
        truth: Some(specs[0].self_test.scored(values[0])),
        params: specs
            .iter()
            .zip(&values)
            .map(|(spec, &v)| (spec.name.to_string(), v))
            .collect(),
    }
}

/// One parameter's true value, drawn from `range`.
fn draw_value(range: &SelfTestRange, d: &mut Draws, strength: f64, nominal: &Scenario) -> f64 {
    let (lo, hi) = match range.source {
        DrawSource::Uniform { lo, hi } => (lo, hi),
        DrawSource::LidarRevolution => {
            return 60.0 / nominal.sensors.lidar.as_ref().map_or(300.0, |l| l.rpm);
        }
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
