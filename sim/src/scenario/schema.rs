//! The scenario file's typed form. Every key is documented in `scenarios/README.md`; unknown keys
//! are rejected so that a typo cannot pass silently.

use std::collections::BTreeMap;

use serde::Deserialize;

pub use hilsim_lidar_protocols::LidarModel;

/// A calibration method (the one definition: `hilsim_recording::Method`).
pub use hilsim_recording::Method;

/// A whole scenario file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name, used in summaries and recordings.
    pub name: String,
    /// What the scenario exercises.
    #[serde(default)]
    pub description: String,
    /// Seed of every random stream of the run (overridden by `--seed`).
    #[serde(default)]
    pub seed: u64,
    /// Length of the run; default: until the drive program ends.
    #[serde(default)]
    pub duration_s: Option<f64>,
    /// Physics settings.
    #[serde(default)]
    pub physics: Physics,
    /// The static world.
    #[serde(default)]
    pub world: World,
    /// The robot.
    pub robot: Robot,
    /// The drive program, run in order.
    #[serde(default)]
    pub drive: Vec<DriveStep>,
    /// The robot's sensors; an absent table means the robot lacks that sensor.
    #[serde(default)]
    pub sensors: Sensors,
    /// Which calibrations `hilsim run` performs on the emulated data.
    #[serde(default)]
    pub calibration: Calibration,
    /// Assertions checked by `hilsim run` and `hilsim scenario test`.
    #[serde(default)]
    pub expect: Vec<Expect>,
    /// Physics switched on beyond the nominal models (the mismatch catalogue); default: none.
    #[serde(default)]
    pub effects: super::effects::Effects,
    /// How the serial link and the unit's motor fail (`serve`, `hil`); default: they do not.
    #[serde(default)]
    pub link: super::link::Link,
    /// The files the scenario names beside it (a map, a recorded path, a scan schedule), read
    /// when the scenario is loaded.
    #[serde(skip)]
    pub files: ScenarioFiles,
}

/// What a scenario's files hold, read when it is loaded: a log's run replayed needs its map, its
/// path and its lidar's scan schedule. Shared, so that copies of a scenario (one a run of a
/// dataset) cost nothing.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ScenarioFiles {
    /// `[world] map`, read.
    pub map: Option<std::sync::Arc<crate::occupancy::OccupancyMap>>,
    /// `[robot] path`, read.
    pub path: Option<std::sync::Arc<crate::recorded_path::RecordedPath>>,
    /// `[sensors.lidar] schedule`, read.
    pub schedule: Option<std::sync::Arc<crate::scan_schedule::ScanSchedule>>,
}

impl Scenario {
    /// The physics step, seconds.
    #[must_use]
    pub fn step_s(&self) -> f64 {
        1.0 / self.physics.step_hz
    }

    /// The reflectivity of a named material (`None`: the built-in default).
    #[must_use]
    pub fn reflectivity(&self, material: Option<&str>) -> f64 {
        material
            .and_then(|m| self.world.materials.get(m))
            .cloned()
            .unwrap_or_default()
            .reflectivity
    }
}

/// `[physics]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Physics {
    /// Fixed physics step rate, Hz.
    #[serde(default = "default_step_hz")]
    pub step_hz: f64,
}

fn default_step_hz() -> f64 {
    100.0
}

impl Default for Physics {
    fn default() -> Self {
        Self {
            step_hz: default_step_hz(),
        }
    }
}

/// `[world]`: static obstacles and their materials.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    /// Walls as line segments.
    #[serde(default)]
    pub walls: Vec<Wall>,
    /// Upright cylinders (landmarks, table legs).
    #[serde(default)]
    pub cylinders: Vec<Cylinder>,
    /// Boards: thin rectangular targets.
    #[serde(default)]
    pub boards: Vec<Board>,
    /// Named materials that obstacles refer to by `material = "name"`.
    #[serde(default)]
    pub materials: BTreeMap<String, Material>,
    /// An occupancy-grid map beside the walls and shapes: map_server's YAML (its image beside
    /// it), relative to the scenario file. Rays stop at its occupied cells; the robot's body
    /// does not collide with them.
    #[serde(default)]
    pub map: Option<std::path::PathBuf>,
}

