//! `sonar_beam_width`: the sonar returns the nearest echo anywhere in its cone, not along its
//! axis only.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `sonar_beam_width`.
pub(crate) struct SonarBeamWidth;

impl Entry for SonarBeamWidth {
    fn name(&self) -> &'static str {
        "sonar_beam_width"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Sonar
    }

    fn variables(&self) -> &'static [Variable] {
        &[Variable::EchoCone]
    }

    /// The self-test draws a cone of [8, 20]° (at most 60°).
    fn params(&self) -> &'static [ParamSpec] {
        const BEAM: [ParamSpec; 1] = [lin(
            "half_angle_deg",
            "deg",
            (0.0, 45.0),
            16,
            R::uniform(8.0, 20.0).at_most(60.0),
        )
        .searched_from_zero()];
        &BEAM
    }

    /// Absent at the declared sonar cone.
    fn absent(&self, declared_half_angle_deg: f64) -> Vec<f64> {
        vec![declared_half_angle_deg]
    }

    /// 1°, four of the emulator's 0.25° rays.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 1.0)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        effects.sonar_beam_width = Some(scenario::SonarBeamWidth {
            half_angle_deg: p(0).clamp(0.0, 89.0),
        });
    }

    fn explanation(&self, params: &[f64], declared_half_angle_deg: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        if declared_half_angle_deg > 0.0 {
            format!(
                "The simulated sonar's cone is ±{declared_half_angle_deg:.1}°; the real one \
                 returns the nearest echo anywhere in a cone of ±{:.1}°.",
                p(0)
            )
        } else {
            format!(
                "The simulated sonar sees along its axis only; the real one returns the nearest \
                 echo anywhere in a cone of ±{:.1}°.",
                p(0)
            )
        }
    }
}
