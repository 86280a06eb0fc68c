//! `sonar_speed_of_sound`: the sound travels at the air's own speed, not at the calibration
//! temperature's, which scales every range.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// The temperature the sonar's speed of sound is calibrated at, °C.
const CALIBRATED_AT_C: f64 = 20.0;

/// `sonar_speed_of_sound`.
pub(crate) struct SonarSpeedOfSound;

impl Entry for SonarSpeedOfSound {
    fn name(&self) -> &'static str {
        "sonar_speed_of_sound"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Sonar
    }

    /// The temperature sets the speed, which scales the range.
    fn variables(&self) -> &'static [Variable] {
        &[Variable::AirTemperature, Variable::Range]
    }

    /// The self-test draws an air temperature of 20 °C ±[15, 30] °C (within [−50, 60] °C,
    /// scored as the departure from 20 °C).
    fn params(&self) -> &'static [ParamSpec] {
        const SOUND: [ParamSpec; 1] = [lin(
            "air_temperature_c",
            "degC",
            (-50.0, 60.0),
            23,
            R::uniform(15.0, 30.0).signed().around(20.0, -50.0, 60.0),
        )];
        &SOUND
    }

    /// Absent at the declared calibration temperature (20 °C).
    fn absent(&self, _: f64) -> Vec<f64> {
        vec![20.0]
    }

    /// 0.6 °C, 0.1 % of range (1 mm at 1 m).
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.6)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        effects.sonar_speed_of_sound = Some(scenario::SonarSpeedOfSound {
            air_temperature_c: p(0),
            calibrated_at_c: CALIBRATED_AT_C,
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        format!(
            "The simulated sonar assumes sound travels at its calibration temperature (20 °C); \
             the real air was at {:.1} °C, which scales every range.",
            p(0)
        )
    }
}
