//! `odometer_wheel_radius`: each wheel rolls on its own effective radius, not the nominal one.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `odometer_wheel_radius`.
pub(crate) struct OdometerWheelRadius;

impl Entry for OdometerWheelRadius {
    fn name(&self) -> &'static str {
        "odometer_wheel_radius"
    }

    /// It moves the robot `scale` times the command (the drive) and makes the encoders
    /// disagree with the world (the odometer). It is the odometer's: the encoders'
    /// disagreement is per wheel and everywhere (straight runs and turns), a millimetre sensor
    /// against the truth, while in the drive an equal scale on both wheels is what the declared
    /// actuation scale error already allows.
    fn sensor(&self) -> Sensor {
        Sensor::Odometer
    }

    fn shows_in_drive(&self) -> bool {
        true
    }

    fn variables(&self) -> &'static [Variable] {
        &[Variable::WheelTravel]
    }

    /// The self-test draws each wheel's radius scale 1 ± [0.01, 0.03].
    fn params(&self) -> &'static [ParamSpec] {
        // Each wheel's radius scale within ±20 % of nominal (a worn or soft tyre is a few per
        // cent; the scenario allows ±50 %).
        const RADIUS: [ParamSpec; 2] = [
            lin(
                "left_scale",
                "",
                (0.8, 1.2),
                9,
                R::uniform(0.01, 0.03).signed().around(1.0, 0.5, 1.5),
            ),
            lin(
                "right_scale",
                "",
                (0.8, 1.2),
                9,
                R::uniform(0.01, 0.03).signed().around(1.0, 0.5, 1.5),
            ),
        ];
        &RADIUS
    }

    fn absent(&self, _: f64) -> Vec<f64> {
        vec![1.0, 1.0]
    }

    /// A scale of 0.003 on either wheel: a rubber tyre's rolling radius changes by that much
    /// under load (0.1 mm of deflection on a 35 mm wheel), and two simulators integrating a
    /// wheel's arc differ by 0.1 % (an independent reality's faithful runs fit 0.999).
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.003), (1, 0.003)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let scale = |i: usize| params.get(i).copied().unwrap_or(1.0);
        effects.odometer_wheel_radius = Some(scenario::OdometerWheelRadius {
            left_scale: scale(0),
            right_scale: scale(1),
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        format!(
            "The simulated wheels have their nominal radius; the real left one is {:.1} % \
             and the right one {:.1} % of it, so the robot moves that much of its command \
             while the encoders report the command.",
            p(0) * 100.0,
            p(1) * 100.0
        )
    }
}