/// A wall: a segment from `from` to `to`, metres.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    /// One end, `[x, y]`.
    pub from: [f64; 2],
    /// The other end, `[x, y]`.
    pub to: [f64; 2],
    /// The surface's material; default: the built-in `default`.
    #[serde(default)]
    pub material: Option<String>,
}

/// An upright cylinder.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cylinder {
    /// Centre `[x, y]`, metres.
    pub center: [f64; 2],
    /// Radius, metres.
    pub radius: f64,
    /// The surface's material.
    #[serde(default)]
    pub material: Option<String>,
}

/// A board: a rectangle of `length` × `thickness`, its length along `yaw_deg`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Board {
    /// Centre `[x, y]`, metres.
    pub center: [f64; 2],
    /// Length of the face, metres.
    pub length: f64,
    /// Thickness, metres; default 0.018 (an 18 mm plywood sheet).
    #[serde(default = "default_board_thickness")]
    pub thickness: f64,
    /// Direction of the face's length, degrees from the world x axis; default 90 (a face
    /// perpendicular to the x axis).
    #[serde(default = "default_board_yaw")]
    pub yaw_deg: f64,
    /// The surface's material.
    #[serde(default)]
    pub material: Option<String>,
}

fn default_board_thickness() -> f64 {
    0.018
}

fn default_board_yaw() -> f64 {
    90.0
}

/// A surface material.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Diffuse reflectivity at the lidar's wavelength, (0, 1]; scales the returned signal
    /// strength.
    #[serde(default = "default_reflectivity")]
    pub reflectivity: f64,
}

fn default_reflectivity() -> f64 {
    // A matte white wall reflects ~0.8–0.9 of near-infrared light; plywood ~0.5–0.6. The
    // built-in default is a generic light indoor surface.
    0.8
}

impl Default for Material {
    fn default() -> Self {
        Self {
            reflectivity: default_reflectivity(),
        }
    }
}

/// `[robot]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Robot {
    /// Pose at t = 0.
    pub start: StartPose,
    /// Distance between the wheels, metres.
    pub wheel_base_m: f64,
    /// The wheels' nominal radius, metres: what the encoders' turns are multiplied by to report
    /// travel (`meta.toml` records it, so a calibration of the wheels can give radii); default
    /// 0.033, a TurtleBot3's (ROBOTIS e-Manual, TurtleBot3 specifications).
    #[serde(default = "default_wheel_radius")]
    pub wheel_radius_m: f64,
    /// Radius of the robot's round body, metres; default 0.165 (a Neato robot is ~0.33 m wide).
    #[serde(default = "default_robot_radius")]
    pub radius_m: f64,
    /// Speed of turns in place, degrees per second; default 45.
    #[serde(default = "default_turn_rate")]
    pub turn_rate_deg_s: f64,
    /// How far the wheels' actual speed departs from the command; default: not at all.
    #[serde(default)]
    pub actuation: Actuation,
    /// A recorded path the robot follows instead of a drive program: a CSV
    /// `t_s,x_m,y_m,yaw_deg` relative to the scenario file (`hilsim_sim::recorded_path`). The
    /// run lasts to its last row unless `duration_s` says otherwise.
    #[serde(default)]
    pub path: Option<std::path::PathBuf>,
}

/// `[robot.actuation]`: the wheels do not do exactly what they are told. The actual speed of both
/// wheels is `command × (1 + scale_error + wander(t))`: a fixed error drawn once per run and an
/// Ornstein–Uhlenbeck process that wanders slowly (motor temperature, battery voltage, floor).
/// The commands in the recording stay as issued, so a calibrator that trusts them errs.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Actuation {
    /// Standard deviation of the fixed speed-scale error, drawn once per run from the seed
    /// (e.g. 0.02 for ±2 %).
    #[serde(default)]
    pub scale_sd: f64,
    /// Stationary standard deviation of the wandering speed-scale error.
    #[serde(default)]
    pub wander_sd: f64,
    /// Correlation time of the wander, seconds; default 10.
    #[serde(default = "default_wander_tau")]
    pub wander_tau_s: f64,
}

fn default_wander_tau() -> f64 {
    10.0
}

impl Default for Actuation {
    fn default() -> Self {
        Self {
            scale_sd: 0.0,
            wander_sd: 0.0,
            wander_tau_s: default_wander_tau(),
        }
    }
}

