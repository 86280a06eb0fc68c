//! `lidar_dropout`: readings missing where the world says the unit would read, its returns too
//! weak to range. Fitted on the lidar's readings valid or not (`crate::dropout`), not on the
//! ranges.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, log, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;
use super::lidar_reflectivity::REFERENCE_REFLECTIVITY;

/// `lidar_dropout`.
pub(crate) struct LidarDropout;

impl Entry for LidarDropout {
    fn name(&self) -> &'static str {
        "lidar_dropout"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Lidar
    }

    /// A return weakens with the range, at grazing incidence and on darker surfaces.
    fn variables(&self) -> &'static [Variable] {
        &[
            Variable::Range,
            Variable::IncidenceAngle,
            Variable::Reflectivity,
        ]
    }

    /// Not: it changes which readings there are, not what they read.
    fn moves_readings(&self) -> bool {
        false
    }

    /// Not: its losses compose as chances do, not as half-loss ranges add.
    fn sizes_add(&self) -> bool {
        false
    }

    /// The self-test draws a half-loss range of [3, 5] m and a spread of [0.15, 0.4], both
    /// unscaled, on a diffuse surface (incidence power 1).
    fn params(&self) -> &'static [ParamSpec] {
        // The range at which half the returns are lost head-on on the reference surface over
        // 0.5–50 m on a log grid (a unit that loses half at 50 m loses nothing a room shows),
        // the spread of the returned log power over 0.05–2 (the loss rising from 12 % to 88 %
        // over a factor 1.1 to 55 of range). The loss chance is smooth in both, so the
        // Bernoulli likelihood is unimodal between grid points.
        //
        // How the power falls with the incidence, `cos^m θ`, over m in [0, 2] on a 0.5 grid:
        // 1 Lambert's diffuse surface (a triangulation unit's spot on paint or plaster), 0 a
        // unit whose losses the range alone sets (a gain set for its surfaces, a time-of-flight
        // unit's range gate), 2 a glossy surface whose lobe falls off the normal faster
        // (Phong, "Illumination for computer generated pictures", CACM 18(6), 1975).
        const DROPOUT: [ParamSpec; 3] = [
            log(
                "half_loss_range_m",
                "m",
                (0.5, 50.0),
                11,
                R::uniform(3.0, 5.0).unscaled(),
            )
            .form(),
            log(
                "log_power_spread",
                "",
                (0.05, 2.0),
                7,
                R::uniform(0.15, 0.4).unscaled(),
            )
            .form(),
            lin(
                "incidence_power",
                "",
                (0.0, 2.0),
                5,
                R::zero().around(1.0, 0.0, 2.0),
            )
            .form(),
        ];
        &DROPOUT
    }

    fn absent(&self, _: f64) -> Vec<f64> {
        // Half the returns lost only at the search's far end, on a diffuse surface.
        vec![50.0, 0.3, 1.0]
    }

    /// Half the returns lost nearer than 40 m head-on (at the search's far end of 50 m a
    /// room's readings are lost only in the logistic's tail, which the spread alone sets).
    /// Whether it loses enough readings to matter is the size's to say (`dropout::earns_place`):
    /// a long-range unit that loses half its returns beyond 6 m on a building's corridors,
    /// most of them at grazing incidence, is fitted losing half head-on at 28 m.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 10.0)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        effects.lidar_dropout = Some(scenario::LidarDropout {
            half_loss_range_m: p(0),
            log_power_spread: p(1),
            reference: REFERENCE_REFLECTIVITY,
            incidence_power: params.get(2).copied().unwrap_or(1.0),
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        let incidence_power = params.get(2).copied().unwrap_or(1.0);
        // Within half the fit's 0.5 grid step of a form.
        let by_range_alone = incidence_power < 0.25;
        let nearer = if by_range_alone {
            "whatever the incidence (the range alone sets the loss: the shape differs from the \
             catalogue's diffuse surface), and nearer on darker surfaces"
                .to_string()
        } else if (incidence_power - 1.0).abs() < 0.25 {
            "nearer at grazing incidence and on darker surfaces".to_string()
        } else {
            format!(
                "nearer at grazing incidence (the power falling as cos^{incidence_power:.1} of \
                 it: the shape differs from the catalogue's diffuse surface) and on darker \
                 surfaces"
            )
        };
        let head_on = if by_range_alone { "" } else { " head-on" };
        format!(
            "The simulated lidar reads every surface within its range; the real one loses \
             returns too weak to range: half of them at {:.1} m{head_on} on a surface of \
             reflectivity {REFERENCE_REFLECTIVITY}, {nearer} ({}from 12 % lost at {:.1} m to \
             88 % at {:.1} m).",
            p(0),
            if by_range_alone { "" } else { "head-on, " },
            p(0) * (-p(1)).exp(),
            p(0) * p(1).exp()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sentence says the loss's form: by the range alone (no "head-on"), the catalogue's
    /// diffuse surface (no departure said), a glossy one's power.
    #[test]
    fn the_sentence_says_how_the_loss_depends_on_the_incidence() {
        let said = |m: f64| LidarDropout.explanation(&[4.0, 0.3, m], 0.0);
        let by_range = said(0.1);
        assert!(by_range.contains("whatever the incidence"), "{by_range}");
        assert!(!by_range.contains("head-on"), "{by_range}");
        let diffuse = said(1.0);
        assert!(diffuse.contains("4.0 m head-on"), "{diffuse}");
        assert!(!diffuse.contains("shape differs"), "{diffuse}");
        let glossy = said(2.0);
        assert!(
            glossy.contains("cos^2.0") && glossy.contains("shape differs"),
            "{glossy}"
        );
    }
}
