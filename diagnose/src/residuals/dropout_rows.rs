//! The lidar's readings as reads and losses: every reading, valid or not, where the world says
//! the unit would read (a surface within its range, well inside its limits, returning a signal
//! the nominal unit ranges), with whether it was lost and the variables a loss depends on.
//! The ranges' residuals keep the valid readings only; a missing reading is its own datum here.

use hilsim_lidar_emulator::lidar::{expected_strength, STRENGTH_INVALID_BELOW};

use super::data::Context;
use super::sensors::{lidar_queries, split, LIMIT_GUARD_TRUE_SD};
use crate::physics::Hypothesis;

/// How many times the nominal unit's weak-signal threshold a reading's expected strength must
/// be for its loss to count: the nominal unit already loses returns below the threshold (dark,
/// far, grazing), and its strength scatters by 10 % from reading to reading, so at twice the
/// threshold it loses none (ten standard deviations).
const NOMINAL_STRENGTH_MARGIN: f64 = 2.0;

/// The rows: one per reading where the world says the unit would read.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct DropoutRows {
    /// The true range, metres.
    pub range_m: Vec<f64>,
    /// `|cos θ|` of the incidence on the surface.
    pub cos_incidence: Vec<f64>,
    /// The surface's reflectivity.
    pub reflectivity: Vec<f64>,
    /// Whether the unit reported the reading invalid.
    pub lost: Vec<bool>,
    /// Whether the row is held out (the ranges' split: alternate blocks by revolution).
    pub heldout: Vec<bool>,
    /// The revolution the reading belongs to: losses cluster within one (a dark wall, a pane
    /// of glass loses every beam that meets it).
    pub revolution: Vec<u64>,
}

/// The lidar's rows, `None` without a lidar. The range limits are the declared ones narrowed
/// to the valid readings' own extremes, as for the ranges (a unit whose maximum is shorter
/// than declared loses the readings beyond it, which is not a loss by power), and a row's
/// predicted reading (the bias polynomial's, not the true range: the limits are the reading's)
/// must lie six of its predicted standard deviations inside them.
pub(crate) fn dropout_rows(ctx: &Context<'_>) -> Option<DropoutRows> {
    let (Some(samples), Some(declared)) = (&ctx.recording.lidar, ctx.physics.declared().lidar)
    else {
        return None;
    };
    let taken: Vec<_> = samples.iter().filter(|s| s.t_s <= ctx.end_s).collect();
    let valid = |s: &hilsim_recording::LidarSample| !s.invalid && s.range_m > 0.0;
    let (lo, hi) = taken
        .iter()
        .filter(|s| valid(s))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s.range_m), hi.max(s.range_m))
        });
    let (min, max) = (declared.min_range_m.max(lo), declared.max_range_m.min(hi));
    let queries = lidar_queries(samples, &taken, declared.rpm);
    let nominal = ctx
        .physics
        .lidar(ctx.trajectory, &queries, &Hypothesis::nominal());
    let mut rows = DropoutRows::default();
    for ((s, q), p) in taken.iter().zip(&queries).zip(&nominal) {
        let (Some(d), Some(main)) = (
            p.true_range_m,
            p.components
                .iter()
                .max_by(|a, b| a.weight.total_cmp(&b.weight)),
        ) else {
            continue;
        };
        let guard = LIMIT_GUARD_TRUE_SD * main.sd_m;
        let reading = main.mean_m;
        let cos = p.incidence_deg.to_radians().cos().abs();
        let strong = expected_strength(d, cos, p.reflectivity)
            >= NOMINAL_STRENGTH_MARGIN * f64::from(STRENGTH_INVALID_BELOW);
        // A beam whose direction noise reaches another surface may return from that one (its
        // range, incidence and reflectivity), so its loss is not the centre ray's to explain.
        if reading < min + guard || reading > max - guard || !strong || p.near_edge {
            continue;
        }
        rows.range_m.push(d);
        rows.cos_incidence.push(cos);
        rows.reflectivity.push(p.reflectivity);
        rows.lost.push(!valid(s));
        rows.heldout.push(split(q.rev_start_s));
        rows.revolution.push(s.rev);
    }
    Some(rows)
}
