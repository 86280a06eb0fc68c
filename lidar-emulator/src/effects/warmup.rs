//! `lidar_warmup_drift`: the range bias drifts with the time since power-on.
//!
//! Derivation. A triangulation range finder measures `d = f b / x`: focal length f, baseline b
//! between laser and camera, x the spot's image position (Konolige et al., "A low-cost laser
//! distance sensor", ICRA 2008, the XV-11's design). After power-on the laser and the board warm
//! up and the laser's pointing drifts by a small angle δ relative to the camera, shifting the
//! image by `f δ`: `d' = f b / (x + f δ) ≈ d − d² δ / b`, a range error growing with d². The
//! unit's temperature settles as a first-order thermal system, `T(t) = T∞ − (T∞ − T₀) e^{−t/τ}`,
//! and δ with it, so `Δd(t) = k d² e^{−t/τ}` with `k = −δ₀ / b` (per metre) and τ the thermal
//! time constant. Such drift of a range finder during its first minutes of operation is well
//! documented (e.g. Ye and Borenstein, "Characterization of a 2-D laser scanner for mobile robot
//! obstacle negotiation", ICRA 2002, on the SICK LMS 200).

/// The range error `k d² e^{−t/τ}`, metres, `t_s` seconds after power-on.
///
/// ```
/// use hilsim_lidar_emulator::effects::warmup_error_m;
/// assert!((warmup_error_m(0.005, 20.0, 2.0, 0.0) - 0.02).abs() < 1e-12);
/// let later = warmup_error_m(0.005, 20.0, 2.0, 20.0);
/// assert!((later - 0.02 / std::f64::consts::E).abs() < 1e-12);
/// ```
#[must_use]
pub fn warmup_error_m(coefficient_per_m: f64, time_constant_s: f64, d_m: f64, t_s: f64) -> f64 {
    coefficient_per_m * d_m * d_m * (-t_s.max(0.0) / time_constant_s).exp()
}
