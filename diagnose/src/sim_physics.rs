//! The diagnosis's physics ([`crate::Physics`]) from the simulator: the
//! scenario's world and sensor models, with a catalogued effect switched on as the
//! `[effects]` table of a scenario would. Glue only: every model lives in `hilsim-sim` and
//! `hilsim-lidar-emulator` (`effects`, `prediction`, `replay`).

use crate::{
    Declared, DeclaredActuation, DeclaredLidar, Effect, Gaussian, Hypothesis, LidarPrediction,
    LidarQuery, MismatchError, Mixture, OdometryPrediction, Physics, SonarPrediction, Trajectory,
};
use hilsim_lidar_emulator::effects::{real_mount, LidarEffects};
use hilsim_lidar_emulator::prediction::{
    BeamNodes, ExpectedLidar, LidarPredictor, OdometerPredictor, SonarPredictor,
};
use hilsim_recording::{CommandSample, TruthSample};
use hilsim_sim::scenario::{self, Effects, LidarTiming};
use hilsim_sim::{replay, Obstacle, Pose, Scenario, World};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, RwLock};

/// Readings predicted per parallel task at most …
const CHUNK: usize = 2048;
/// … and at least, when fewer than [`CHUNK`] a thread: a scan matcher's revolution (a few
/// dozen readings, each several rays) is then shared by the threads too.
const MIN_CHUNK: usize = 16;
/// The widest beam the mixed-pixel fit tries (its catalogue range), radians.
fn max_half_width_rad() -> f64 {
    Effect::LidarMixedPixels.params()[0].hi * std::f64::consts::PI / 180.0
}

/// A lidar reading's place: the robot's pose (x, y, yaw), the beam's angle and the unit's
/// mount on the robot (x, y, yaw), bit for bit.
type BeamKey = [u64; 7];

/// Where and when a hypothesis casts the beams: the unit's mount (x, y, yaw), the lidar's
/// delay and the revolution's duration of a motion skew (NaN: none), bit for bit.
type Geometry = [u64; 5];
/// Geometries counted at most before the count starts again.
const GEOMETRIES_COUNTED: usize = 4096;
/// A cache by beam: a lookup per reading per evaluation is the fits' inner loop, so its keys
/// are hashed by a fast hash (randomly seeded: a recording cannot be made to collide). Only
/// looked up, never iterated: the seed changes no result.
type BeamCache<V> = HashMap<BeamKey, V, foldhash::fast::RandomState>;
/// Whether a lidar prediction casts the world's reach of each reading
/// ([`LidarPrediction::world_reach_m`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reach {
    Cast,
    LeftOut,
}
/// Beams the caches hold at most (~1 KB each): a 60 s recording has 108,000 readings; beyond
/// this (e.g. the many trial poses of a scan matcher) beams are cast again instead.
const CACHE_CAPACITY: usize = 250_000;

/// A scenario's simulation, answering the diagnosis's questions.
pub struct SimPhysics {
    scenario: Scenario,
    world: World,
    declared: Declared,
    names: Vec<String>,
    /// What each beam's quadrature directions see, without a footprint: the same under every
    /// hypothesis of the same geometry (mount, delay, skew) but mixed pixels (another
    /// footprint), so the fits of the lidar's range effects cast no ray twice.
    beams: RwLock<BeamCache<Arc<BeamNodes>>>,
    /// Whether no other surface lies within the widest footprint of a beam.
    clear: RwLock<BeamCache<bool>>,
    /// How often each geometry has been asked about: a geometry's beams are kept from its
    /// second time on. A fit of the mount, the delay or the skew asks about a new geometry at
    /// every evaluation, which would fill the caches with beams never asked about again; the
    /// fits of the other effects on top of one found ask about it again and again.
    geometries: Mutex<HashMap<Geometry, u32>>,
    /// The beams of whole calls, in their readings' order: a fit evaluates the same readings
    /// along the same path at every step, and looking each beam up in [`SimPhysics::beams`]
    /// (a cache miss for its bucket and its key) was a sixth of a diagnosis with truth.
    calls: Mutex<Vec<Arc<CallBeams>>>,
}

/// The beams of one call's readings, in order, with the readings' keys they were found for.
struct CallBeams {
    /// A hash of `keys`, to pass over the calls of other readings at a glance.
    fingerprint: u64,
    keys: Vec<BeamKey>,
    beams: Vec<Arc<BeamNodes>>,
}

