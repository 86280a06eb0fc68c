//! Expected readings: what each sensor of a scenario should report from a given pose, noise-free,
//! with the spread its declared noise gives — the predictive distribution of one reading. For
//! estimators that hold the simulation against data (`hilsim diagnose`); the emulator itself
//! draws from the same models (`lidar.rs`, `sonar.rs`, `odometer.rs`, `effects`).
//!
//! The lidar's beam direction is noisy (`angle_noise_deg`, σ_φ): on a surface met obliquely that
//! turns into range noise (and, at grazing incidence, a skewed one), and near an edge the beam
//! lands on one side or the other, or (with mixed pixels) anywhere between. On one surface the
//! prediction integrates over the direction with 7-point Gauss–Hermite quadrature (exact for
//! polynomials up to degree 13 in the angle error) into one Gaussian with the quadrature's mean
//! and variance. When those directions reach another surface (or a footprint mixes), the
//! reading is no smooth function of the direction: it is sampled every σ_φ/2 over ±3.5 σ_φ,
//! each direction one Gaussian of the mixture, widened by the reading's change to its
//! neighbours.
//! Readings are millimetres, so every spread includes the rounding's `1 mm / √12`.

use hilsim_sim::{scenario, Obstacle, Pose, World};
use smallvec::SmallVec;

use crate::effects::{BeamReturn, LidarEffects};
use crate::neato_packet::MAX_DISTANCE_MM;
use crate::normal::Gaussian;
use crate::range_model::{ModelError, RangeModel};
use crate::sonar::Sonar;
use hilsim_recording::Mount;

/// Variance of rounding to whole millimetres, m².
const ROUNDING_VAR_M2: f64 = 1e-6 / 12.0;

/// 7-point Gauss–Hermite nodes `x_k` for `∫ e^{−x²} f(x) dx` (Abramowitz & Stegun, table 25.10),
/// and the weights divided by √π, so that `E f(σ z) ≈ Σ w_k f(√2 σ x_k)` for z ~ N(0, 1).
const GH_NODES: [f64; 7] = [
    -2.651_961_356_835_233,
    -1.673_551_628_767_471,
    -0.816_287_882_858_965,
    0.0,
    0.816_287_882_858_965,
    1.673_551_628_767_471,
    2.651_961_356_835_233,
];
const GH_WEIGHTS: [f64; 7] = [
    0.000_548_268_855_972,
    0.030_757_123_967_586,
    0.240_123_178_605_013,
    0.457_142_857_142_857,
    0.240_123_178_605_013,
    0.030_757_123_967_586,
    0.000_548_268_855_972,
];

/// The obliquest incidence a surface's uncertainty is carried along the beam at: |cos θ| of
/// 87° (twenty times the normal's).
const MIN_SURFACE_COS: f64 = 0.05;

/// The variance a reading gets from the uncertainty of the surface it hit (a map's cell): the
/// surface anywhere within ±u of where the map puts it along its normal (variance u²/3),
/// carried along the beam (divided by |cos θ|).
fn surface_var_m2(ret: &BeamReturn) -> f64 {
    let u = ret.hit.surface_uncertainty_m / ret.cos_incidence.max(MIN_SURFACE_COS);
    u * u / 3.0
}

/// How far the world's own uncertainty can move the reading of a beam whose centre ray
/// returned `centre`: its surface moved ±u along the normal (`u / |cos θ|` along the beam), or
/// across the beam (the beam then meeting what lies beside: the change of range of the rays
/// `u` to either side at the hit). 0 for an exactly drawn surface.
fn world_reach_m(
    world: &World,
    origin: [f64; 2],
    heading: f64,
    centre: Option<&BeamReturn>,
    cast_limit_m: f64,
) -> f64 {
    let Some(c) = centre else {
        return 0.0;
    };
    let u = c.hit.surface_uncertainty_m;
    if u <= 0.0 {
        return 0.0;
    }
    let d = c.hit.distance.max(u);
    let along = u / c.cos_incidence.max(MIN_SURFACE_COS);
    let aside = (u / d).atan();
    let beside = [-aside, aside].map(|o| {
        world
            .cast_ray(origin, heading + o, cast_limit_m)
            .map_or(cast_limit_m - d, |h| (h.distance - d).abs())
    });
    along.max(beside[0]).max(beside[1])
}

/// Directions sampled across an edge: every half σ over ±3.5 σ of the direction noise (the
/// Gaussian's mass beyond is 5e-4).
const DENSE_NODES: usize = 15;
const DENSE_SPACING: f64 = 0.5;

