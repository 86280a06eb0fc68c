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
        RmseOver::PathSpans => " (the lidar-matched path's spans against the encoders')",
        RmseOver::TruthSpans => " (the truth's spans between its poses against the encoders')",
    }
}

/// What the held-out RMSEs are counted over.
pub(super) fn heldout_unit(f: &crate::explain::CandidateFit) -> &'static str {
    match f.rmse_over {
        RmseOver::PathSteps => "steps",
        RmseOver::PathSpans | RmseOver::TruthSpans => "spans",
        RmseOver::Readings | RmseOver::ReadingsGivenPast => "readings",
    }
}

/// Why a fitted parameter `i` of `f` has a standard error of exactly 0: held at its absence
/// by the fit, or a form the fit moved off its absence where the likelihood's curvature gives
/// no error (a form at its range's end, a centroid share of 1), whose error is then given for
/// the size alone.
pub(super) fn without_error(f: &crate::explain::CandidateFit, i: usize) -> &'static str {
    let absent = f.effect.absent(0.0);
    let moved = f.params.get(i) != absent.get(i);
    if moved && f.effect.form_params().contains(&i) {
        "its form, no s.e."
    } else {
        "held"
    }
}

#[cfg(test)]
mod tests {
    use super::without_error;
    use crate::catalogue::{Effect, Sensor};
    use crate::explain::CandidateFit;

    fn sonar_cone(params: Vec<f64>) -> CandidateFit {
        CandidateFit {
            effect: Effect::SonarBeamWidth,
            sensor: Sensor::Sonar,
            param_sd: vec![0.01, 0.0],
            params,
            train_gain: 150.0,
            heldout_gain: 130.0,
            bic_gain: 120.0,
            rmse_before: 0.5,
            rmse_after: 0.01,
            noise_floor: 0.008,
            heldout_n: 200,
            rmse_over: crate::RmseOver::ReadingsGivenPast,
            heldout_ll_per_reading: 4.0,
            size_m: 1.0,
            size_noise_m: 0.002,
            floor_multiple: 4.0,
            scaled_rmse: (1.2, 1.0),
            seen_until_s: 60.0,
        }
    }

    /// A centroid share fitted at 1 (no curvature past its range's end) is a form found, not a
    /// parameter held; one left at the nearest echo is held.
    #[test]
    fn a_form_moved_off_its_absence_is_not_called_held() {
        assert_eq!(
            without_error(&sonar_cone(vec![17.3, 1.0]), 1),
            "its form, no s.e."
        );
        assert_eq!(without_error(&sonar_cone(vec![17.3, 0.0]), 1), "held");
    }
}
