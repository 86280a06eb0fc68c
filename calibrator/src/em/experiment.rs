//! The EM paper's experiment (Sec. VI) as scenarios, shared by the EM tests, the `em`
//! benchmark and the `reproduce_em` example: the simulated sensors' true models, one run's
//! scenario text (for `hilsim_sim::Scenario::from_toml`; the calibrator itself never runs the
//! physics), and a recording drawn straight from the models without the physics.

use hilsim_recording::{
    CommandSample, LidarSample, Meta, Mount, OdometrySample, Recording, SonarSample, TruthSample,
};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

/// The lidar of `scenarios/straight-board.toml`: the landmark paper's simulation model
/// (Alhashimi et al., Sensors 2021, Sec. 4.1) with the EM paper's β2 d² noise.
pub const LIDAR_ALPHA: [f64; 3] = [0.0525, 0.8838, 0.0584];
/// β2 of the lidar, metres⁻¹.
pub const LIDAR_BETA2: f64 = 0.004;
/// The sonar's affine bias (mount offset, speed-of-sound scale) and constant noise.
pub const SONAR_ALPHA: [f64; 2] = [0.021, 1.028];
/// Sonar noise sd, metres.
pub const SONAR_BETA0: f64 = 0.008;
/// Encoder over-report (slip) fraction.
pub const ODOMETER_SLIP: f64 = 0.027;
/// Encoder noise sd per wheel, metres.
pub const ODOMETER_NOISE_M: f64 = 0.004;

/// One run of the paper's experiment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Run {
    /// Reversing speed, m/s (the paper: 0.1, 0.2, 0.3).
    pub speed_mps: f64,
    /// Start distance (0.5 m in the paper) …
    pub start_m: f64,
    /// … and end distance (4 m), lidar to board.
    pub end_m: f64,
    /// Fixed speed-scale actuation error sd (0: ideal drive).
    pub scale_sd: f64,
    /// Wandering speed-scale error sd.
    pub wander_sd: f64,
    /// The robot's start yaw offset from facing the board squarely, degrees (Sec. VI-C).
    pub heading_error_deg: f64,
    /// Seed of every random stream.
    pub seed: u64,
    /// Whether the robot carries the sonar and the encoders.
    pub all_sensors: bool,
}

impl Default for Run {
    fn default() -> Self {
        Self {
            speed_mps: 0.1,
            start_m: 0.5,
            end_m: 4.0,
            scale_sd: 0.02,
            wander_sd: 0.01,
            heading_error_deg: 0.0,
            seed: 1,
            all_sensors: true,
        }
    }
}

impl Run {
    /// The scenario file's text (as `scenarios/straight-board.toml`, parameterised).
    #[must_use]
    pub fn scenario_toml(&self) -> String {
        let sensors = if self.all_sensors {
            format!(
                r#"
[sensors.sonar]
bias = [{}, {}]
noise = [{SONAR_BETA0}]
half_angle_deg = 15.0
max_range_m = 5.0
[sensors.odometer]
slip = {ODOMETER_SLIP}
noise_m = {ODOMETER_NOISE_M}
"#,
                SONAR_ALPHA[0], SONAR_ALPHA[1]
            )
        } else {
            String::new()
        };
        format!(
            r#"
name = "issue-5"
seed = {seed}
[world]
boards = [{{ center = [-0.009, 0.0], length = 1.2, thickness = 0.018, yaw_deg = 90.0, material = "plywood" }}]
walls = [
    {{ from = [-0.5, -3.0], to = [9.0, -3.0] }},
    {{ from = [9.0, -3.0], to = [9.0, 3.0] }},
    {{ from = [9.0, 3.0], to = [-0.5, 3.0] }},
    {{ from = [-0.5, 3.0], to = [-0.5, -3.0] }},
]
[world.materials.plywood]
reflectivity = 0.55
[robot]
start = {{ x = {start}, y = 0.0, yaw_deg = {yaw} }}
wheel_base_m = 0.23
[robot.actuation]
scale_sd = {scale_sd}
wander_sd = {wander_sd}
wander_tau_s = 10.0
[[drive]]
stop_s = 1.0
[[drive]]
speed_mps = {speed}
distance_m = {distance}
[[drive]]
stop_s = 1.0
[sensors.lidar]
bias = [{a0}, {a1}, {a2}]
noise = [0.0, 0.0, {b2}]
angle_noise_deg = 0.5
{sensors}"#,
            seed = self.seed,
            start = self.start_m,
            yaw = 180.0 + self.heading_error_deg,
            scale_sd = self.scale_sd,
            wander_sd = self.wander_sd,
            speed = -self.speed_mps,
            distance = self.end_m - self.start_m,
            a0 = LIDAR_ALPHA[0],
            a1 = LIDAR_ALPHA[1],
            a2 = LIDAR_ALPHA[2],
            b2 = LIDAR_BETA2,
        )
    }
}

/// A recording drawn straight from the paper's models, without the physics: `revolutions`
/// lidar samples (beam 0 only, one row per revolution, 5 Hz) of a robot reversing from 0.5 m
/// to 4 m at a commanded speed 1 % slower than its actual one, with encoders and a sonar read
/// at the same instants, and the truth. For the benchmarks, whose sample counts (10⁴) would
/// need a 2000 s simulation. `rng` draws every noise (the benchmark's is
/// `hilsim_sim::rng::stream(seed, "issue-5-synthetic")`).
pub fn synthetic_recording(revolutions: usize, rng: &mut impl Rng) -> Recording {
    let mut e = || -> f64 { StandardNormal.sample(rng) };
    let dt = 0.2;
    let duration = revolutions as f64 * dt;
    let commanded = -3.5 / duration;
    let actual = commanded * 1.01;
    let mut rec = Recording::new(Meta::default());
    rec.meta.lidar = Some(Mount {
        x_m: 0.0,
        y_m: 0.0,
        yaw_deg: 0.0,
    });
    rec.meta.world.target_start_distance_m = Some(0.5);
    rec.commands = vec![CommandSample {
        t_s: 0.0,
        left_mps: commanded,
        right_mps: commanded,
    }];
    let (mut lidar, mut odo, mut sonar, mut truth) = (vec![], vec![], vec![], vec![]);
    for k in 0..revolutions {
        let t = k as f64 * dt;
        let travel = actual * t;
        let d = 0.5 - travel;
        let y = LIDAR_ALPHA[0]
            + LIDAR_ALPHA[1] * d
            + LIDAR_ALPHA[2] * d * d
            + LIDAR_BETA2 * d * d * e();
        lidar.push(LidarSample {
            t_s: t,
            rev: k as u64,
            angle_deg: 0.0,
            range_m: (y * 1000.0).round() / 1000.0,
            strength: 300,
            invalid: false,
            warning: false,
            true_range_m: Some(d),
        });
        let wheel = travel * (1.0 + ODOMETER_SLIP);
        odo.push(OdometrySample {
            t_s: t,
            left_m: wheel + ODOMETER_NOISE_M * e(),
            right_m: wheel + ODOMETER_NOISE_M * e(),
        });
        sonar.push(SonarSample {
            t_s: t,
            range_m: SONAR_ALPHA[0] + SONAR_ALPHA[1] * d + SONAR_BETA0 * e(),
            true_range_m: Some(d),
        });
        truth.push(TruthSample {
            t_s: t,
            x_m: d,
            y_m: 0.0,
            yaw_rad: std::f64::consts::PI,
        });
    }
    rec.lidar = Some(lidar);
    rec.odometry = Some(odo);
    rec.sonar = Some(sonar);
    rec.truth = Some(truth);
    rec
}