/// A predictive mixture: one Gaussian per surface the beam can land on; held inline, as it is
/// one or two but at an edge, so that a prediction allocates nothing.
pub type Mixture = SmallVec<[Gaussian; 2]>;

/// The predictive distribution of one lidar reading, and the beam's geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct ExpectedLidar {
    /// The mixture a valid reading is drawn from: one Gaussian per surface the beam's direction
    /// noise can land on, truncated to the readings reported valid (a reading beyond a range
    /// limit is reported invalid instead); empty when no valid reading is expected (nothing
    /// hit, or out of range).
    pub components: Mixture,
    /// The centre ray's true range, when it hit something.
    pub true_range_m: Option<f64>,
    /// `|cos θ|` of the centre ray on its surface.
    pub cos_incidence: f64,
    /// What the centre ray hit.
    pub obstacle: Option<Obstacle>,
    /// The reflectivity of what it hit.
    pub reflectivity: f64,
    /// Whether the beam's direction noise (or its footprint) reaches another surface.
    pub near_edge: bool,
    /// How far the world's own uncertainty (a map's cells) can move the reading, metres; 0 in
    /// a world drawn exactly.
    pub world_reach_m: f64,
}

/// What a beam's quadrature directions see: the geometry of one reading, before any range
/// error. It depends on the pose, the angle and the beam's footprint (mixed pixels) only, so it
/// can be computed once and predicted from under many parameters of the other effects.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamNodes {
    /// (weight, what the direction returned) per quadrature node; one node, weight 1, without
    /// direction noise. The centre node is `centre`.
    pub nodes: Vec<(f64, Option<BeamReturn>)>,
    /// The index of the centre direction in `nodes`.
    pub centre: usize,
    /// Whether the nodes sample the direction densely (an edge within reach) rather than by
    /// Gauss–Hermite quadrature.
    pub dense: bool,
    /// How far the world's own uncertainty can move the reading, metres.
    pub world_reach_m: f64,
}

/// A beam's nodes as cast, on the stack (at most [`DENSE_NODES`]).
struct CastNodes {
    at: [(f64, Option<BeamReturn>); DENSE_NODES],
    len: usize,
    centre: usize,
    dense: bool,
    world_reach_m: f64,
}

impl CastNodes {
    fn nodes(&self) -> &[(f64, Option<BeamReturn>)] {
        &self.at[..self.len]
    }
}

/// Predicts the readings of a scenario's lidar with given effects.
#[derive(Debug, Clone)]
pub struct LidarPredictor {
    model: RangeModel,
    mount: Mount,
    angle_noise_rad: f64,
    min_m: f64,
    max_m: f64,
    cast_limit_m: f64,
    effects: LidarEffects,
}

impl LidarPredictor {
    /// The predictor of `config`'s lidar with `effects` switched on.
    ///
    /// # Errors
    /// A range model that makes no sense.
    pub fn new(config: &scenario::Lidar, effects: LidarEffects) -> Result<Self, ModelError> {
        Ok(Self {
            model: RangeModel::builder()
                .bias(effects.bias(&config.bias))
                .noise(&config.noise)
                .build()?,
            mount: config.mount.into(),
            angle_noise_rad: config.angle_noise_deg.to_radians(),
            // The unit rounds to millimetres first, then compares with its limits (`lidar.rs`):
            // a valid reading is one whose unrounded value lies within these.
            min_m: ((config.min_range_m * 1000.0).ceil() - 0.5) / 1000.0,
            max_m: ((config.max_range_m * 1000.0).floor() + 0.5) / 1000.0,
            // As the emulated unit casts (`Lidar::cast_limit_m`): the XV-11's 14-bit field, or a
            // log's scans' 16 bits.
            cast_limit_m: (config.max_range_m * 2.0).min(if config.schedule.is_some() {
                f64::from(u16::MAX) / 1000.0
            } else {
                f64::from(MAX_DISTANCE_MM) / 1000.0
            }),
            effects,
        })
    }

    /// The effects it predicts with.
    #[must_use]
    pub fn effects(&self) -> &LidarEffects {
        &self.effects
    }

    /// The lidar's origin and the beam's direction for `angle_deg` when the robot is at `robot`.
    fn beam(&self, robot: &Pose, angle_deg: f64) -> ([f64; 2], f64) {
        let sensor = self.mount.in_world(robot);
        ([sensor.x, sensor.y], sensor.yaw + angle_deg.to_radians())
    }

