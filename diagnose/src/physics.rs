//! The physics the diagnosis asks about, behind a small trait: what the scenario's sensors
//! should read from a trajectory, and where its robot goes under recorded commands — nominally,
//! or with one catalogued effect switched on with given parameters. [`crate::SimPhysics`]
//! implements it from the simulator (`hilsim-sim`, `hilsim-lidar-emulator`); the trait itself
//! speaks only in the recording's samples and the normal distribution's [`Gaussian`], so the
//! statistics here would work with any simulator that implements it.

pub use hilsim_lidar_emulator::normal::Gaussian;
pub use hilsim_lidar_emulator::prediction::Mixture;
use hilsim_recording::{CommandSample, TruthSample};

use crate::catalogue::Effect;
use hilsim_recording::{Mount, Pose};

use crate::trajectory::Trajectory;

/// A model to predict with: the nominal one, or the nominal one with one or more effects
/// switched on, each with its parameters (in the order of [`Effect::params`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Hypothesis {
    /// The effects switched on, each at most once; empty: the nominal model.
    pub effects: Vec<(Effect, Vec<f64>)>,
}

impl Hypothesis {
    /// The scenario as declared.
    #[must_use]
    pub fn nominal() -> Self {
        Self::default()
    }

    /// The scenario with `effect` switched on with `params`.
    #[must_use]
    pub fn with(effect: Effect, params: Vec<f64>) -> Self {
        Self {
            effects: vec![(effect, params)],
        }
    }

    /// This hypothesis with `effect` switched on with `params` as well (replacing its
    /// parameters when it already is).
    #[must_use]
    pub fn and(&self, effect: Effect, params: Vec<f64>) -> Self {
        let mut effects: Vec<(Effect, Vec<f64>)> = self
            .effects
            .iter()
            .filter(|(e, _)| *e != effect)
            .cloned()
            .collect();
        effects.push((effect, params));
        Self { effects }
    }

    /// Whether no effect is switched on.
    #[must_use]
    pub fn is_nominal(&self) -> bool {
        self.effects.is_empty()
    }

    /// The `i`-th parameter of `effect` when it is switched on.
    #[must_use]
    pub fn param_of(&self, effect: Effect, i: usize) -> Option<f64> {
        self.effects
            .iter()
            .find(|(e, _)| *e == effect)
            .and_then(|(_, p)| p.get(i).copied())
    }
}

/// What the scenario declares that the diagnosis needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Declared {
    /// The scenario's name.
    pub scenario: String,
    /// The robot's start pose.
    pub start: Pose,
    /// The distance between the wheels, metres.
    pub wheel_base_m: f64,
    /// The lidar, when the robot has one.
    pub lidar: Option<DeclaredLidar>,
    /// The sonar's declared cone half-angle (degrees), when the robot has a sonar.
    pub sonar_half_angle_deg: Option<f64>,
    /// Whether the robot has wheel encoders.
    pub odometer: bool,
    /// The declared actuation error (zero for an ideal drive).
    pub actuation: DeclaredActuation,
    /// The path the scenario's robot follows (`[robot] path`), when it declares one: a twin's,
    /// which `hilsim world` matched to the log's own scans. An estimate of the real trajectory
    /// starts from it rather than from the encoders' bare integration, whose drift over a long
    /// run is more than a revolution's match can take back.
    pub path: Option<Trajectory>,
}

/// The declared actuation error: the wheels turn at `command × (1 + scale + wander(t))`, one
/// factor for both, `scale` drawn once per run, `wander` an Ornstein–Uhlenbeck process.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeclaredActuation {
    /// Standard deviation of the fixed scale error.
    pub scale_sd: f64,
    /// Stationary standard deviation of the wander.
    pub wander_sd: f64,
    /// The wander's correlation time, seconds.
    pub wander_tau_s: f64,
}

