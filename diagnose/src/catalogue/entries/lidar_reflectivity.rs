//! `lidar_reflectivity`: the lidar's range walks with how much light the surface returns.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// The reference reflectivity of `[effects.lidar_reflectivity]` (the catalogue's coefficient is
/// the range walk on a surface of half of it).
pub(crate) const REFERENCE_REFLECTIVITY: f64 = 0.8;

/// `lidar_reflectivity`.
pub(crate) struct LidarReflectivity;

impl Entry for LidarReflectivity {
    fn name(&self) -> &'static str {
        "lidar_reflectivity"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Lidar
    }

    fn variables(&self) -> &'static [Variable] {
        &[Variable::Reflectivity]
    }

    /// The self-test draws c ±[0.008, 0.02] m.
    fn params(&self) -> &'static [ParamSpec] {
        const REFLECTIVITY: [ParamSpec; 1] = [lin(
            "coefficient_m",
            "m",
            (-0.1, 0.1),
            11,
            R::uniform(0.008, 0.02).signed(),
        )];
        &REFLECTIVITY
    }

    /// c: 1 mm on a surface of half the reference's reflectivity.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.001)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        effects.lidar_reflectivity = Some(scenario::LidarReflectivity {
            coefficient_m: p(0),
            reference: REFERENCE_REFLECTIVITY,
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        format!(
            "The simulated lidar ranges every material alike; the real one's range walks with \
             the surface's reflectivity ({:+.1} mm on a surface of half the reference's).",
            p(0) * 1000.0
        )
    }
}