    /// The beam's quadrature directions and what each returns (with the footprint of mixed
    /// pixels when that effect is on).
    #[must_use]
    pub fn beam_nodes(&self, world: &World, robot: &Pose, angle_deg: f64) -> BeamNodes {
        let cast = self.cast_nodes(world, robot, angle_deg);
        BeamNodes {
            nodes: cast.nodes().to_vec(),
            centre: cast.centre,
            dense: cast.dense,
            world_reach_m: cast.world_reach_m,
        }
    }

    /// [`LidarPredictor::beam_nodes`] on the stack: a prediction that is not kept allocates
    /// nothing for its nodes.
    fn cast_nodes(&self, world: &World, robot: &Pose, angle_deg: f64) -> CastNodes {
        let mut out = self.cast_directions(world, robot, angle_deg);
        let (origin, heading) = self.beam(robot, angle_deg);
        let centre = out.at[out.centre].1;
        out.world_reach_m =
            world_reach_m(world, origin, heading, centre.as_ref(), self.cast_limit_m);
        out
    }

    /// The beam's directions and what each returns ([`LidarPredictor::cast_nodes`] without the
    /// world's reach).
    fn cast_directions(&self, world: &World, robot: &Pose, angle_deg: f64) -> CastNodes {
        let (origin, heading) = self.beam(robot, angle_deg);
        let cast = |o: f64| {
            self.effects
                .beam_return(world, origin, heading + o, self.cast_limit_m)
        };
        let mut out = CastNodes {
            at: [(0.0, None); DENSE_NODES],
            len: 1,
            centre: 0,
            dense: false,
            world_reach_m: 0.0,
        };
        if self.angle_noise_rad <= 0.0 {
            out.at[0] = (1.0, cast(0.0));
            return out;
        }
        let sigma = self.angle_noise_rad;
        for (k, (x, w)) in GH_NODES.iter().zip(GH_WEIGHTS).enumerate() {
            out.at[k] = (w, cast(std::f64::consts::SQRT_2 * sigma * x));
        }
        out.len = GH_NODES.len();
        out.centre = GH_NODES.len() / 2;
        let centre = out.at[out.centre].1.map(|r| r.hit.obstacle);
        let uniform = out.nodes().iter().all(|(_, r)| {
            r.map(|r| r.hit.obstacle) == centre && r.is_none_or(|r| r.footprint_m == r.hit.distance)
        });
        if uniform {
            return out;
        }
        // An edge (or a footprint that mixes) within reach of the direction noise: the reading
        // is no longer a smooth function of the direction, so sample it densely.
        let half = DENSE_NODES / 2;
        let mut total = 0.0;
        for k in 0..DENSE_NODES {
            let x = (k as f64 - half as f64) * DENSE_SPACING;
            let w = (-0.5 * x * x).exp();
            total += w;
            out.at[k] = (w, cast(x * sigma));
        }
        for node in &mut out.at {
            node.0 /= total;
        }
        out.len = DENSE_NODES;
        out.centre = half;
        out.dense = true;
        out
    }

    /// Whether no surface but the centre's lies within `margin_rad` (beyond the quadrature's
    /// reach) of the beam, sampled every 0.25°: then no footprint up to that half-width mixes.
    #[must_use]
    pub fn clear_of_edges(
        &self,
        world: &World,
        robot: &Pose,
        angle_deg: f64,
        margin_rad: f64,
    ) -> bool {
        let (origin, heading) = self.beam(robot, angle_deg);
        let reach = margin_rad + 3.0 * self.angle_noise_rad;
        let centre = world
            .cast_ray(origin, heading, self.cast_limit_m)
            .map(|h| h.obstacle);
        let step = 0.25f64.to_radians();
        let n = (reach / step).ceil() as i64;
        (-n..=n).filter(|k| *k != 0).all(|k| {
            world
                .cast_ray(origin, heading + k as f64 * step, self.cast_limit_m)
                .map(|h| h.obstacle)
                == centre
        })
    }

    /// The predictive distribution of a reading whose beam saw `beam`, `t_s` seconds after
    /// power-on. The nodes are grouped by the surface they landed on; each group becomes one
    /// Gaussian with the group's weight and the quadrature's mean and variance of the reading
    /// over it (range noise and rounding included), so a surface met obliquely gets the spread
    /// (and the skew of the mean) its direction noise gives, and an edge a mixture.
    #[must_use]
    pub fn predict_nodes(&self, beam: &BeamNodes, t_s: f64) -> ExpectedLidar {
        let mut e = self.predict_from(&beam.nodes, beam.centre, beam.dense, t_s);
        e.world_reach_m = beam.world_reach_m;
        e
    }

