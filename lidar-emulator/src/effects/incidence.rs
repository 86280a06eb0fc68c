//! `lidar_incidence_angle`: the range error grows as the beam meets a surface obliquely.
//!
//! Derivation (beam footprint). A beam of angular half-width γ meeting a plane at incidence θ
//! (the angle between the beam and the surface normal) at range d lights a footprint whose edges
//! lie at ranges `d cos γ / cos(θ ± γ) ≈ d (1 ± γ tan θ)`: the footprint spans `2 γ d tan θ` in
//! depth, nothing at normal incidence and without bound towards grazing. A range finder reports
//! the centroid of the returned light, and that light is not spread evenly over the footprint
//! (its near half returns more: Lambert's cosine and 1/r², and the triangulation receiver's spot
//! image is skewed), so the reported range sits a fixed fraction of the footprint's depth from
//! its centre: `Δd = κ d tan θ`. κ lumps the divergence and the asymmetry; it is the unit's own,
//! to be fitted. A collimated beam (a laser spot a few millimetres wide whatever the range, as
//! the XV-11's over its few metres) lights a footprint of fixed width w, `w tan θ` deep, and its
//! centroid sits `c tan θ` off for any range, c a fraction of w. The model is both,
//! `Δd = (κ d + c) tan θ`. Measurements of terrestrial scanners show the same growth of the
//! error with obliquity (Soudarissanane, Lindenbergh, Menenti, Teunissen, "Scanning geometry: influencing
//! factor on the quality of terrestrial laser scanning points", ISPRS J. Photogramm. Remote
//! Sens. 66 (2011)).
//!
//! The fixed fraction is the first-order case. Where the asymmetry of the returned light across
//! the footprint itself grows with the footprint's depth (a Gaussian spot whose near edge is
//! both nearer and met less obliquely: the irradiance's gradient along the footprint is ∝ tan θ),
//! the centroid's offset is the depth times an asymmetry ∝ tan θ, `∝ tan² θ = 1/cos² θ − 1`;
//! a receiver that resolves the spot's skew only once the footprint outgrows a pixel stays
//! near zero up to some angle and rises steeply past it. The model takes the power as a
//! parameter: `Δd = (κ d + c) tanᵖ θ`, p = 1 the footprint's depth.

use hilsim_sim::scenario::LidarIncidenceAngle;

/// Incidence beyond this is treated as this (tan 80° ≈ 5.7): at grazing incidence the footprint
/// model breaks down and the return is usually too weak to range anyway.
pub const MAX_INCIDENCE_DEG: f64 = 80.0;

/// `tan θ` for a beam meeting a surface with `cos θ = cos_incidence`, θ capped at
/// [`MAX_INCIDENCE_DEG`].
#[must_use]
pub fn tan_incidence(cos_incidence: f64) -> f64 {
    let cap = MAX_INCIDENCE_DEG.to_radians();
    let theta = cos_incidence.abs().min(1.0).acos().min(cap);
    theta.tan()
}

/// The range error `(κ d + c) tanᵖ θ`, metres, of a beam at range `d_m` meeting a surface with
/// `cos θ = cos_incidence`, for `effect`'s κ (`coefficient`), c (`collimated_m`) and p
/// (`exponent`).
///
/// ```
/// use hilsim_lidar_emulator::effects::incidence_error_m;
/// use hilsim_sim::scenario::LidarIncidenceAngle;
/// let diverging = LidarIncidenceAngle { coefficient: 0.01, collimated_m: 0.0, exponent: 1.0 };
/// // 45°: tan θ = 1, so 1 % of 2 m.
/// let e = incidence_error_m(&diverging, 2.0, std::f64::consts::FRAC_1_SQRT_2);
/// assert!((e - 0.02).abs() < 1e-12);
/// assert_eq!(incidence_error_m(&diverging, 2.0, 1.0), 0.0);
/// let collimated = LidarIncidenceAngle { coefficient: 0.0, collimated_m: 0.005, exponent: 1.0 };
/// let e = incidence_error_m(&collimated, 4.0, std::f64::consts::FRAC_1_SQRT_2);
/// assert!((e - 0.005).abs() < 1e-12);
/// // tan² θ = 3 at 60°.
/// let skewed = LidarIncidenceAngle { exponent: 2.0, ..collimated };
/// let e = incidence_error_m(&skewed, 4.0, 0.5);
/// assert!((e - 0.015).abs() < 1e-12);
/// ```
#[must_use]
pub fn incidence_error_m(effect: &LidarIncidenceAngle, d_m: f64, cos_incidence: f64) -> f64 {
    let tan = tan_incidence(cos_incidence);
    // `powf` of an exponent of 1 is exact, so the first-order model is unchanged by it.
    (effect.coefficient * d_m + effect.collimated_m) * tan.powf(effect.exponent)
}
