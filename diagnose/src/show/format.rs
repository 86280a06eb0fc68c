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
