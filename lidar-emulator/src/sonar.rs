//! The sonar: the nearest echo anywhere inside its beam cone, with the EM paper's affine bias and
//! homoscedastic noise (Sec. II-C).

use hilsim_recording::SonarSample;
use hilsim_sim::{rng, scenario, StepState, World};

use crate::mount::Mount;
use crate::range_model::{ModelError, RangeModel};

/// Angular spacing of the rays that sample the cone, radians (0.25°). The nearest point of a
/// cylinder of radius r at distance d can fall between two rays; the range error is then at most
/// d·(1 − cos(δ/2)) ≈ 2.4e-6·d, far below any sonar's resolution.
const CONE_RAY_SPACING_RAD: f64 = 0.25 * std::f64::consts::PI / 180.0;

/// The emulated sonar.
pub struct Sonar {
    model: RangeModel,
    mount: Mount,
    ray_offsets: Vec<f64>,
    period_s: f64,
    max_range_m: f64,
    rng: rng::Rng,
    next_ping: u64,
}

impl Sonar {
    /// The sonar of a scenario, drawing from the run's `sonar` stream.
    ///
    /// # Errors
    /// A range model that makes no sense.
    pub fn new(config: &scenario::Sonar, seed: u64) -> Result<Self, ModelError> {
        let model = RangeModel::builder()
            .bias(&config.bias)
            .noise(&config.noise)
            .build()?;
        let half = config.half_angle_deg.to_radians();
        let per_side = (half / CONE_RAY_SPACING_RAD).ceil() as i64;
        let ray_offsets = if per_side == 0 {
            vec![0.0]
        } else {
            // Evenly spaced, both edges included.
            (-per_side..=per_side)
                .map(|k| half * k as f64 / per_side as f64)
                .collect()
        };
        Ok(Self {
            model,
            mount: config.mount.into(),
            ray_offsets,
            period_s: 1.0 / config.rate_hz,
            max_range_m: config.max_range_m,
            rng: rng::stream(seed, "sonar"),
            next_ping: 0,
        })
    }

    /// The nearest echo inside the cone from the sonar at `robot`, metres.
    #[must_use]
    pub fn nearest_echo(&self, world: &World, robot: &hilsim_sim::Pose) -> Option<f64> {
        let sensor = self.mount.in_world(robot);
        self.ray_offsets
            .iter()
            .filter_map(|off| {
                world.cast_ray([sensor.x, sensor.y], sensor.yaw + off, self.max_range_m)
            })
            .map(|hit| hit.distance)
            .min_by(f64::total_cmp)
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
            if let Some(d) = self.nearest_echo(world, &step.pose_at(t)) {
                // Echo timing resolves about a millimetre; report whole millimetres.
                let range = (self.model.sample(d, &mut self.rng) * 1000.0).round() / 1000.0;
                out.push(SonarSample {
                    t_s: t,
                    range_m: range.max(0.0),
                    true_range_m: Some(d),
                });
            }
        }
    }
}