    /// [`LidarPredictor::predict_nodes`] of the nodes `beam` (centre `centre`, sampled densely
    /// when `dense`), with its working sets on the stack.
    fn predict_from(
        &self,
        beam: &[(f64, Option<BeamReturn>)],
        centre: usize,
        dense: bool,
        t_s: f64,
    ) -> ExpectedLidar {
        let centre = beam.get(centre).and_then(|(_, r)| *r);
        let mut out = ExpectedLidar {
            components: Mixture::new(),
            true_range_m: centre.map(|c| c.hit.distance),
            cos_incidence: centre.map_or(1.0, |c| c.cos_incidence),
            obstacle: centre.map(|c| c.hit.obstacle),
            reflectivity: centre.map_or(0.0, |c| c.hit.reflectivity),
            near_edge: false,
            world_reach_m: 0.0,
        };
        // (weight × chance of a valid reading, mean, variance, surface, weight) per node whose
        // reading can be valid.
        type Node = (f64, f64, f64, Obstacle, f64);
        let mut nodes: [Option<Node>; DENSE_NODES] = [None; DENSE_NODES];
        let nodes = &mut nodes[..beam.len()];
        for ((w, ret), node) in beam.iter().zip(nodes.iter_mut()) {
            let Some(ret) = ret else {
                out.near_edge |= centre.is_some();
                continue;
            };
            out.near_edge |= ret.footprint_m != ret.hit.distance;
            let ranged = self.effects.ranged_m(ret, t_s);
            let mean = self.model.mean(ranged);
            let sd = self.model.std_dev(ranged);
            let var = sd * sd + ROUNDING_VAR_M2 + surface_var_m2(ret);
            // A reading outside [min, max] is reported invalid: a valid one comes from the part
            // of each node's distribution inside (its weight the probability of landing there).
            let valid = self.limited(Gaussian::new(1.0, mean, var.sqrt())).mass();
            *node = (valid >= 1e-9).then_some((w * valid, mean, var, ret.hit.obstacle, *w));
        }
        if dense {
            out.near_edge = true;
            // One Gaussian per node, widened by the spread of the reading across the node's
            // share of directions: the slope to its neighbours on the same surface (or across a
            // mixing footprint, where the reading is continuous) times the spacing, / √12.
            for k in 0..nodes.len() {
                let Some((w, mean, var, what, _)) = nodes[k] else {
                    continue;
                };
                let step = |j: Option<usize>| {
                    j.and_then(|j| nodes.get(j).copied().flatten())
                        .filter(|n| n.3 == what || (n.1 - mean).abs() < 10.0 * var.sqrt())
                        .map(|n| (n.1 - mean).abs())
                };
                let (sum, count) = [step(k.checked_sub(1)), step(Some(k + 1))]
                    .into_iter()
                    .flatten()
                    .fold((0.0, 0.0), |(sum, count), d| (sum + d, count + 1.0));
                let spread = if count == 0.0 { 0.0 } else { sum / count };
                out.components.push(self.limited(Gaussian::new(
                    w,
                    mean,
                    (var + spread * spread / 12.0).sqrt(),
                )));
            }
        } else {
            // One surface: the quadrature's mean and variance of the reading over the direction
            // noise, one Gaussian per surface (a single one unless a node fell off the range).
            // The moments are of the reading before the range limits (weights: the directions'
            // own), so that the limits, applied once to the surface's Gaussian (its
            // truncation), are not applied twice; its weight is its chance of a valid reading.
            let mut groups = [None::<(Obstacle, f64, f64, f64, f64)>; DENSE_NODES];
            let mut count = 0;
            for &(wv, mean, var, what, w) in nodes.iter().flatten() {
                match groups[..count].iter_mut().flatten().find(|g| g.0 == what) {
                    Some(g) => {
                        g.1 += wv;
                        g.2 += w * mean;
                        g.3 += w * (var + mean * mean);
                        g.4 += w;
                    }
                    None => {
                        groups[count] = Some((what, wv, w * mean, w * (var + mean * mean), w));
                        count += 1;
                    }
                }
            }
            out.near_edge |= count > 1;
            for &(_, wv, sm, ss, w) in groups[..count].iter().flatten() {
                let mean = sm / w;
                let var = (ss / w - mean * mean).max(ROUNDING_VAR_M2);
                out.components
                    .push(self.limited(Gaussian::new(wv, mean, var.sqrt())));
            }
        }
        let total: f64 = out.components.iter().map(|c| c.weight).sum();
        if total > 0.0 {
            for c in &mut out.components {
                c.weight /= total;
            }
        }
        out
    }