/// The fingerprint of a call's readings' keys ([`CallBeams`]): a fixed hash, as the
/// fingerprint only narrows the search and the keys themselves are compared.
fn fingerprint(keys: &[BeamKey]) -> u64 {
    use std::hash::BuildHasher;
    foldhash::fast::FixedState::with_seed(0).hash_one(keys)
}

/// Readings the calls kept hold at most together (~70 bytes each): the training and grid
/// readings of the fits in flight, a few times over.
const CALLS_CAPACITY: usize = 200_000;

impl SimPhysics {
    /// The beams kept for a call whose readings have `keys`.
    fn call_beams(&self, fingerprint: u64, keys: &[BeamKey]) -> Option<Arc<CallBeams>> {
        let calls = self.calls.lock().ok()?;
        calls
            .iter()
            .find(|c| c.fingerprint == fingerprint && c.keys == keys)
            .cloned()
    }

    /// Keeps a call's beams (unless they alone exceed [`CALLS_CAPACITY`]), the oldest calls
    /// making room; returns them.
    fn keep_call(&self, call: CallBeams) -> Arc<CallBeams> {
        let call = Arc::new(call);
        if call.keys.len() > CALLS_CAPACITY {
            return call;
        }
        if let Ok(mut calls) = self.calls.lock() {
            let mut held: usize = calls.iter().map(|c| c.keys.len()).sum();
            while held + call.keys.len() > CALLS_CAPACITY && !calls.is_empty() {
                held -= calls.remove(0).keys.len();
            }
            calls.push(call.clone());
        }
        call
    }
}

/// `p` with its heading wrapped as the simulator keeps every pose.
fn pose(p: Pose) -> Pose {
    Pose::new(p.x, p.y, p.yaw)
}

impl SimPhysics {
    /// The scenario whose drive replays commands under `hypothesis`. The declared actuation
    /// error is noise to the diagnosis, not a prediction, so it is left out.
    fn drive_scenario(&self, hypothesis: &Hypothesis) -> Scenario {
        let mut s = self.scenario.clone();
        s.effects = self.effects(hypothesis);
        s.robot.actuation.scale_sd = 0.0;
        s.robot.actuation.wander_sd = 0.0;
        s
    }

    /// The physics of `scenario` as declared (its own `[effects]` included: they are part of
    /// what it declares).
    pub fn new(scenario: &Scenario) -> Result<Self, MismatchError> {
        // Check the sensor models once, so that predicting cannot fail later.
        if let Some(l) = &scenario.sensors.lidar {
            LidarPredictor::new(l, LidarEffects::default())
                .map_err(|e| MismatchError::Input(format!("lidar model: {e}")))?;
        }
        if let Some(s) = &scenario.sensors.sonar {
            SonarPredictor::new(s, &scenario.effects)
                .map_err(|e| MismatchError::Input(format!("sonar model: {e}")))?;
        }
        let s = &scenario;
        let a = s.robot.actuation;
        let material = |m: &Option<String>| m.clone().unwrap_or_else(|| "default".into());
        let mut names = Vec::new();
        for (i, w) in s.world.walls.iter().enumerate() {
            names.push(format!("wall {i} ({})", material(&w.material)));
        }
        for (i, c) in s.world.cylinders.iter().enumerate() {
            names.push(format!("cylinder {i} ({})", material(&c.material)));
        }
        for (i, b) in s.world.boards.iter().enumerate() {
            names.push(format!("board {i} ({})", material(&b.material)));
        }
        let world = World::new(scenario);
        Ok(Self {
            declared: Declared {
                scenario: s.name.clone(),
                start: Pose {
                    x: s.robot.start.x,
                    y: s.robot.start.y,
                    yaw: hilsim_sim::pose::wrap_angle(s.robot.start.yaw_deg.to_radians()),
                },
                wheel_base_m: s.robot.wheel_base_m,
                lidar: s.sensors.lidar.as_ref().map(|l| DeclaredLidar {
                    snapshot: l.timing == LidarTiming::PerRevolution
                        && s.effects.lidar_motion_skew.is_none(),
                    rpm: l.rpm,
                    max_range_m: l.max_range_m,
                    min_range_m: l.min_range_m,
                    mount: l.mount.into(),
                    world_uncertainty_m: world.surface_uncertainty_m(),
                }),
                sonar_half_angle_deg: s.sensors.sonar.as_ref().map(|u| {
                    s.effects
                        .sonar_beam_width
                        .map_or(u.half_angle_deg, |b| b.half_angle_deg)
                }),
                odometer: s.sensors.odometer.is_some(),
                actuation: DeclaredActuation {
                    scale_sd: a.scale_sd,
                    wander_sd: a.wander_sd,
                    wander_tau_s: a.wander_tau_s,
                },
                path: s
                    .files
                    .path
                    .as_ref()
                    .map(|path| Trajectory::from_poses(path.iter()))
                    .transpose()?,
            },
            world,
            scenario: scenario.clone(),
            names,
            beams: RwLock::default(),
            clear: RwLock::default(),
            geometries: Mutex::default(),
            calls: Mutex::default(),
        })
    }

