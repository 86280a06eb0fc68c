//! Number and text formatting shared by the renderers (the chart module's, plus millimetres).

pub(super) use hilsim_report::svg::{escape, fmt_sig};

/// Metres as millimetres with one decimal, "—" when not finite.
pub(super) fn mm(v: f64) -> String {
    if v.is_finite() {
        format!("{:.1} mm", v * 1000.0)
    } else {
        "—".to_string()
    }
}

/// What a fit's RMSEs are of, when it is not the plain residual: " (each reading given the
/// readings before)" for the encoders along an estimated path.
pub(super) fn given_past(f: &crate::explain::CandidateFit) -> &'static str {
    if f.rmse_given_past {
        " (each reading given the readings before)"
    } else {
        ""
    }
}
