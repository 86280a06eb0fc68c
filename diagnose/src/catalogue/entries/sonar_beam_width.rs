//! `sonar_beam_width`: the sonar hears echoes anywhere in its cone, not along its axis only:
//! the nearest of them, or (its form) partly their centroid across the beam's main lobe.

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

    /// The self-test draws a cone of [8, 20]° (at most 60°), timed at the nearest echo.
    ///
    /// The form is the share of the reading that is the echoes' centroid across the main lobe
    /// rather than the nearest echo: a threshold detector times an echo's onset (0), an
    /// envelope detector its centre (1), and a wide reflector seen across the beam puts the
    /// two apart by a large share of its range. Searched at 0, ½ and 1.
    fn params(&self) -> &'static [ParamSpec] {
        const BEAM: [ParamSpec; 2] = [
            lin(
                "half_angle_deg",
                "deg",
                (0.0, 45.0),
                16,
                R::uniform(8.0, 20.0).at_most(60.0),
            )
            .searched_from_zero(),
            lin("centroid_share", "", (0.0, 1.0), 3, R::zero()).form(),
        ];
        &BEAM
    }

    /// The centroid share.
    fn form_params(&self) -> &'static [usize] {
        &[1]
    }

    /// Absent at the declared sonar cone, timed at the nearest echo.
    fn absent(&self, declared_half_angle_deg: f64) -> Vec<f64> {
        vec![declared_half_angle_deg, 0.0]
    }

    /// 1°, four of the emulator's 0.25° rays.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 1.0)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        effects.sonar_beam_width = Some(scenario::SonarBeamWidth {
            half_angle_deg: p(0).clamp(0.0, 89.0),
            centroid_share: p(1).clamp(0.0, 1.0),
        });
    }

    fn explanation(&self, params: &[f64], declared_half_angle_deg: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        let share = params.get(1).copied().unwrap_or(0.0);
        // A tenth of the grid's ½ step from the onset: the catalogue's nearest echo.
        let echo = if share.is_finite() && share >= 0.995 {
            format!(
                "times its echoes at their centroid across the beam's main lobe, in a cone of \
                 ±{:.1}°: the shape differs from the catalogue's nearest echo",
                p(0)
            )
        } else if share.is_finite() && share >= 0.05 {
            format!(
                "times its echoes {:.0} % at their centroid across the beam's main lobe and the \
                 rest at the nearest, in a cone of ±{:.1}°: the shape differs from the \
                 catalogue's nearest echo",
                share * 100.0,
                p(0)
            )
        } else {
            format!(
                "returns the nearest echo anywhere in a cone of ±{:.1}°",
                p(0)
            )
        };
        if declared_half_angle_deg > 0.0 {
            format!(
                "The simulated sonar's cone is ±{declared_half_angle_deg:.1}°; the real one \
                 {echo}."
            )
        } else {
            format!("The simulated sonar sees along its axis only; the real one {echo}.")
        }
    }
}