    /// Whether the beams of `geometry` are worth keeping: the declared one always, another
    /// from its second time on.
    fn keeps(&self, geometry: Geometry, declared: bool) -> bool {
        if declared {
            return true;
        }
        let Ok(mut seen) = self.geometries.lock() else {
            return false;
        };
        if seen.len() >= GEOMETRIES_COUNTED {
            seen.clear();
        }
        let count = seen.entry(geometry).or_insert(0);
        *count = count.saturating_add(1);
        *count >= 2
    }

    /// The beam's quadrature directions from the cache, cast on a miss (without a footprint)
    /// and kept when `keep`.
    fn cached_beam(
        &self,
        geometry: &LidarPredictor,
        key: BeamKey,
        keep: bool,
        robot: &Pose,
        angle: f64,
    ) -> Arc<BeamNodes> {
        if let Some(b) = self.beams.read().ok().and_then(|m| m.get(&key).cloned()) {
            return b;
        }
        let b = Arc::new(geometry.beam_nodes(&self.world, robot, angle));
        if !keep {
            return b;
        }
        if let Ok(mut m) = self.beams.write() {
            if m.len() < CACHE_CAPACITY {
                m.insert(key, b.clone());
            }
        }
        b
    }

    fn cached_clear(
        &self,
        geometry: &LidarPredictor,
        key: BeamKey,
        keep: bool,
        robot: &Pose,
        angle: f64,
    ) -> bool {
        if let Some(c) = self.clear.read().ok().and_then(|m| m.get(&key).copied()) {
            return c;
        }
        let c = geometry.clear_of_edges(&self.world, robot, angle, max_half_width_rad());
        if !keep {
            return c;
        }
        if let Ok(mut m) = self.clear.write() {
            if m.len() < CACHE_CAPACITY {
                m.insert(key, c);
            }
        }
        c
    }

