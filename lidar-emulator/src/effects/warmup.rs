//! `lidar_warmup_drift`: the range bias drifts with the time since power-on.
//!
//! Derivation. A triangulation range finder measures `d = f b / x`: focal length f, baseline b
//! between laser and camera, x the spot's image position (Konolige et al., "A low-cost laser
//! distance sensor", ICRA 2008, the XV-11's design). After power-on the laser and the board warm
//! up and the laser's pointing drifts by a small angle δ relative to the camera, shifting the
//! image by `f δ`: `d' = f b / (x + f δ) ≈ d − d² δ / b`, a range error growing with d². The
//! unit's temperature settles as a first-order thermal system, `T(t) = T∞ − (T∞ − T₀) e^{−t/τ}`,
//! and δ with it, so `Δd(t) = k d² e^{−t/τ}` with `k = −δ₀ / b` (per metre) and τ the thermal
//! time constant. The same warming expands the housing that holds the optics at a fixed
//! distance from the head's axis, the constant term of the range calibration: a constant
//! error `c e^{−t/τ}` settling with it (aluminium's 23 ppm/K over a 20 K rise moves a 50 mm
//! optical path by 0.02 mm; a unit whose calibration's constant drifts with its electronics'
//! timing, or a simulator that drifts the whole bias, shows centimetres). The model is the
//! drift of the range bias's constant and quadratic terms, `(c + k d²) e^{−t/τ}`; the linear
//! term's drift, the baseline's own expansion (`Δd = d Δb / b`, 0.05 % over 20 K: 2 mm at
//! 4 m), is below the unit's noise and left out. A unit of several thermal masses (a laser
//! diode on its board, the board in its housing) settles as a sum of exponentials; over the
//! spread of their time constants that sum is close to a stretched exponential `e^{−(t/τ)^β}`
//! with β < 1 (the Kohlrausch–Williams–Watts relaxation), and a heater held by a thermostat
//! settles faster than one mass at the end (β > 1): `stretch` is β, 1 one mass. Such drift of a range finder during its first
//! minutes of operation is well documented (e.g. Ye and Borenstein, "Characterization of a 2-D laser scanner for mobile robot
//! obstacle negotiation", ICRA 2002, on the SICK LMS 200).

use hilsim_sim::scenario::LidarWarmupDrift;

/// The range error `(c + k d²) e^{−(t/τ)^β}`, metres, `t_s` seconds after power-on, of `drift`
/// (c its `offset_m`, k its `coefficient_per_m`, τ its `time_constant_s`, β its `stretch`).
///
/// ```
/// use hilsim_lidar_emulator::effects::warmup_error_m;
/// use hilsim_sim::scenario::LidarWarmupDrift;
/// let drift = LidarWarmupDrift {
///     coefficient_per_m: 0.005,
///     time_constant_s: 20.0,
///     offset_m: 0.0,
///     stretch: 1.0,
/// };
/// assert!((warmup_error_m(&drift, 2.0, 0.0) - 0.02).abs() < 1e-12);
/// let later = warmup_error_m(&drift, 2.0, 20.0);
/// assert!((later - 0.02 / std::f64::consts::E).abs() < 1e-12);
/// let constant = LidarWarmupDrift { offset_m: 0.03, ..drift };
/// assert!((warmup_error_m(&constant, 2.0, 0.0) - 0.05).abs() < 1e-12);
/// // Stretched: the same e^{−1} at τ, less before it and more after it.
/// let stretched = LidarWarmupDrift { stretch: 0.5, ..drift };
/// assert!((warmup_error_m(&stretched, 2.0, 20.0) - later).abs() < 1e-12);
/// assert!(warmup_error_m(&stretched, 2.0, 5.0) < warmup_error_m(&drift, 2.0, 5.0));
/// assert!(warmup_error_m(&stretched, 2.0, 60.0) > warmup_error_m(&drift, 2.0, 60.0));
/// ```
#[must_use]
pub fn warmup_error_m(drift: &LidarWarmupDrift, d_m: f64, t_s: f64) -> f64 {
    (drift.offset_m + drift.coefficient_per_m * d_m * d_m)
        * (-(t_s.max(0.0) / drift.time_constant_s).powf(drift.stretch)).exp()
}
