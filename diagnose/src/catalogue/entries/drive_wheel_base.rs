//! `drive_wheel_base`: the wheels turn the robot about their effective base, not the nominal
//! one.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `drive_wheel_base`.
pub(crate) struct DriveWheelBase;

impl Entry for DriveWheelBase {
    fn name(&self) -> &'static str {
        "drive_wheel_base"
    }

    /// It turns the robot `1/scale` times the command (the drive) while the encoders agree
    /// with the command, so they disagree with the world's turn (the odometer). It is the
    /// odometer's: fitted beside the wheel radius on the same data, the forward selection
    /// tells the two apart (the radius moves straight travel as well, the base only turns)
    /// instead of each being named in its own sensor for the other's mismatch. See
    /// [`Entry::shows_in`] for the drive.
    fn sensor(&self) -> Sensor {
        Sensor::Odometer
    }

    fn shows_in_drive(&self) -> bool {
        true
    }

    fn variables(&self) -> &'static [Variable] {
        &[Variable::Turn]
    }

    /// The self-test draws a scale of 1 ± [0.03, 0.1].
    fn params(&self) -> &'static [ParamSpec] {
        // The base's scale within ±30 % of nominal (a worn or soft tyre is a few per cent; the
        // scenario allows ±50 %).
        const BASE: [ParamSpec; 1] = [lin(
            "scale",
            "",
            (0.7, 1.3),
            13,
            R::uniform(0.03, 0.1).signed().around(1.0, 0.5, 1.5),
        )];
        &BASE
    }

    fn absent(&self, _: f64) -> Vec<f64> {
        vec![1.0]
    }

    /// A scale of 0.0005, 1 mm of turn per 2 m of wheel travel.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.000_5)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        effects.drive_wheel_base = Some(scenario::DriveWheelBase {
            scale: params.first().copied().unwrap_or(1.0),
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        format!(
            "The simulated wheels turn the robot about the nominal wheel base; the real \
             effective base is {:.1} % of it, so every turn comes out {:.1} % as large.",
            p(0) * 100.0,
            100.0 / p(0)
        )
    }
}
