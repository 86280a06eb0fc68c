//! `lidar_dropout`: readings missing where the world says the unit would read, its returns too
//! weak to range. Fitted on the lidar's readings valid or not (`crate::dropout`), not on the
//! ranges.

use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{log, ParamSpec, SelfTestRange as R};
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
    /// unscaled.
    fn params(&self) -> &'static [ParamSpec] {
        // The range at which half the returns are lost head-on on the reference surface over
        // 0.5–50 m on a log grid (a unit that loses half at 50 m loses nothing a room shows),
        // the spread of the returned log power over 0.05–2 (the loss rising from 12 % to 88 %
        // over a factor 1.1 to 55 of range). The loss chance is smooth in both, so the
        // Bernoulli likelihood is unimodal between grid points.
        const DROPOUT: [ParamSpec; 2] = [
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
        ];
        &DROPOUT
    }

    fn absent(&self, _: f64) -> Vec<f64> {
        // Half the returns lost only at the search's far end.
        vec![50.0, 0.3]
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
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        format!(
            "The simulated lidar reads every surface within its range; the real one loses \
             returns too weak to range: half of them at {:.1} m head-on on a surface of \
             reflectivity {REFERENCE_REFLECTIVITY}, nearer at grazing incidence and on darker \
             surfaces (head-on, from 12 % lost at {:.1} m to 88 % at {:.1} m).",
            p(0),
            p(0) * (-p(1)).exp(),
            p(0) * p(1).exp()
        )
    }
}
