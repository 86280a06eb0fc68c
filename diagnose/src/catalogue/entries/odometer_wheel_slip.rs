//! `odometer_wheel_slip`: a driven wheel's surface outruns the ground as it speeds up, so the
//! encoders lead the true travel.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `odometer_wheel_slip`.
pub(crate) struct OdometerWheelSlip;

impl Entry for OdometerWheelSlip {
    fn name(&self) -> &'static str {
        "odometer_wheel_slip"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Odometer
    }

    fn variables(&self) -> &'static [Variable] {
        &[Variable::WheelAcceleration]
    }

    /// The mirror of a delay: encoders leading the path by `g v`, as ones stamped early would.
    fn sized_as_a_delay(&self) -> bool {
        true
    }

    /// The self-test draws a gain of [0.03, 0.1] s (braking alike).
    fn params(&self) -> &'static [ParamSpec] {
        // Slip's gain is searched at g ≥ 0 only (the same 0.1 s grid as before on that side):
        // a driven wheel's surface outruns the ground as it accelerates (the traction force
        // needs a positive slip ratio: Wong, *Theory of Ground Vehicles*, ch. 1), so the
        // encoders lead. Encoders that lag the travel by `L v` are a late stamp, the
        // odometer's `sensor_latency`, which is otherwise a slip with g = −L.
        //
        // The braking gain as a share of the driving one over [−1, 1] on a 0.5 grid
        // through 1 (even: braking gives back what speeding up led), 0 (slip only while speeding
        // up) and −1 (a lead gained at every change of speed): the form, which the self-test's
        // catalogue reality keeps even.
        const SLIP: [ParamSpec; 2] = [
            lin("gain_s", "s", (0.0, 0.5), 6, R::uniform(0.03, 0.1)).searched_from_zero(),
            lin(
                "braking_share",
                "",
                (-1.0, 1.0),
                5,
                R::zero().around(1.0, -1.0, 1.0),
            )
            .form(),
        ];
        &SLIP
    }

    /// The braking share.
    fn form_params(&self) -> &'static [usize] {
        &[1]
    }

    fn absent(&self, _: f64) -> Vec<f64> {
        vec![0.0, 1.0]
    }

    /// g: 0.01 s, the odometer's 2 mm floor over a 0.2 m/s change of speed (slip's extra
    /// travel is g Δv).
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.01)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        // The braking gain as a share of the driving one; even (1) when not fitted.
        let share = params.get(1).copied().unwrap_or(1.0);
        effects.odometer_wheel_slip = Some(scenario::OdometerWheelSlip {
            gain_s: p(0),
            braking_gain_s: (share != 1.0).then(|| share * p(0)),
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        slip_sentence(p(0), params.get(1).copied())
    }
}

/// The slip's sentence: its driving gain, and how braking departs from giving back the lead
/// when the braking share (the braking gain over the driving one) is not even.
fn slip_sentence(gain_s: f64, braking_share: Option<f64>) -> String {
    let ms = gain_s * 1000.0;
    let even = "The simulated wheels grip perfectly; the real ones slip as they accelerate, so";
    // Within a tenth of the fit's 0.5 grid step of even.
    match braking_share {
        Some(share) if share.is_finite() && (share - 1.0).abs() >= 0.05 => {
            let braking = if share.abs() < 0.05 {
                "braking gives none of it back".to_string()
            } else if share < 0.0 {
                format!(
                    "braking adds {:.0} ms × the change of speed to the lead instead of giving it \
                     back",
                    -share * ms
                )
            } else {
                format!("braking gives back {:.0} % of it", share * 100.0)
            };
            format!(
                "{even} the encoders gain {ms:.0} ms × the change of speed on speeding up, and \
                 {braking}: the shape differs from the catalogue's even slip."
            )
        }
        _ => format!("{even} the encoders lead the true travel by {ms:.0} ms × the wheel's speed."),
    }
}
