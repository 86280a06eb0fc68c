//! Number and text formatting shared by the renderers.

/// Metres as millimetres with one decimal, "—" when not finite.
pub(super) fn mm(v: f64) -> String {
    if v.is_finite() {
        format!("{:.1} mm", v * 1000.0)
    } else {
        "—".to_string()
    }
}

/// A number with about three significant figures.
pub(super) fn fmt_sig(v: f64) -> String {
    if !v.is_finite() {
        return "—".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 8) as usize;
    format!("{v:.digits$}")
}

/// `s` escaped for HTML and SVG text and attributes.
pub(super) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
