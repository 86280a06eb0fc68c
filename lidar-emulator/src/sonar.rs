//! The sonar: the nearest echo anywhere inside its beam cone (or, under
//! `[effects.sonar_beam_width] centroid_share`, partly the echoes' centroid across its main lobe),
//! with the EM paper's affine bias and homoscedastic noise (Sec. II-C).

use hilsim_recording::SonarSample;
use hilsim_sim::{rng, scenario, StepState, World};

use crate::effects::{real_bias, sonar_range_scale};
use crate::range_model::{ModelError, RangeModel};
use hilsim_recording::Mount;

/// Angular spacing of the rays that sample the cone, radians (0.25°). The nearest point of a
/// cylinder of radius r at distance d can fall between two rays; the range error is then at most
/// d·(1 − cos(δ/2)) ≈ 2.4e-6·d, far below any sonar's resolution.
const CONE_RAY_SPACING_RAD: f64 = 0.25 * std::f64::consts::PI / 180.0;

/// Rays across the main lobe's ±2 half-angles for the echoes' centroid (an integral of a
/// smooth weight: 64 intervals put a 0.1 m object's share within a sixty-fourth of the lobe).
const LOBE_RAYS: i64 = 64;

/// The main lobe a centroid is weighted by, and the share of the reading it makes.
#[derive(Debug, Clone)]
struct Lobe {
    /// The share of the reading that is the centroid, in (0, 1].
    share: f64,
    /// Each ray's offset from the axis (radians) and its amplitude, the Gaussian main lobe
    /// `e^{−2 φ²/φ₀²}` with φ₀ the cone's half-angle (Kuc and Siegel, "Physically based
    /// simulation model for acoustic sensor robot navigation", IEEE PAMI 9(6), 1987).
    rays: Vec<(f64, f64)>,
}

/// The emulated sonar.
pub struct Sonar {
    model: RangeModel,
    mount: Mount,
    ray_offsets: Vec<f64>,
    /// `[effects.sonar_beam_width] centroid_share` when above 0.
    lobe: Option<Lobe>,
    period_s: f64,
    max_range_m: f64,
    rng: rng::Rng,
    next_ping: u64,
    /// `[effects.sonar_speed_of_sound]`: c(calibrated) / c(air); 1 when off.
    range_scale: f64,
    /// `[effects.sensor_latency]`: how late each ping is stamped, seconds (0 when off).
    latency_s: f64,
}

impl Sonar {
    /// The sonar of a scenario, drawing from the run's `sonar` stream.
    ///
    /// # Errors
    /// A range model that makes no sense.
    pub fn new(config: &scenario::Sonar, seed: u64) -> Result<Self, ModelError> {
        Self::with_effects(config, &scenario::Effects::default(), seed)
    }

    /// The sonar of a scenario with the scenario's `[effects]` that concern it: the beam width
    /// (`sonar_beam_width` replaces the declared cone), the speed of sound (every range
    /// scaled by `c(calibrated_at_c) / c(air_temperature_c)`, see `effects`) and the range bias
    /// (`sonar_range_bias`'s polynomial added to the declared one).
    ///
    /// # Errors
    /// A range model that makes no sense.
    pub fn with_effects(
        config: &scenario::Sonar,
        effects: &scenario::Effects,
        seed: u64,
    ) -> Result<Self, ModelError> {
        let model = RangeModel::builder()
            .bias(real_bias(&config.bias, effects.sonar_range_bias.as_ref()))
            .noise(&config.noise)
            .build()?;
        let half_angle_deg = effects
            .sonar_beam_width
            .map_or(config.half_angle_deg, |b| b.half_angle_deg);
        let half = half_angle_deg.to_radians();
        let per_side = (half / CONE_RAY_SPACING_RAD).ceil() as i64;
        let ray_offsets = if per_side == 0 {
            vec![0.0]
        } else {
            // Evenly spaced, both edges included.
            (-per_side..=per_side)
                .map(|k| half * k as f64 / per_side as f64)
                .collect()
        };
        let share = effects.sonar_beam_width.map_or(0.0, |b| b.centroid_share);
        let lobe = (share > 0.0 && half > 0.0).then(|| Lobe {
            share: share.min(1.0),
            rays: (-LOBE_RAYS / 2..=LOBE_RAYS / 2)
                .map(|k| {
                    let u = 4.0 * k as f64 / LOBE_RAYS as f64;
                    (u * half, (-2.0 * u * u).exp())
                })
                .collect(),
        });
        Ok(Self {
            model,
            mount: config.mount.into(),
            ray_offsets,
            lobe,
            period_s: 1.0 / config.rate_hz,
            max_range_m: config.max_range_m,
            rng: rng::stream(seed, "sonar"),
            next_ping: 0,
            range_scale: effects.sonar_speed_of_sound.map_or(1.0, |e| {
                sonar_range_scale(e.air_temperature_c, e.calibrated_at_c)
            }),
            latency_s: effects.sensor_latency.map_or(0.0, |l| l.sonar_s),
        })
    }