/// What the scenario declares about the lidar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeclaredLidar {
    /// Every reading of a revolution from the pose at its start (`timing = "per_revolution"`).
    pub snapshot: bool,
    /// The motor speed, rpm.
    pub rpm: f64,
    /// The farthest valid range, metres.
    pub max_range_m: f64,
    /// The nearest valid range, metres.
    pub min_range_m: f64,
    /// Where the lidar sits on the robot, as declared.
    pub mount: Mount,
    /// How far the world's surfaces may be from where the scenario puts them, metres: 0 for
    /// drawn shapes, half a cell for an occupancy map. A lidar departure smaller than this is
    /// as likely the world's as the lidar's, and is not reported.
    pub world_uncertainty_m: f64,
}

/// One lidar reading to predict.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LidarQuery {
    /// Its timestamp, seconds.
    pub t_s: f64,
    /// When its revolution started (the timestamp of its reading 0), seconds.
    pub rev_start_s: f64,
    /// Its angle in the lidar's frame, degrees.
    pub angle_deg: f64,
}

/// The predictive distribution of one lidar reading, with its geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct LidarPrediction {
    /// The mixture a valid reading comes from; empty: no valid reading expected.
    pub components: Mixture,
    /// The centre ray's true range, metres.
    pub true_range_m: Option<f64>,
    /// The angle between the beam and the surface normal, degrees.
    pub incidence_deg: f64,
    /// What the beam hit (an index for [`Physics::object_name`]).
    pub object: Option<u32>,
    /// Its reflectivity.
    pub reflectivity: f64,
    /// Whether the beam's direction noise or footprint reaches another surface.
    pub near_edge: bool,
    /// How far the world's own uncertainty (a map's cells) can move the reading, metres; 0 in
    /// a world drawn exactly.
    pub world_reach_m: f64,
}

/// The predictive distribution of one sonar ping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SonarPrediction {
    /// The expected reading; `None`: no echo within range expected.
    pub reading: Option<Gaussian>,
    /// The nearest echo's true range in the hypothesis's cone, metres.
    pub true_range_m: Option<f64>,
    /// The nearest echo within 30° of the axis, metres (where a wider cone would look).
    pub wide_cone_m: Option<f64>,
}

/// The predictive distribution of one odometer reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometryPrediction {
    /// Left and right wheels.
    pub wheels: [Gaussian; 2],
    /// The wheels' speeds then, m/s.
    pub speed_mps: [f64; 2],
}

/// The simulator, as the diagnosis sees it.
///
/// Every method is a pure function of its arguments: the same question gets the same answer
/// (the diagnosis asks many times while it fits). A `Hypothesis` whose effect does not concern
/// the sensor asked about leaves its predictions nominal.
///
/// ```
/// use hilsim_diagnose::*;
/// use hilsim_recording::{CommandSample, TruthSample};
///
/// /// A robot that never moves, in front of a wall 2 m ahead of its start.
/// struct Corridor(Declared);
/// impl Physics for Corridor {
///     fn declared(&self) -> &Declared { &self.0 }
///     fn object_name(&self, _: u32) -> String { "wall 0".into() }
///     fn drive(&self, _: &[CommandSample], end_s: f64, _: &Hypothesis) -> Vec<TruthSample> {
///         vec![TruthSample { t_s: 0.0, x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 },
///              TruthSample { t_s: end_s, x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 }]
///     }
///     fn lidar(&self, tr: &Trajectory, q: &[LidarQuery], _: &Hypothesis) -> Vec<LidarPrediction> {
///         q.iter().map(|q| {
///             let p = tr.pose_at(q.t_s);
///             let d = (2.0 - p.x) / (p.yaw + q.angle_deg.to_radians()).cos();
///             LidarPrediction {
///                 components: [Gaussian::new(1.0, d, 0.01)].into_iter().collect(),
///                 true_range_m: Some(d), incidence_deg: q.angle_deg, object: Some(0),
///                 reflectivity: 0.8, near_edge: false, world_reach_m: 0.0,
///             }
///         }).collect()
///     }
///     fn sonar(&self, _: &Trajectory, t: &[f64], _: &Hypothesis) -> Vec<SonarPrediction> {
///         t.iter().map(|_| SonarPrediction { reading: None, true_range_m: None, wide_cone_m: None }).collect()
///     }
///     fn odometry(&self, _: &Trajectory, t: &[f64], _: &Hypothesis) -> Vec<OdometryPrediction> {
///         let g = Gaussian::new(1.0, 0.0, 0.001);
///         t.iter().map(|_| OdometryPrediction { wheels: [g, g], speed_mps: [0.0; 2] }).collect()
///     }
/// }
/// let physics = Corridor(Declared {
///     scenario: "corridor".into(), start: Pose::default(), wheel_base_m: 0.23,
///     lidar: Some(DeclaredLidar {
///         snapshot: false, rpm: 300.0, max_range_m: 6.0, min_range_m: 0.06,
///         mount: Default::default(), world_uncertainty_m: 0.0,
///     }),
///     sonar_half_angle_deg: None, odometer: false,
///     actuation: Default::default(), path: None,
/// });
/// let still = Trajectory::new(&physics.drive(&[], 1.0, &Hypothesis::nominal()))?;
/// let ahead = physics.lidar(&still, &[LidarQuery { t_s: 0.5, rev_start_s: 0.4, angle_deg: 0.0 }],
///                           &Hypothesis::nominal());
/// assert_eq!(ahead[0].true_range_m, Some(2.0));
/// # Ok::<(), MismatchError>(())
/// ```
pub trait Physics: Sync {
    /// What the scenario declares.
    fn declared(&self) -> &Declared;

