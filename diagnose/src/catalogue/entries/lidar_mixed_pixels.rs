//! `lidar_mixed_pixels`: the lidar's beam has a width, and where it grazes an edge it returns a
//! range between the near surface and the far one.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{log, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `lidar_mixed_pixels`.
pub(crate) struct LidarMixedPixels;

impl Entry for LidarMixedPixels {
    fn name(&self) -> &'static str {
        "lidar_mixed_pixels"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Lidar
    }

    fn variables(&self) -> &'static [Variable] {
        &[Variable::NearnessToEdge]
    }

    /// The self-test draws a half-width of [0.5, 1.5]° (at most 5°).
    fn params(&self) -> &'static [ParamSpec] {
        const MIXED: [ParamSpec; 1] = [log(
            "half_width_deg",
            "deg",
            (0.05, 3.0),
            10,
            R::uniform(0.5, 1.5).at_most(5.0),
        )
        .searched_from_zero()];
        &MIXED
    }

    /// A beam half-width of 0.1°, a third of a typical 0.3° direction noise.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.1)]
    }

    /// A footprint of 0 leaves the effect off: the scenario's table cannot exist there.
    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        effects.lidar_mixed_pixels = (p(0) > 0.0).then_some(scenario::LidarMixedPixels {
            half_width_deg: p(0),
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        format!(
            "The simulated lidar's beam is a line; the real beam is {:.2}° wide, and where it \
             grazes an edge it returns a range between foreground and background.",
            2.0 * p(0)
        )
    }
}
