//! `lidar_incidence_angle`: the lidar's range error grows with the angle at which the beam
//! meets the surface.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{weighted_size, Entry, Variable};
use super::super::params::{lin, log, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `lidar_incidence_angle`.
pub(crate) struct LidarIncidenceAngle;

impl Entry for LidarIncidenceAngle {
    fn name(&self) -> &'static str {
        "lidar_incidence_angle"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Lidar
    }

    /// A diverging beam's term grows with the range too.
    fn variables(&self) -> &'static [Variable] {
        &[Variable::IncidenceAngle, Variable::Range]
    }

    /// The self-test draws κ ±[0.01, 0.03] (its power of `tan θ` 1), on a fair coin moved whole
    /// to its collimated term (the same scored error; `draw_values`).
    fn params(&self) -> &'static [ParamSpec] {
        // The collimated beam's term over ±0.2 m at 45° on a 2 cm grid: κ's window at 2 m, as
        // the self-test draws its size as κ's there (`draw_values` puts it all in one or the
        // other), so that a draw is never past the search's edge.
        // The power of tan θ over [0.5, 4] on a √2 grid through 1 (the footprint's depth) and 2
        // (an asymmetry that grows with it, `1/cos² θ − 1`): the form of the growth, which
        // the self-test's catalogue reality does not vary.
        const INCIDENCE: [ParamSpec; 3] = [
            lin(
                "coefficient",
                "",
                (-0.1, 0.1),
                11,
                R::uniform(0.01, 0.03).signed(),
            ),
            lin("collimated_m", "m", (-0.2, 0.2), 21, R::zero()),
            log(
                "exponent",
                "",
                (0.5, 4.0),
                7,
                R::zero().around(1.0, 0.5, 4.0),
            )
            .form(),
        ];
        &INCIDENCE
    }

    /// The incidence's two terms, a diverging beam's `κ d tanᵖ θ` and a collimated one's
    /// `c tanᵖ θ`, are alternatives: searched each alone (each with the power p of its growth)
    /// and not refined together (see [`Entry::shapes_refined_together`]).
    fn shapes(&self) -> &'static [&'static [usize]] {
        &[&[0, 2], &[1, 2]]
    }

    /// The power of `tan θ`.
    fn form_params(&self) -> &'static [usize] {
        &[2]
    }

    /// Not refined together: a beam diverges or is collimated over a unit's range, and the two
    /// terms together trade against each other (an independent simulator's range-independent
    /// error, fitted as κ = −0.0024 with c = 8 mm, raised the ranges' RMSE where c alone lowered
    /// it).
    fn shapes_refined_together(&self) -> bool {
        false
    }

    /// Absent at κ = c = 0 for any power of `tan θ` (held at 1, the catalogue's first-order
    /// form).
    fn absent(&self, _: f64) -> Vec<f64> {
        vec![0.0, 0.0, 1.0]
    }

    /// κ: 0.001 is 1 mm per metre at 45°, and its collimated term 1 mm at 45°.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.001), (1, 0.001)]
    }

    /// Its range error at 2 m and 45° is `c + κ 2 m`, which either term alone may carry.
    fn size_terms(&self) -> &'static [(usize, f64)] {
        &[(0, 2.0), (1, 1.0)]
    }

    /// Its range error at 2 m and 45°, `c + κ 2 m` ([`Entry::size_terms`]).
    fn scored(&self, params: &[f64]) -> f64 {
        weighted_size(self, params)
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        effects.lidar_incidence_angle = Some(scenario::LidarIncidenceAngle {
            coefficient: p(0),
            collimated_m: p(1),
            exponent: params.get(2).copied().unwrap_or(1.0),
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        format!(
            "The simulated lidar ranges every surface as if it met it head-on; the real one's \
             range error grows with the angle of incidence ({:+.1} mm at 45° at 1 m, {:+.1} mm \
             at 4 m{}).",
            (p(0) + p(1)) * 1000.0,
            (p(0) * 4.0 + p(1)) * 1000.0,
            incidence_form(p(2))
        )
    }
}

/// How the incidence's error grows past 45°, where its form departs from the catalogue's
/// first-order `tan θ` (the footprint's depth) by more than its grid resolves; else nothing.
fn incidence_form(exponent: f64) -> String {
    // A tenth of the fit's √2 grid step in the power.
    if !exponent.is_finite() || (exponent - 1.0).abs() < 0.04 {
        return String::new();
    }
    let pace = if exponent > 1.0 { "faster" } else { "slower" };
    format!(
        "; it grows as tan^{exponent:.2} θ, {pace} than the footprint's depth: the shape differs \
         from the catalogue's tan θ"
    )
}
