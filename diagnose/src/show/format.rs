//! Number and text formatting shared by the renderers (the chart module's, plus millimetres).

pub(super) use hilsim_report::svg::{escape, fmt_sig};

use crate::explain::RmseOver;

/// Metres as millimetres with one decimal, "—" when not finite.
pub(super) fn mm(v: f64) -> String {
    if v.is_finite() {
        format!("{:.1} mm", v * 1000.0)
    } else {
        "—".to_string()
    }
}

/// What a fit's before and after are: its sensor's RMSE, or for an effect that moves no
/// reading (the lidar's dropout) the root mean square of each reading's loss (1 lost, 0 read)
/// less its chance of loss.
pub(super) fn fit_metric(f: &crate::explain::CandidateFit) -> &'static str {
    if f.effect.moves_readings() {
        "RMSE"
    } else {
        "loss RMS (lost less its chance)"
    }
}

/// One of a fit's before, after or floor values, in its metric's unit ([`fit_metric`]).
pub(super) fn fit_value(f: &crate::explain::CandidateFit, v: f64) -> String {
    if f.effect.moves_readings() {
        mm(v)
    } else {
        format!("{v:.3}")
    }
}

/// How much a fit changes its sensor's readings: metres, or for the dropout the share of
/// readings it loses beyond those lost at random where it loses most.
pub(super) fn fit_size(f: &crate::explain::CandidateFit) -> String {
    if f.effect.moves_readings() {
        mm(f.size_m)
    } else {
        format!("{:.1} % more lost where it loses most", f.size_m * 100.0)
    }
}

/// What a fit's RMSEs are of, when it is not the plain residual: each reading given the
/// readings before (the encoders along an estimated path), or the path's sideways motion.
pub(super) fn rmse_of(f: &crate::explain::CandidateFit) -> &'static str {
    match f.rmse_over {
        RmseOver::Readings => "",
        RmseOver::ReadingsGivenPast => " (each reading given the readings before)",
        RmseOver::PathSteps => {
            " (the lidar-matched path's sideways motion, which wheels cannot make)"
        }
    }
}

/// What the held-out RMSEs are counted over.
pub(super) fn heldout_unit(f: &crate::explain::CandidateFit) -> &'static str {
    match f.rmse_over {
        RmseOver::PathSteps => "steps",
        RmseOver::Readings | RmseOver::ReadingsGivenPast => "readings",
    }
}
