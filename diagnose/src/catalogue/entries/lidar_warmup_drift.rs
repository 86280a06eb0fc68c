//! `lidar_warmup_drift`: the lidar's range bias drifts while the unit warms up from power-on.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{weighted_size, Entry, Variable};
use super::super::params::{lin, log, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `lidar_warmup_drift`.
pub(crate) struct LidarWarmupDrift;

/// The stretch β searched, `2^{±1.5}`: a settling of β = 0.35 or of 2.83 departs from one
/// mass's by at most 0.26 of the drift at power-on (`max_t |e^{−(t/τ)^β} − e^{−t/τ}|`), a
/// shape in time still a warm-up's rather than another mechanism's.
const STRETCH_LEAST: f64 = 0.353_553_390_593_273_8;
/// See [`STRETCH_LEAST`].
const STRETCH_MOST: f64 = 2.828_427_124_746_19;

impl Entry for LidarWarmupDrift {
    fn name(&self) -> &'static str {
        "lidar_warmup_drift"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Lidar
    }

    /// Its quadratic term grows with the range.
    fn variables(&self) -> &'static [Variable] {
        &[Variable::TimeSincePowerOn, Variable::Range]
    }

    /// The self-test draws k ±[0.004, 0.01] /m with τ in [5, 20] s (unscaled), on a fair coin
    /// moved whole to its constant term (the same scored error; `draw_values`).
    fn params(&self) -> &'static [ParamSpec] {
        // The warm-up's constant term over ±0.1 m on a 5 cm grid (a unit's drift is
        // centimetres at most), Nelder–Mead refining the three together. The self-test draws
        // its size as the quadratic term's (`draw_values` puts it all in one or the other).
        const WARMUP: [ParamSpec; 4] = [
            lin(
                "coefficient_per_m",
                "1/m",
                (-0.05, 0.05),
                7,
                R::uniform(0.004, 0.01).signed(),
            ),
            log(
                "time_constant_s",
                "s",
                (1.0, 1000.0),
                6,
                R::uniform(5.0, 20.0).unscaled(),
            )
            .form(),
            lin("offset_m", "m", (-0.1, 0.1), 5, R::zero()),
            // The settling's stretch β of `e^{−(t/τ)^β}` on a log grid through 1 (one thermal
            // mass): below, masses of spread time constants, whose sum settles fast at first
            // and slowly at the end (Glennie and Lichti 2011 saw such a warm-up); above, a
            // settling that ends sooner than one mass's, as a thermostat's does. The catalogue
            // reality keeps one mass.
            log(
                "stretch",
                "",
                (STRETCH_LEAST, STRETCH_MOST),
                3,
                R::zero().around(1.0, 1.0, 1.0),
            )
            .form(),
        ];
        &WARMUP
    }

    /// The drift is searched in its quadratic term with τ and in its constant term with τ: a
    /// drift all in one term (as a unit's pointing or its housing makes it, or another
    /// simulator's "bias drift") sits between the joint grid's coarse points but on that
    /// shape's own grid, and Nelder–Mead over all three from the joint grid was measured to
    /// stop at τ's bound (an independent reality's k = −0.0044 /m, τ = 12.8 s fitted as
    /// τ = 1 s).
    ///
    /// Against a trajectory estimated from the lidar itself the constant term is fitted too.
    /// The scan matching takes part of a range offset every beam shares into the pose (it
    /// weighs the near readings most, and the pose shifts away from them), and the realignment
    /// gives it back (`realign_lidar` in the diagnosis settles each term apart, by rounds of
    /// estimating the path under it, and keeps the one the lidar's held-out readings favour).
    /// Held at zero, a warm-up drawn in that term would be fitted in its quadratic term and its
    /// early position error named as a wheel radius or slip; a drift that does not settle
    /// within the run, which the term freed took up beside a concealed reflectivity, is not
    /// named (`select::earns_place`).
    fn shapes(&self) -> &'static [&'static [usize]] {
        &[&[0, 1], &[2, 1]]
    }

    /// The settling's stretch β, freed when the best term is refined against a recorded path
    /// (from one mass, the grid's shapes being one mass's). Along a path estimated from the
    /// lidar it is held at one mass: the path takes up the drift where most scans see the
    /// walls, so what is left of it in time is not the settling's shape, and a free β follows
    /// that instead.
    fn refined_against_recorded_path(&self) -> &'static [usize] {
        &[3]
    }

    /// The time constant and the stretch.
    fn form_params(&self) -> &'static [usize] {
        &[1, 3]
    }

    /// Its two terms are settled apart: the path first takes up a constant term, the fit then
    /// reads the near walls' shift as `k d²`, and rounds that follow both at once move the
    /// drift between them instead of settling it.
    fn shapes_settled_apart(&self) -> bool {
        true
    }

    /// Where its mean settling time is at most `span_s`: `τ Γ(1/β) / β` for the stretched
    /// settling `e^{−(t/τ)^β}` (the Kohlrausch–Williams–Watts relaxation's mean time; Lindsey
    /// and Patterson, J. Chem. Phys. 73, 1980), τ itself for one mass. A settling spread as
    /// far as the family goes (β = 0.35) takes 4.8 τ on average: at τ of a thousand seconds
    /// it is a drift over the whole of an hour's log, not a warm-up.
    fn settles_within(&self, params: &[f64], span_s: f64) -> bool {
        let stretch = params
            .get(3)
            .copied()
            .unwrap_or(1.0)
            .clamp(STRETCH_LEAST, STRETCH_MOST);
        params
            .get(1)
            .is_some_and(|tau_s| tau_s * libm::tgamma(1.0 / stretch) / stretch <= span_s)
    }

    /// Absent at k = 0 for any τ.
    fn absent(&self, _: f64) -> Vec<f64> {
        vec![0.0, 10.0, 0.0, 1.0]
    }

    /// k: 0.00025 /m, 1 mm at 2 m at power-on, and its constant term 1 mm.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.000_25), (2, 0.001)]
    }

    /// Its range error at 2 m at power-on is `c + k (2 m)²`.
    fn size_terms(&self) -> &'static [(usize, f64)] {
        &[(0, 4.0), (2, 1.0)]
    }

    /// Its range error at 2 m at power-on, `c + k (2 m)²` ([`Entry::size_terms`]), which
    /// either term alone may carry.
    fn scored(&self, params: &[f64]) -> f64 {
        weighted_size(self, params)
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        effects.lidar_warmup_drift = Some(scenario::LidarWarmupDrift {
            coefficient_per_m: p(0),
            time_constant_s: p(1).max(1e-3),
            offset_m: p(2),
            stretch: params
                .get(3)
                .copied()
                .unwrap_or(1.0)
                .clamp(STRETCH_LEAST, STRETCH_MOST),
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        let stretch = params.get(3).copied().unwrap_or(1.0);
        // A tenth of the grid's step (a factor 2^1.5) from one mass.
        let settling = if stretch.is_finite() && stretch.ln().abs() > 0.1 {
            format!(
                "settling as e^(−(t/τ)^{stretch:.2}) with τ = {:.0} s, {} than one thermal \
                 mass's: the shape differs from the catalogue's",
                p(1),
                if stretch < 1.0 {
                    "faster at first and slower at the end"
                } else {
                    "slower at first and sooner done"
                }
            )
        } else {
            format!("settling with a {:.0} s time constant", p(1))
        };
        format!(
            "The simulated lidar is warm from power-on; the real one's range bias drifts as it \
             warms up ({:+.1} mm at 0.5 m and {:+.1} mm at 4 m at power-on, {settling}).",
            (p(2) + p(0) * 0.25) * 1000.0,
            (p(2) + p(0) * 16.0) * 1000.0,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::{LidarWarmupDrift, STRETCH_LEAST};
    use crate::catalogue::Entry;

    /// One mass settles on average in τ; a settling spread as far as the family goes takes
    /// Γ(1/β)/β ≈ 4.8 τ, so at τ = 1000 s it outlasts a 22-minute log and not a 75-minute one
    /// at τ = 300 s.
    #[test]
    fn a_warmup_settles_within_a_span_by_its_mean_settling_time() {
        let w = LidarWarmupDrift;
        let at = |tau_s: f64, stretch: f64| vec![0.005, tau_s, 0.0, stretch];
        assert!(w.settles_within(&at(250.0, 1.0), 1339.0));
        assert!(w.settles_within(&at(1000.0, 1.0), 1339.0));
        assert!(!w.settles_within(&at(1000.0, STRETCH_LEAST), 1339.0));
        assert!(!w.settles_within(&at(300.0, STRETCH_LEAST), 1339.0));
        assert!(w.settles_within(&at(300.0, STRETCH_LEAST), 2684.0));
        // Held at one mass when the stretch is not fitted.
        assert!(w.settles_within(&[0.005, 60.0], 60.0));
    }
}
