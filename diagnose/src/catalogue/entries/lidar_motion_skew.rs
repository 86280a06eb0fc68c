//! `lidar_motion_skew`: the lidar's head takes a revolution to turn while the robot moves, so
//! each reading is taken from where the robot was at its own instant.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `lidar_motion_skew`.
pub(crate) struct LidarMotionSkew;

impl Entry for LidarMotionSkew {
    fn name(&self) -> &'static str {
        "lidar_motion_skew"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Lidar
    }

    /// A reading's instant within the revolution, and how far the robot moves and turns by it.
    fn variables(&self) -> &'static [Variable] {
        &[
            Variable::TimeInRevolution,
            Variable::WheelSpeed,
            Variable::Turn,
        ]
    }

    /// The self-test takes the head's own period.
    fn params(&self) -> &'static [ParamSpec] {
        const SKEW: [ParamSpec; 1] =
            [lin("revolution_s", "s", (0.0, 0.6), 9, R::lidar_revolution()).searched_from_zero()];
        &SKEW
    }

    /// A revolution of 0.02 s, a tenth of the XV-11's 0.2 s.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.02)]
    }

    /// Motion skew's table has no parameter: the revolution's duration is the lidar's `rpm` in
    /// a scenario, and the diagnosis's physics fits it as the timing of each reading
    /// ([`crate::SimPhysics`]).
    fn apply(&self, _: &[f64], effects: &mut Effects) {
        effects.lidar_motion_skew = Some(scenario::LidarMotionSkew {});
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        format!(
            "The simulated lidar takes a whole revolution at one instant; the real one turns \
             for {:.2} s while the robot moves.",
            p(0)
        )
    }
}