    /// `g` truncated to the readings reported valid.
    fn limited(&self, g: Gaussian) -> Gaussian {
        g.truncated(self.min_m, self.max_m)
    }

    /// The reading at `angle_deg` (lidar frame) when the robot is at `robot`, `t_s` seconds
    /// after power-on.
    #[must_use]
    pub fn predict(&self, world: &World, robot: &Pose, angle_deg: f64, t_s: f64) -> ExpectedLidar {
        let cast = self.cast_nodes(world, robot, angle_deg);
        let mut e = self.predict_from(cast.nodes(), cast.centre, cast.dense, t_s);
        e.world_reach_m = cast.world_reach_m;
        e
    }

    /// [`LidarPredictor::predict`] without the world's reach (`world_reach_m` 0), which casts
    /// two more rays in a world with uncertain surfaces: for a caller that reads the reading's
    /// distribution only (a scan matcher).
    #[must_use]
    pub fn predict_distribution(
        &self,
        world: &World,
        robot: &Pose,
        angle_deg: f64,
        t_s: f64,
    ) -> ExpectedLidar {
        let cast = self.cast_directions(world, robot, angle_deg);
        self.predict_from(cast.nodes(), cast.centre, cast.dense, t_s)
    }
}

/// The expected reading of a sonar ping, and the echo's true range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExpectedSonar {
    /// The expected reading and its spread.
    pub reading: Gaussian,
    /// The echo's true range (the nearest echo's, or its blend with the lobe's centroid),
    /// metres.
    pub true_range_m: f64,
}

/// Predicts the pings of a scenario's sonar with given effects.
pub struct SonarPredictor {
    sonar: Sonar,
}

impl SonarPredictor {
    /// The predictor of `config`'s sonar with the `[effects]` that concern it (beam width,
    /// speed of sound).
    ///
    /// # Errors
    /// A range model that makes no sense.
    pub fn new(config: &scenario::Sonar, effects: &scenario::Effects) -> Result<Self, ModelError> {
        Ok(Self {
            sonar: Sonar::with_effects(config, effects, 0)?,
        })
    }

    /// The ping when the robot is at `robot`; `None`: no echo within range (no sample).
    #[must_use]
    pub fn predict(&self, world: &World, robot: &Pose) -> Option<ExpectedSonar> {
        let d = self.sonar.echo_m(world, robot)?;
        let mean = self.sonar.mean_reading_m(d);
        let sd = self.sonar.reading_sd_m(d);
        Some(ExpectedSonar {
            reading: Gaussian::new(1.0, mean, (sd * sd + ROUNDING_VAR_M2).sqrt()),
            true_range_m: d,
        })
    }
}

/// Predicts the encoders' readings from the wheels' true travel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometerPredictor {
    scale: f64,
    sd_m: f64,
    slip: Option<scenario::OdometerWheelSlip>,
}

impl OdometerPredictor {
    /// The predictor of `config`'s encoders with `[effects.odometer_wheel_slip]` when on.
    #[must_use]
    pub fn new(config: &scenario::Odometer, effects: &scenario::Effects) -> Self {
        let tick_var = config.tick_m * config.tick_m / 12.0;
        Self {
            scale: 1.0 + config.slip,
            sd_m: (config.noise_m * config.noise_m + tick_var).sqrt(),
            slip: effects.odometer_wheel_slip,
        }
    }

    /// The expected reading of one wheel whose true cumulative travel is `travel_m` while it
    /// turns at `speed_mps` (its speed during the physics step), `braking_mps` its changes of
    /// speed while braking summed since the start
    /// ([`braking_change_mps`](crate::effects::braking_change_mps)), and the reading's spread.
    #[must_use]
    pub fn predict(&self, travel_m: f64, speed_mps: f64, braking_mps: f64) -> Gaussian {
        let slip = self.slip.as_ref().map_or(0.0, |slip| {
            crate::effects::slip_travel_m(slip, speed_mps, braking_mps)
        });
        Gaussian::new(1.0, (travel_m + slip) * self.scale, self.sd_m)
    }
}