    /// The nearest echo inside the cone from the sonar at `robot`, metres.
    #[must_use]
    pub fn nearest_echo(&self, world: &World, robot: &hilsim_sim::Pose) -> Option<f64> {
        let sensor = self.mount.in_world(robot);
        // Each ray only looks for an echo nearer than the nearest so far: the same minimum,
        // with most obstacles skipped.
        let mut nearest: Option<f64> = None;
        for off in &self.ray_offsets {
            let max_m = nearest.unwrap_or(self.max_range_m);
            if let Some(hit) = world.cast_ray([sensor.x, sensor.y], sensor.yaw + off, max_m) {
                if nearest.is_none_or(|n| hit.distance < n) {
                    nearest = Some(hit.distance);
                }
            }
        }
        nearest
    }

    /// The range the sonar's timing gives for its echoes from `robot`, metres: the nearest echo
    /// in the cone or, under a centroid share s, `(1 − s)` of it plus `s` of the echoes'
    /// centroid across the main lobe, each direction weighted by the lobe's amplitude and the
    /// echo's spreading `1/d²`. `None`: no echo within range.
    #[must_use]
    pub fn echo_m(&self, world: &World, robot: &hilsim_sim::Pose) -> Option<f64> {
        let Some(lobe) = &self.lobe else {
            return self.nearest_echo(world, robot);
        };
        let sensor = self.mount.in_world(robot);
        let (mut sum, mut weight) = (0.0, 0.0);
        for &(off, amplitude) in &lobe.rays {
            if let Some(hit) =
                world.cast_ray([sensor.x, sensor.y], sensor.yaw + off, self.max_range_m)
            {
                let d = hit.distance.max(1e-3);
                let w = amplitude / (d * d);
                sum += w * d;
                weight += w;
            }
        }
        if weight <= 0.0 {
            return self.nearest_echo(world, robot);
        }
        let centroid = sum / weight;
        // Timed wholly at the centroid, the nearest echo is not cast.
        if lobe.share >= 1.0 {
            return Some(centroid);
        }
        // An echo off the cone but in the lobe still times a reading, as its centre does.
        let nearest = self.nearest_echo(world, robot);
        Some(nearest.map_or(centroid, |n| (1.0 - lobe.share) * n + lobe.share * centroid))
    }

    /// The expected reading (noise-free, before millimetre rounding) for a nearest echo at
    /// `d_m`: the range model's mean of the range the echo's time gives.
    #[must_use]
    pub fn mean_reading_m(&self, d_m: f64) -> f64 {
        self.model.mean(d_m * self.range_scale)
    }

    /// The standard deviation of the reading for a nearest echo at `d_m`.
    #[must_use]
    pub fn reading_sd_m(&self, d_m: f64) -> f64 {
        self.model.std_dev(d_m * self.range_scale)
    }

    /// The range model.
    #[must_use]
    pub fn model(&self) -> &RangeModel {
        &self.model
    }

    /// Pings whose instant falls in `[step.t0, step.t1)`. A ping with no echo within range
    /// yields no sample (the sensor times out).
    pub fn observe(&mut self, world: &World, step: &StepState, out: &mut Vec<SonarSample>) {
        loop {
            let t = self.next_ping as f64 * self.period_s;
            if t >= step.t1 {
                return;
            }
            self.next_ping += 1;
            if t < step.t0 {
                continue;
            }
            if let Some(d) = self.echo_m(world, &step.pose_at(t)) {
                // Echo timing resolves about a millimetre; report whole millimetres.
                let ranged = d * self.range_scale;
                let range = (self.model.sample(ranged, &mut self.rng) * 1000.0).round() / 1000.0;
                out.push(SonarSample {
                    t_s: crate::effects::stamped_s(t, self.latency_s),
                    range_m: range.max(0.0),
                    true_range_m: Some(d),
                });
            }
        }
    }
}
