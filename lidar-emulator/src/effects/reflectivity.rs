//! `lidar_reflectivity`: the range bias depends on the target's material (range walk).
//!
//! Derivation. A range finder times (or locates) the return where its signal crosses a fixed
//! detection level. A return of amplitude A whose leading edge rises over a fixed width crosses
//! a level L at a fraction L/A of that width, so the detected position "walks" by an amount
//! proportional to 1/A: the classic walk error of threshold detection (e.g. Kostamovaara et al.,
//! the timing discriminators of pulsed time-of-flight range finders). The amplitude is
//! proportional to the surface's diffuse reflectivity ρ, and a unit calibrated on a surface of
//! reflectivity ρ_ref has no walk there, so `Δd = c (ρ_ref / ρ − 1)`: dark surfaces read long
//! for c > 0. The unit's automatic exposure compensates the fall-off with distance (the strength
//! falls only as d^-0.7, see `lidar.rs`), so the walk is modelled as a function of the material
//! alone; the incidence angle is the separate `lidar_incidence_angle` effect.

/// The range walk `c (ρ_ref / ρ − 1)`, metres, on a surface of reflectivity `reflectivity`.
///
/// ```
/// use hilsim_lidar_emulator::effects::range_walk_m;
/// assert_eq!(range_walk_m(0.01, 0.8, 0.8), 0.0);
/// assert!((range_walk_m(0.01, 0.8, 0.08) - 0.09).abs() < 1e-12); // a dark door: 9 cm long
/// ```
#[must_use]
pub fn range_walk_m(coefficient_m: f64, reference: f64, reflectivity: f64) -> f64 {
    coefficient_m * (reference / reflectivity.max(1e-3) - 1.0)
}