fn default_robot_radius() -> f64 {
    0.165
}

fn default_wheel_radius() -> f64 {
    0.033
}

fn default_turn_rate() -> f64 {
    45.0
}

/// The robot's start pose.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartPose {
    /// x, metres.
    pub x: f64,
    /// y, metres.
    pub y: f64,
    /// Heading, degrees counter-clockwise from the world x axis.
    #[serde(default)]
    pub yaw_deg: f64,
}

/// One step of the drive program as written; exactly one kind per step (checked on load).
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveStep {
    /// Straight at this forward speed, m/s (negative: reverse) …
    pub speed_mps: Option<f64>,
    /// … for this distance, metres.
    pub distance_m: Option<f64>,
    /// Stand still for this long, seconds.
    pub stop_s: Option<f64>,
    /// Turn in place by this angle, degrees (positive: counter-clockwise).
    pub turn_deg: Option<f64>,
}

impl DriveStep {
    /// How long the step lasts, seconds (a turn at `turn_rate_deg_s`), before rounding to
    /// physics steps; `None` for a step of no known kind (validation refuses those).
    #[must_use]
    pub fn duration_s(&self, turn_rate_deg_s: f64) -> Option<f64> {
        match (self.speed_mps, self.distance_m, self.stop_s, self.turn_deg) {
            (Some(v), Some(d), _, _) => Some(d / v.abs()),
            (_, _, Some(t), _) => Some(t),
            (_, _, _, Some(deg)) => Some(deg.to_radians().abs() / turn_rate_deg_s.to_radians()),
            _ => None,
        }
    }
}

/// `[sensors]`.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sensors {
    /// The Neato XV-11 lidar.
    pub lidar: Option<Lidar>,
    /// The sonar.
    pub sonar: Option<Sonar>,
    /// The wheel encoders.
    pub odometer: Option<Odometer>,
}

/// A sensor's `mount` table in a scenario: parsed strictly (an unknown key is an error), then
/// used as the recording's [`hilsim_recording::Mount`], the one mount of the sensor models.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mount {
    /// Forward offset, metres.
    #[serde(default)]
    pub x_m: f64,
    /// Leftward offset, metres.
    #[serde(default)]
    pub y_m: f64,
    /// Yaw relative to the robot's forward axis, degrees.
    #[serde(default)]
    pub yaw_deg: f64,
}

impl From<Mount> for hilsim_recording::Mount {
    fn from(m: Mount) -> Self {
        Self {
            x_m: m.x_m,
            y_m: m.y_m,
            yaw_deg: m.yaw_deg,
        }
    }
}

/// `[sensors.lidar]`: a spinning 2-D lidar, by default the Neato XV-11 triangulation lidar.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lidar {
    /// Which unit: its protocol on the wire, its geometry and timing, and the defaults of
    /// `rpm`, `min_range_m`, `max_range_m` and `noise` where the file sets none (the unit's
    /// datasheet: `hilsim_lidar_protocols::UnitSpec`). Default `xv11`.
    #[serde(default)]
    pub model: LidarModel,
    /// alpha_0.. of the papers' eq. (2), the range bias polynomial; default `[0, 1]` (unbiased).
    #[serde(default = "unbiased")]
    pub bias: Vec<f64>,
    /// beta_0.. of eq. (2), the noise standard deviation polynomial; default `[0]`.
    #[serde(default = "noiseless")]
    pub noise: Vec<f64>,
    /// Standard deviation of the beam direction, degrees.
    #[serde(default)]
    pub angle_noise_deg: f64,
    /// Motor speed, revolutions per minute; default the model's nominal rate (the XV-11's 300,
    /// 5 Hz).
    #[serde(default = "default_rpm")]
    pub rpm: f64,
    /// Amplitude of a slow sinusoidal rpm wobble, rpm; default 0.
    #[serde(default)]
    pub rpm_wobble: f64,
    /// Nearest range reported, metres; default 0.2 (Konolige et al., "A low-cost laser distance
    /// sensor", ICRA 2008: the XV-11 design's range is 0.2–6 m).
    #[serde(default = "default_lidar_min")]
    pub min_range_m: f64,
    /// Farthest range reported, metres; default 6.0 (same source).
    #[serde(default = "default_lidar_max")]
    pub max_range_m: f64,
    /// Mount pose on the robot.
    #[serde(default)]
    pub mount: Mount,
    /// When each reading's geometry is taken; default: each at its own instant.
    #[serde(default)]
    pub timing: LidarTiming,
    /// The scans of a recorded lidar to take instead of the XV-11's revolutions: a CSV
    /// `t_s,rev,beams,first_deg,step_deg,beam_period_s` relative to the scenario file
    /// (`hilsim_sim::scan_schedule`); `rpm` and `rpm_wobble` then do not apply.
    #[serde(default)]
    pub schedule: Option<std::path::PathBuf>,
}

