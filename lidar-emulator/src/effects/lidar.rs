//! The lidar's effects together: which are on, and what one beam ranges with them.

use hilsim_sim::scenario::{Effects, LidarIncidenceAngle, LidarWarmupDrift, RangeBias};
use hilsim_sim::{RayHit, World};

use super::incidence::incidence_error_m;
use super::mixed_pixels::footprint_range_m;
use super::range_bias::real_bias;
use super::reflectivity::range_walk_m;
use super::warmup::warmup_error_m;

/// The lidar's effects, with their parameters; `None`: off.
///
/// ```
/// use hilsim_lidar_emulator::effects::LidarEffects;
/// let nominal = LidarEffects::default();
/// assert!(nominal.is_nominal());
/// use hilsim_sim::scenario::LidarIncidenceAngle;
/// let incidence = LidarIncidenceAngle { coefficient: 0.01, collimated_m: 0.0, exponent: 1.0 };
/// let tilted = LidarEffects { incidence: Some(incidence), ..LidarEffects::default() };
/// assert!(!tilted.is_nominal());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LidarEffects {
    /// `lidar_incidence_angle`: `(κ d + c) tanᵖ θ`.
    pub incidence: Option<LidarIncidenceAngle>,
    /// `lidar_reflectivity`: (c metres, ρ_ref) of `c (ρ_ref / ρ − 1)`.
    pub reflectivity: Option<(f64, f64)>,
    /// `lidar_mixed_pixels`: the beam's half-width, radians.
    pub mixed_half_width_rad: Option<f64>,
    /// `lidar_warmup_drift`: `(c + k d²) e^{−t/τ}`.
    pub warmup: Option<LidarWarmupDrift>,
    /// `lidar_range_bias`: `c + s d + q d²` added to the declared bias polynomial.
    pub range_bias: Option<RangeBias>,
}

/// What one beam returns before the range model: the centre ray's hit and the range the
/// footprint measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamReturn {
    /// The centre ray's hit (the true range along the beam, the surface, its normal).
    pub hit: RayHit,
    /// `|cos θ|` of the centre ray on its surface.
    pub cos_incidence: f64,
    /// The range the footprint measures: the centre's distance, or the mixed-pixel centroid.
    pub footprint_m: f64,
}

impl LidarEffects {
    /// The lidar effects a scenario switches on.
    #[must_use]
    pub fn from_scenario(effects: &Effects) -> Self {
        Self {
            incidence: effects.lidar_incidence_angle,
            reflectivity: effects
                .lidar_reflectivity
                .map(|e| (e.coefficient_m, e.reference)),
            mixed_half_width_rad: effects
                .lidar_mixed_pixels
                .map(|e| e.half_width_deg.to_radians()),
            warmup: effects.lidar_warmup_drift,
            range_bias: effects.lidar_range_bias,
        }
    }

    /// Whether every effect is off.
    #[must_use]
    pub fn is_nominal(&self) -> bool {
        *self == Self::default()
    }

    /// The unit's bias polynomial (eq. 2's alpha) given the `declared` one: with
    /// `lidar_range_bias`'s difference added when it is on.
    #[must_use]
    pub fn bias(&self, declared: &[f64]) -> Vec<f64> {
        real_bias(declared, self.range_bias.as_ref())
    }

    /// The beam along `heading` from `origin`: `None` when its centre ray hits nothing within
    /// `max_m`.
    #[must_use]
    pub fn beam_return(
        &self,
        world: &World,
        origin: [f64; 2],
        heading: f64,
        max_m: f64,
    ) -> Option<BeamReturn> {
        let (sin, cos) = heading.sin_cos();
        let hit = world.cast_ray_along(origin, [cos, sin], max_m)?;
        let cos_incidence = (hit.normal[0] * cos + hit.normal[1] * sin).abs();
        let footprint_m = self
            .mixed_half_width_rad
            .and_then(|h| footprint_range_m(world, origin, heading, h, max_m, &hit))
            .unwrap_or(hit.distance);
        Some(BeamReturn {
            hit,
            cos_incidence,
            footprint_m,
        })
    }

    /// The distance the unit ranges (fed to the range model, eq. 2) for a beam that returned
    /// `ret`, `t_s` seconds after power-on: the footprint's range plus the incidence, walk and
    /// warm-up errors that are switched on. Exactly `ret.footprint_m` when all are off.
    #[must_use]
    pub fn ranged_m(&self, ret: &BeamReturn, t_s: f64) -> f64 {
        let mut d = ret.footprint_m;
        let true_d = ret.hit.distance;
        if let Some(incidence) = &self.incidence {
            d += incidence_error_m(incidence, true_d, ret.cos_incidence);
        }
        if let Some((c, reference)) = self.reflectivity {
            d += range_walk_m(c, reference, ret.hit.reflectivity);
        }
        if let Some(drift) = &self.warmup {
            d += warmup_error_m(drift, true_d, t_s);
        }
        d
    }
}