    /// [`Physics::lidar`], with the world's reach of each reading cast or left out.
    fn lidar_predicted(
        &self,
        trajectory: &Trajectory,
        queries: &[LidarQuery],
        hypothesis: &Hypothesis,
        reach: Reach,
    ) -> Vec<LidarPrediction> {
        let all_effects = self.effects(hypothesis);
        let Some(config) = self.lidar_config(&all_effects) else {
            return queries.iter().map(|_| empty_lidar()).collect();
        };
        let effects = LidarEffects::from_scenario(&all_effects);
        let (Ok(predictor), Ok(geometry)) = (
            LidarPredictor::new(&config, effects),
            LidarPredictor::new(
                &config,
                LidarEffects {
                    mixed_half_width_rad: None,
                    ..effects
                },
            ),
        ) else {
            return queries.iter().map(|_| empty_lidar()).collect();
        };
        let mixed = effects.mixed_half_width_rad.is_some();
        // Only a whole run's trajectory is asked about again and again; the short pieces a
        // scan matcher tries are not worth keeping.
        let span = trajectory.end_s() - trajectory.times()[0];
        let cacheable = span > 2.0;
        let snapshot = self.declared.lidar.is_some_and(|l| l.snapshot);
        let skew = hypothesis.param_of(Effect::LidarMotionSkew, 0);
        // `[effects.sensor_latency]`: each reading was taken this long before its stamp.
        let latency_s = all_effects.sensor_latency.map_or(0.0, |l| l.lidar_s);
        let mount = [config.mount.x_m, config.mount.y_m, config.mount.yaw_deg];
        let keep = cacheable
            && self.keeps(
                [
                    mount[0],
                    mount[1],
                    mount[2],
                    latency_s,
                    skew.unwrap_or(f64::NAN),
                ]
                .map(f64::to_bits),
                all_effects.lidar_mount_offset.is_none() && latency_s == 0.0 && skew.is_none(),
            );
        // When each reading's geometry is taken.
        let instant = |q: &LidarQuery| {
            let stamped = match (snapshot, skew) {
                (true, Some(revolution_s)) => q.rev_start_s + q.angle_deg / 360.0 * revolution_s,
                (true, None) => q.rev_start_s,
                (false, _) => q.t_s,
            };
            stamped - latency_s
        };
        let chunk = queries
            .len()
            .div_ceil(rayon::current_num_threads())
            .clamp(MIN_CHUNK, CHUNK);
        let prediction = |e: ExpectedLidar| LidarPrediction {
            components: e.components,
            true_range_m: e.true_range_m,
            incidence_deg: e.cos_incidence.clamp(0.0, 1.0).acos().to_degrees(),
            object: e.obstacle.map(|o| self.object_id(o)),
            reflectivity: e.reflectivity,
            near_edge: e.near_edge,
            world_reach_m: e.world_reach_m,
        };
        let place = |q: &LidarQuery| {
            let p = trajectory.pose_at(instant(q));
            let key =
                [p.x, p.y, p.yaw, q.angle_deg, mount[0], mount[1], mount[2]].map(f64::to_bits);
            (pose(p), key)
        };
        let uncached = |robot: &Pose, q: &LidarQuery| match reach {
            Reach::Cast => predictor.predict(&self.world, robot, q.angle_deg, q.t_s),
            Reach::LeftOut => {
                predictor.predict_distribution(&self.world, robot, q.angle_deg, q.t_s)
            }
        };
        // Without a footprint of its own, a kept call's beams are read in order.
        if cacheable && keep && !mixed {
            let places: Vec<(Pose, BeamKey)> = queries
                .par_chunks(chunk)
                .flat_map_iter(|chunk| chunk.iter().map(place))
                .collect();
            let keys: Vec<BeamKey> = places.iter().map(|&(_, key)| key).collect();
            let print = fingerprint(&keys);
            let call = match self.call_beams(print, &keys) {
                Some(call) => call,
                None => {
                    let beams: Vec<Arc<BeamNodes>> = queries
                        .par_chunks(chunk)
                        .zip(places.par_chunks(chunk))
                        .flat_map_iter(|(chunk, places)| {
                            chunk.iter().zip(places).map(|(q, (robot, key))| {
                                self.cached_beam(&geometry, *key, true, robot, q.angle_deg)
                            })
                        })
                        .collect();
                    self.keep_call(CallBeams {
                        fingerprint: print,
                        keys,
                        beams,
                    })
                }
            };
            return queries
                .par_iter()
                .zip(call.beams.par_iter())
                .with_min_len(MIN_CHUNK)
                .map(|(q, beam)| prediction(predictor.predict_nodes(beam, q.t_s)))
                .collect();
        }
        queries
            .par_chunks(chunk)
            .flat_map_iter(|chunk| {
                chunk.iter().map(|q| {
                    let (robot, key) = place(q);
                    let e = if cacheable {
                        if mixed && !self.cached_clear(&geometry, key, keep, &robot, q.angle_deg) {
                            uncached(&robot, q)
                        } else {
                            let beam = self.cached_beam(&geometry, key, keep, &robot, q.angle_deg);
                            predictor.predict_nodes(&beam, q.t_s)
                        }
                    } else {
                        uncached(&robot, q)
                    };
                    prediction(e)
                })
            })
            .collect()
    }

    fn object_id(&self, o: Obstacle) -> u32 {
        let w = &self.scenario.world;
        (match o {
            Obstacle::Wall(i) => i,
            Obstacle::Cylinder(i) => w.walls.len() + i,
            Obstacle::Board(i) => w.walls.len() + w.cylinders.len() + i,
            Obstacle::Map => w.walls.len() + w.cylinders.len() + w.boards.len(),
        }) as u32
    }

    /// The lidar as the hypothesis has it mounted (`[effects.lidar_mount_offset]`: the
    /// simulator's own [`real_mount`]).
    fn lidar_config(&self, effects: &Effects) -> Option<scenario::Lidar> {
        let mut config = self.scenario.sensors.lidar.clone()?;
        let m = real_mount(config.mount.into(), effects.lidar_mount_offset);
        config.mount = scenario::Mount {
            x_m: m.x_m,
            y_m: m.y_m,
            yaw_deg: m.yaw_deg,
        };
        Some(config)
    }