/// When the lidar's readings are taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LidarTiming {
    /// Each reading at its own instant as the head turns (the XV-11 as it is).
    #[default]
    PerReading,
    /// A whole revolution at one instant, its start: the robot's pose then for all 360 readings
    /// (the snapshot many simulators take). The readings keep their per-reading timestamps,
    /// the slots the unit's packets time them by. `[effects.lidar_motion_skew]` is the physics
    /// this leaves out.
    PerRevolution,
}

fn unbiased() -> Vec<f64> {
    vec![0.0, 1.0]
}

fn noiseless() -> Vec<f64> {
    vec![0.0]
}

fn default_rpm() -> f64 {
    300.0
}

fn default_lidar_min() -> f64 {
    0.2
}

fn default_lidar_max() -> f64 {
    6.0
}

/// `[sensors.sonar]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sonar {
    /// alpha_0.. of eq. (2); the EM paper's sonar is affine. Default `[0, 1]`.
    #[serde(default = "unbiased")]
    pub bias: Vec<f64>,
    /// beta_0.. of eq. (2); the EM paper's sonar noise is constant. Default `[0]`.
    #[serde(default = "noiseless")]
    pub noise: Vec<f64>,
    /// Half of the beam cone, degrees; default 0, an axis-only sonar (a scenario's nominal
    /// simulation is what it declares: a cone, e.g. 15° for the HC-SR04 class, is declared here,
    /// or left out and switched on as `[effects.sonar_beam_width]`).
    #[serde(default)]
    pub half_angle_deg: f64,
    /// Ping rate, Hz; default 10.
    #[serde(default = "default_sonar_rate")]
    pub rate_hz: f64,
    /// Farthest echo, metres; default 4.0 (HC-SR04 datasheet).
    #[serde(default = "default_sonar_max")]
    pub max_range_m: f64,
    /// Mount pose on the robot.
    #[serde(default)]
    pub mount: Mount,
}

fn default_sonar_rate() -> f64 {
    10.0
}

fn default_sonar_max() -> f64 {
    4.0
}

/// `[sensors.odometer]`: the wheel encoders.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Odometer {
    /// Fraction by which the encoders over-report travel (the wheels spin on the floor).
    #[serde(default)]
    pub slip: f64,
    /// Standard deviation of each reading's noise, metres.
    #[serde(default)]
    pub noise_m: f64,
    /// Travel per encoder tick, metres; default 0.001 (the Neato command interface reports whole
    /// millimetres).
    #[serde(default = "default_tick")]
    pub tick_m: f64,
    /// Reading rate, Hz; default 20.
    #[serde(default = "default_odometer_rate")]
    pub rate_hz: f64,
}

fn default_tick() -> f64 {
    0.001
}

fn default_odometer_rate() -> f64 {
    20.0
}

/// `[calibration]`.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// Methods `hilsim run` applies: `em`, `landmarks`, `groundtruth`.
    #[serde(default)]
    pub methods: Vec<Method>,
}

/// An `[[expect]]` assertion on a named metric.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expect {
    /// A documented metric name.
    pub metric: String,
    /// The metric must be at least this.
    pub at_least: Option<f64>,
    /// The metric must be at most this.
    pub at_most: Option<f64>,
    /// In which kind of run it is checked: both (the default), only when the scenario's drive
    /// program runs (`run`, `scenario test`), or only when a firmware drives (`hil`).
    #[serde(default)]
    pub when: ExpectWhen,
}

/// `[[expect]] when`: the kind of run an assertion is checked in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ExpectWhen {
    /// Every kind.
    #[default]
    Always,
    /// `hilsim run` and `hilsim scenario test`: the drive program drives.
    Run,
    /// `hilsim hil`: the firmware drives.
    Hil,
}
