//! `lidar_range_bias`: the lidar's calibration differs from the declared one, by an error that
//! changes with the range.

use hilsim_sim::scenario::{self, Effects, RangeBias};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// The range about which the catalogue's range bias is parametrised (its error there, slope and
/// curvature), metres: the middle of a room's ranges.
const RANGE_BIAS_ABOUT_M: f64 = 2.0;

/// A `lidar_range_bias` of `params` (its error at 2 m, slope and curvature there; a missing one
/// is 0) in the papers' form, `c + s d + q d²`: the scenario's `[effects.lidar_range_bias]`.
pub(crate) fn range_bias(params: &[f64]) -> scenario::RangeBias {
    let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
    let (a, s, q, r) = (p(0), p(1), p(2), RANGE_BIAS_ABOUT_M);
    scenario::RangeBias {
        offset_m: a - s * r + q * r * r,
        scale_error: s - 2.0 * q * r,
        quadratic_per_m: q,
    }
}

/// `lidar_range_bias`.
pub(crate) struct LidarRangeBias;

impl Entry for LidarRangeBias {
    fn name(&self) -> &'static str {
        "lidar_range_bias"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Lidar
    }

    fn variables(&self) -> &'static [Variable] {
        &[Variable::Range]
    }

    fn is_range_calibration(&self) -> bool {
        true
    }

    /// The self-test draws ±[10, 60] mm at 2 m and a scale error of ±[0.5, 3] % (its quadratic
    /// term not drawn).
    fn params(&self) -> &'static [ParamSpec] {
        // The range bias as its error at 2 m (the middle of a room's ranges), its slope there
        // and its curvature about it, `a + s (d − 2 m) + q (d − 2 m)²`: in the papers'
        // `c + s d + q d²` the offset and the scale trade against each other over a room's
        // ranges (the simplex, started on the grid, ran along their valley to the box's
        // corner), while about the middle the three are nearly independent. The error at 2 m
        // over ±0.2 m on a 5 cm grid, the scale error over ±10 % on a 5 % grid, the curvature
        // over ±0.02 /m (a third of the XV-11's own 0.058 /m, the landmark paper's Sec. 4.1):
        // the readings' means are linear in all three, so the likelihood is unimodal.
        const RANGE_BIAS: [ParamSpec; 3] = [
            lin(
                "at_2m_m",
                "m",
                (-0.2, 0.2),
                9,
                R::uniform(0.01, 0.06).signed(),
            ),
            lin(
                "scale_error",
                "",
                (-0.1, 0.1),
                5,
                R::uniform(0.005, 0.03).signed(),
            ),
            lin("quadratic_per_m", "1/m", (-0.02, 0.02), 3, R::zero()).form(),
        ];
        &RANGE_BIAS
    }

    fn absent(&self, _: f64) -> Vec<f64> {
        vec![0.0; 3]
    }

    /// 1 mm at 2 m, or 1 mm at 0 and 4 m of its scale error or curvature.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.001), (1, 0.000_5), (2, 0.000_25)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        effects.lidar_range_bias = Some(range_bias(params));
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        range_bias_sentence(&range_bias(params))
    }
}

/// The range bias's sentence: what the real lidar reads more than the scenario declares, as
/// `c + s·d` (and `q·d²` where the quadratic term is a millimetre or more at 2 m), with its size
/// at 1 m and 4 m.
fn range_bias_sentence(bias: &RangeBias) -> String {
    let [offset_m, scale_error, quadratic_per_m] = bias.coefficients();
    let at = |d: f64| (offset_m + scale_error * d + quadratic_per_m * d * d) * 1000.0;
    let quadratic = if (quadratic_per_m * 4.0).abs() >= 0.001 {
        format!(" {:+.1} mm/m² · d²", quadratic_per_m * 1000.0)
    } else {
        String::new()
    };
    format!(
        "The real lidar reads {:+.1} mm {:+.2} % · d{quadratic} more than the scenario's range \
         bias declares ({:+.1} mm at 1 m, {:+.1} mm at 4 m): its calibration differs from the \
         declared one.",
        offset_m * 1000.0,
        scale_error * 100.0,
        at(1.0),
        at(4.0)
    )
}