    /// The scenario's effects with the hypothesis's switched on over them.
    fn effects(&self, h: &Hypothesis) -> Effects {
        let mut e = self.scenario.effects.clone();
        for (effect, params) in &h.effects {
            effect.apply(params, &mut e);
        }
        e
    }
}

impl Physics for SimPhysics {
    fn declared(&self) -> &Declared {
        &self.declared
    }

    fn object_name(&self, object: u32) -> String {
        self.names
            .get(object as usize)
            .cloned()
            .unwrap_or_else(|| format!("object {object}"))
    }

    fn drive(
        &self,
        commands: &[CommandSample],
        end_s: f64,
        hypothesis: &Hypothesis,
    ) -> Vec<TruthSample> {
        replay::replay_commands(&self.drive_scenario(hypothesis), commands, end_s)
    }

    fn drive_contacts(&self, commands: &[CommandSample], end_s: f64) -> Vec<(f64, f64)> {
        replay::replay_contacts(
            &self.drive_scenario(&Hypothesis::nominal()),
            commands,
            end_s,
        )
    }

    fn lidar(
        &self,
        trajectory: &Trajectory,
        queries: &[LidarQuery],
        hypothesis: &Hypothesis,
    ) -> Vec<LidarPrediction> {
        self.lidar_predicted(trajectory, queries, hypothesis, Reach::Cast)
    }

    fn lidar_distributions(
        &self,
        trajectory: &Trajectory,
        queries: &[LidarQuery],
        hypothesis: &Hypothesis,
    ) -> Vec<LidarPrediction> {
        self.lidar_predicted(trajectory, queries, hypothesis, Reach::LeftOut)
    }

    fn sonar(
        &self,
        trajectory: &Trajectory,
        times: &[f64],
        hypothesis: &Hypothesis,
    ) -> Vec<SonarPrediction> {
        let none = SonarPrediction {
            reading: None,
            true_range_m: None,
            wide_cone_m: None,
        };
        let Some(config) = &self.scenario.sensors.sonar else {
            return times.iter().map(|_| none).collect();
        };
        let effects = self.effects(hypothesis);
        let Ok(predictor) = SonarPredictor::new(config, &effects) else {
            return times.iter().map(|_| none).collect();
        };
        // Where a wider cone would look (asked only with the nominal model: a covariate).
        let wide = hypothesis.is_nominal().then(|| {
            let mut e = effects.clone();
            Effect::SonarBeamWidth.apply(&[30.0], &mut e);
            SonarPredictor::new(config, &e)
        });
        // `[effects.sensor_latency]`: each ping was taken this long before its stamp.
        let latency_s = effects.sensor_latency.map_or(0.0, |l| l.sonar_s);
        times
            .par_iter()
            .map(|&t| {
                let robot = pose(trajectory.pose_at(t - latency_s));
                let p = predictor.predict(&self.world, &robot);
                SonarPrediction {
                    reading: p.map(|p| p.reading),
                    true_range_m: p.map(|p| p.true_range_m),
                    wide_cone_m: wide
                        .as_ref()
                        .and_then(|w| w.as_ref().ok())
                        .and_then(|w| w.predict(&self.world, &robot))
                        .map(|p| p.true_range_m),
                }
            })
            .collect()
    }

