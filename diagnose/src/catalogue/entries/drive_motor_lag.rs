//! `drive_motor_lag`: the wheels reach a commanded speed through the motors' response, not at
//! once.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, log, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `drive_motor_lag`.
pub(crate) struct DriveMotorLag;

impl Entry for DriveMotorLag {
    fn name(&self) -> &'static str {
        "drive_motor_lag"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Drive
    }

    fn variables(&self) -> &'static [Variable] {
        &[Variable::Command]
    }

    /// The self-test draws τ of [0.1, 0.4] s (at most 10 s).
    fn params(&self) -> &'static [ParamSpec] {
        // The lag's response time, and its form as the inverse of a second-order response's
        // damping over [0, 2.5] on a 0.5 grid: 0 the first-order lag (a second order's limit as
        // its damping grows at the same response time), 1 critical damping, 2.5 a wheel that
        // overshoots by 52 % (ζ = 0.4). The form, which the self-test's catalogue reality keeps
        // first order.
        const LAG: [ParamSpec; 2] = [
            log(
                "time_constant_s",
                "s",
                (0.005, 5.0),
                13,
                R::uniform(0.1, 0.4).at_most(10.0),
            )
            .searched_from_zero(),
            lin("underdamping", "", (0.0, 2.5), 6, R::zero()).form(),
        ];
        &LAG
    }

    /// The underdamping.
    fn form_params(&self) -> &'static [usize] {
        &[1]
    }

    fn absent(&self, _: f64) -> Vec<f64> {
        vec![0.0, 0.0]
    }

    /// τ: 0.02 s, two physics steps (the drive's resolution is 0.01 s).
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.02)]
    }

    /// A lag of 0 leaves the effect off: the scenario's table cannot exist there.
    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        // The underdamping 1/ζ; under 0.1 (ζ past 10) the response is the first-order
        // lag's to a tenth of a percent.
        let underdamping = p(1);
        effects.drive_motor_lag = (p(0) > 0.0).then_some(scenario::DriveMotorLag {
            time_constant_s: p(0),
            damping: (underdamping >= 0.1).then(|| 1.0 / underdamping),
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        if p(1) >= 0.1 {
            format!(
                "The simulated wheels reach a commanded speed at once; the real ones reach \
                 1 − 1/e of a step in {:.2} s through a second-order response of damping {:.2}{}.",
                p(0),
                1.0 / p(1),
                if p(1) > 1.0 {
                    ", overshooting before they settle"
                } else {
                    ""
                }
            )
        } else {
            format!(
                "The simulated wheels reach a commanded speed at once; the real ones follow it \
                 with a first-order lag of {:.2} s.",
                p(0)
            )
        }
    }
}
