//! `sonar_range_bias`: the sonar's echo is detected later (or earlier) than its calibration
//! says, by the same distance at every range.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `sonar_range_bias`.
pub(crate) struct SonarRangeBias;

impl Entry for SonarRangeBias {
    fn name(&self) -> &'static str {
        "sonar_range_bias"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Sonar
    }

    fn variables(&self) -> &'static [Variable] {
        &[Variable::Range]
    }

    fn is_range_calibration(&self) -> bool {
        true
    }

    /// The self-test draws a range offset of ±[10, 60] mm.
    fn params(&self) -> &'static [ParamSpec] {
        // The sonar's range offset alone, over ±0.2 m on a 5 cm grid: its scale is the speed
        // of sound's (`sonar_speed_of_sound` scales every range, and an affine sonar's scale
        // error is that one's parameter), so the two entries together are the EM paper's
        // affine sonar and neither can pass for the other.
        const SONAR_RANGE_BIAS: [ParamSpec; 1] = [lin(
            "offset_m",
            "m",
            (-0.2, 0.2),
            9,
            R::uniform(0.01, 0.06).signed(),
        )];
        &SONAR_RANGE_BIAS
    }

    /// The offset: 1 mm.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.001)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        effects.sonar_range_bias = Some(scenario::RangeBias {
            offset_m: p(0),
            ..scenario::RangeBias::default()
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        format!(
            "The real sonar reads {:+.1} mm more than the scenario's range bias declares, at \
             every range: its echo is detected that much later than its calibration says.",
            p(0) * 1000.0
        )
    }
}