    fn odometry(
        &self,
        trajectory: &Trajectory,
        times: &[f64],
        hypothesis: &Hypothesis,
    ) -> Vec<OdometryPrediction> {
        let flat = Gaussian::new(1.0, 0.0, 1.0);
        let Some(config) = &self.scenario.sensors.odometer else {
            return times
                .iter()
                .map(|_| OdometryPrediction {
                    wheels: [flat; 2],
                    speed_mps: [0.0; 2],
                })
                .collect();
        };
        let effects = self.effects(hypothesis);
        let predictor = OdometerPredictor::new(config, &effects);
        // `[effects.drive_wheel_base]`: the wheels' contact points are this far apart, so
        // the body's turn comes from their travel over the effective base.
        let wheel_base_m =
            self.scenario.robot.wheel_base_m * effects.drive_wheel_base.map_or(1.0, |b| b.scale);
        // `[effects.odometer_wheel_radius]`: the encoders count turns of the real radius and
        // report them at the nominal one: the true travel over each wheel's scale.
        let radius_scale = effects
            .odometer_wheel_radius
            .map_or([1.0; 2], |r| [r.left_scale, r.right_scale]);
        // `[effects.sensor_latency]`: each reading was taken this long before its stamp.
        let latency_s = effects.sensor_latency.map_or(0.0, |l| l.odometer_s);
        // The wheels' true travel along the trajectory, as the simulator defines it.
        let (ts, ps) = (trajectory.times(), trajectory.poses());
        let mut travel = Vec::with_capacity(ts.len());
        travel.push([0.0; 2]);
        for k in 1..ts.len() {
            let prev = travel[k - 1];
            travel.push(replay::wheel_travel(
                prev,
                &pose(ps[k - 1]),
                &pose(ps[k]),
                wheel_base_m,
            ));
        }
        // A slip whose braking gain differs from its driving one needs the wheels' changes of
        // speed while braking (with equal gains they add nothing).
        let braking = match effects.odometer_wheel_slip {
            Some(slip) if slip.braking_gain() != slip.gain_s => braking_along(trajectory, &travel),
            _ => vec![[0.0; 2]; ts.len()],
        };
        times
            .iter()
            .map(|&t| {
                let t = t - latency_s;
                let at = trajectory.interpolate(&travel, t);
                let k = trajectory.interval(t);
                let speed = match ts.get(k + 1) {
                    Some(&t1) if t1 > ts[k] => {
                        [0, 1].map(|w| (travel[k + 1][w] - travel[k][w]) / (t1 - ts[k]))
                    }
                    _ => [0.0; 2],
                };
                // The slip acts on the ground's travel, before the encoders' scale (as in
                // the emulator); the slip being linear in speed, dividing both is the same.
                let scaled = [0, 1].map(|w| speed[w] / radius_scale[w]);
                OdometryPrediction {
                    wheels: [0, 1].map(|w| {
                        predictor.predict(
                            at[w] / radius_scale[w],
                            scaled[w],
                            braking[k][w] / radius_scale[w],
                        )
                    }),
                    speed_mps: speed,
                }
            })
            .collect()
    }
}

/// The span a wheel's speed is measured over to tell its braking, seconds: the robots' changes
/// of speed take a few tenths of a second (a motor's lag, a ramp), while differences of a path's
/// poses a physics step apart carry its rounding (a truth file's micrometres over 10 ms are
/// 0.1 mm/s) and an estimated path's noise.
const BRAKING_SPEED_SPAN_S: f64 = 0.2;
/// Changes of a wheel's speed smaller than this are not counted as speeding up or braking,
/// m/s: a play operator's width, so that the noise left in the measured speed does not add up
/// over a run (a tenth of the slowest speeds the catalogue's robots drive at, 0.05 m/s).
const BRAKING_PLAY_MPS: f64 = 0.005;

/// Each wheel's changes of speed while braking, summed from the start to each of `trajectory`'s
/// points (`travel` its wheels' travel there), as
/// [`braking_change_mps`](hilsim_lidar_emulator::effects::braking_change_mps) sums them in the
/// emulator from the true speeds; here from the path's speeds over [`BRAKING_SPEED_SPAN_S`],
/// through a play of [`BRAKING_PLAY_MPS`].
fn braking_along(trajectory: &Trajectory, travel: &[[f64; 2]]) -> Vec<[f64; 2]> {
    use hilsim_lidar_emulator::effects::braking_change_mps;
    let half = BRAKING_SPEED_SPAN_S / 2.0;
    let mut held = [0.0_f64; 2];
    let mut sum = [0.0_f64; 2];
    trajectory
        .times()
        .iter()
        .map(|&t| {
            let (a, b) = (
                trajectory.interpolate(travel, t - half),
                trajectory.interpolate(travel, t + half),
            );
            for w in 0..2 {
                let speed = (b[w] - a[w]) / BRAKING_SPEED_SPAN_S;
                let gap = speed - held[w];
                if gap.abs() > BRAKING_PLAY_MPS {
                    let next = speed - BRAKING_PLAY_MPS.copysign(gap);
                    sum[w] += braking_change_mps(held[w], next);
                    held[w] = next;
                }
            }
            sum
        })
        .collect()
}

fn empty_lidar() -> LidarPrediction {
    LidarPrediction {
        components: Mixture::new(),
        true_range_m: None,
        incidence_deg: 0.0,
        object: None,
        reflectivity: 0.0,
        near_edge: false,
        world_reach_m: 0.0,
    }
}