    /// A name for an object of [`LidarPrediction::object`], e.g. `board 1 (dark)`.
    fn object_name(&self, object: u32) -> String;

    /// The intervals `(from, to)`, seconds, in which the robot replaying `commands` under the
    /// nominal model touches an obstacle (its wheels' travel there is the contact's doing, not
    /// the drive's). Default: none (a physics without contacts).
    fn drive_contacts(&self, _commands: &[CommandSample], _end_s: f64) -> Vec<(f64, f64)> {
        Vec::new()
    }

    /// The robot's trajectory from t = 0 to `end_s` when its wheels are commanded by `commands`
    /// (the recording's `commands.csv`), under `hypothesis` (motor lag, the wheels' radii and
    /// base; any other effect leaves the drive nominal). The declared actuation error is left out: it is noise to the
    /// diagnosis, not a prediction.
    fn drive(
        &self,
        commands: &[CommandSample],
        end_s: f64,
        hypothesis: &Hypothesis,
    ) -> Vec<TruthSample>;

    /// The lidar readings `queries` from the robot on `trajectory`, under `hypothesis`. When
    /// each reading's geometry is taken (its timestamp, its revolution's start, or in between
    /// under motion skew) is the physics' to decide.
    fn lidar(
        &self,
        trajectory: &Trajectory,
        queries: &[LidarQuery],
        hypothesis: &Hypothesis,
    ) -> Vec<LidarPrediction>;

    /// [`Physics::lidar`] for matching scans to the world, which reads each reading's
    /// distribution (`components`) and nothing else: the physics may leave out what only
    /// judging the readings needs ([`LidarPrediction::world_reach_m`], 0 then, which takes two
    /// more rays a reading in a map). The default asks [`Physics::lidar`].
    fn lidar_distributions(
        &self,
        trajectory: &Trajectory,
        queries: &[LidarQuery],
        hypothesis: &Hypothesis,
    ) -> Vec<LidarPrediction> {
        self.lidar(trajectory, queries, hypothesis)
    }

    /// The sonar pings at `times` from the robot on `trajectory`, under `hypothesis`.
    fn sonar(
        &self,
        trajectory: &Trajectory,
        times: &[f64],
        hypothesis: &Hypothesis,
    ) -> Vec<SonarPrediction>;

    /// The odometer readings at `times` from the robot on `trajectory`, under `hypothesis`.
    fn odometry(
        &self,
        trajectory: &Trajectory,
        times: &[f64],
        hypothesis: &Hypothesis,
    ) -> Vec<OdometryPrediction>;
}
