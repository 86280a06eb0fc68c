//! An independent reality: recordings of a scenario made by a generator that shares no model
//! code with hilsim's simulator (`hilsim-sim`) or sensor emulator (`hilsim-lidar-emulator`).
//! Its geometry and ray casting, its noise, its timing and its drive are written here from the
//! scenario format (`docs/formats/interfaces.md`, `scenarios/README.md`) and the papers' range
//! model; it uses `hilsim_sim::scenario` only for the scenario file's parsed form and
//! `hilsim-recording` for the output types. On top of the scenario it can conceal effects
//! (the diagnosis catalogue's physics, written again here, and physics outside it) and the
//! small differences between any two simulators that no catalogue is about ([`Nuisances`]).
//! `hilsim diagnose --self-test N --reality independent` proves the diagnosis on it.

mod concealed;
pub mod form;
mod motion;
mod noise;
mod nuisance;
mod sensors;
mod world;

pub use concealed::{Concealed, Stamped};
pub use noise::Stream;
pub use nuisance::Nuisances;

use hilsim_recording::{Meta, Mount, Pose, Recording, RobotMeta, SonarMount};
use hilsim_sim::scenario::Scenario;

use crate::motion::Drive;
use crate::sensors::Run;
use crate::world::{World, WorldOffsets};

/// A recording of `scenario` by this generator, with `concealed` physics and `nuisances`,
/// its noise drawn from `seed`.
#[must_use]
pub fn record(
    scenario: &Scenario,
    concealed: &[Concealed],
    nuisances: Nuisances,
    seed: u64,
) -> Recording {
    let world = World::new(
        scenario,
        WorldOffsets {
            wall_shift_m: nuisances.wall_shift_m,
            radius_change_m: nuisances.radius_change_m,
        },
    );
    let spans = motion::program(scenario);
    let end_s = motion::run_length(scenario, &spans);
    let lag = concealed.iter().find_map(|c| match *c {
        Concealed::MotorLag {
            time_constant_s,
            response,
        } => Some((time_constant_s, response)),
        _ => None,
    });
    let start = Pose {
        x: scenario.robot.start.x,
        y: scenario.robot.start.y,
        yaw: scenario.robot.start.yaw_deg.to_radians(),
    };
    let radius_scale = concealed
        .iter()
        .find_map(|c| match *c {
            Concealed::WheelRadius {
                left_scale,
                right_scale,
            } => Some([left_scale, right_scale]),
            _ => None,
        })
        .unwrap_or([1.0; 2]);
    let base_scale = concealed
        .iter()
        .find_map(|c| match *c {
            Concealed::WheelBase { scale } => Some(scale),
            _ => None,
        })
        .unwrap_or(1.0);
    let mut drive_noise = Stream::new(seed, "reality-drive");
    let motion = motion::integrate(
        &spans,
        start,
        scenario.robot.wheel_base_m * base_scale,
        end_s,
        Drive {
            lag,
            speed_noise: nuisances.speed_noise,
            radius_scale,
        },
        &mut drive_noise,
    );
    let run = Run {
        scenario,
        world: &world,
        motion: &motion,
        end_s,
        concealed,
        nuisances,
        radius_scale,
    };
    let s = &scenario.sensors;
    Recording {
        meta: Meta {
            robot: RobotMeta {
                wheel_base_m: scenario.robot.wheel_base_m,
                wheel_radius_m: Some(scenario.robot.wheel_radius_m),
            },
            lidar: s.lidar.as_ref().map(|l| Mount::from(l.mount)),
            sonar: s.sonar.as_ref().map(|u| SonarMount {
                x_m: u.mount.x_m,
                y_m: u.mount.y_m,
                yaw_deg: u.mount.yaw_deg,
                half_angle_deg: u.half_angle_deg,
            }),
            ..Meta::default()
        },
        commands: motion::commands(&spans, end_s),
        odometry: run.odometer(seed),
        lidar: run.lidar(seed),
        sonar: run.sonar(seed),
        truth: Some(run.truth(seed)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::form::{DriveResponse, EchoPick, Traction};

    /// A robot standing 2 m in front of a wall, every sensor, for 10 s.
    fn facing_a_wall() -> Scenario {
        Scenario::from_toml(
            r#"name = "wall"
[world]
walls = [{ from = [3.0, -2.0], to = [3.0, 2.0] }]
[robot]
start = { x = 1.0, y = 0.0, yaw_deg = 0.0 }
wheel_base_m = 0.23
[[drive]]
stop_s = 10.0
[sensors.lidar]
bias = [0.0, 1.0]
noise = [0.01]
[sensors.sonar]
bias = [0.0, 1.0]
noise = [0.008]
[sensors.odometer]
noise_m = 0.002
"#,
            std::path::Path::new("wall.toml"),
        )
        .unwrap()
    }

    fn mean(v: &[f64]) -> f64 {
        v.iter().sum::<f64>() / v.len() as f64
    }

    #[test]
    fn a_wall_two_metres_ahead_reads_two_metres_and_a_hot_room_reads_short() {
        let s = facing_a_wall();
        let r = record(&s, &[], Nuisances::default(), 7);
        let ahead: Vec<f64> = r
            .lidar
            .as_ref()
            .unwrap()
            .iter()
            .filter(|l| l.angle_deg == 0.0 && !l.invalid)
            .map(|l| l.range_m)
            .collect();
        // 50 revolutions of noise 10 mm: the mean within 4σ/√50 = 5.7 mm of 2 m.
        assert_eq!(ahead.len(), 50);
        assert!((mean(&ahead) - 2.0).abs() < 0.0057, "{}", mean(&ahead));
        let sonar: Vec<f64> = r
            .sonar
            .as_ref()
            .unwrap()
            .iter()
            .map(|p| p.range_m)
            .collect();
        assert!((mean(&sonar) - 2.0).abs() < 0.004, "{}", mean(&sonar));
        // Air at 40 °C against a calibration at 20 °C: ranges × c(20)/c(40) = 0.9686.
        let hot = record(
            &s,
            &[Concealed::SonarSpeedOfSound {
                air_temperature_c: 40.0,
                calibrated_at_c: 20.0,
            }],
            Nuisances::default(),
            7,
        );
        let hot: Vec<f64> = hot.sonar.unwrap().iter().map(|p| p.range_m).collect();
        assert!((mean(&hot) - 2.0 * 0.9686).abs() < 0.004, "{}", mean(&hot));
        // The same seed, the same recording.
        assert_eq!(record(&s, &[], Nuisances::default(), 7), r);
    }

    #[test]
    fn a_lidar_mounted_forward_reads_short_and_late_stamps_come_late() {
        let s = facing_a_wall();
        let ahead = |r: &Recording| {
            mean(
                &r.lidar
                    .as_ref()
                    .unwrap()
                    .iter()
                    .filter(|l| l.angle_deg == 0.0 && !l.invalid)
                    .map(|l| l.range_m)
                    .collect::<Vec<_>>(),
            )
        };
        let moved = record(
            &s,
            &[Concealed::LidarMountOffset {
                yaw_deg: 0.0,
                x_m: 0.1,
                y_m: 0.0,
            }],
            Nuisances::default(),
            7,
        );
        // 10 cm nearer the wall; the same noise draws, so the difference is exact to rounding.
        let nominal = record(&s, &[], Nuisances::default(), 7);
        assert!((ahead(&nominal) - ahead(&moved) - 0.1).abs() < 0.001);
        // A yaw of 30° turns bearing 0° onto the wall at 30°: 2 / cos 30° = 2.309 m.
        let turned = record(
            &s,
            &[Concealed::LidarMountOffset {
                yaw_deg: 30.0,
                x_m: 0.0,
                y_m: 0.0,
            }],
            Nuisances::default(),
            7,
        );
        assert!((ahead(&turned) - 2.0 / 30f64.to_radians().cos()).abs() < 0.006);
        let late = record(
            &s,
            &[Concealed::SensorLatency {
                sensor: Stamped::Sonar,
                delay_s: 0.05,
            }],
            Nuisances::default(),
            7,
        );
        let (a, b) = (nominal.sonar.unwrap(), late.sonar.unwrap());
        assert_eq!(a.len(), b.len());
        for (a, b) in a.iter().zip(&b) {
            assert!((b.t_s - a.t_s - 0.05).abs() < 1e-9);
            assert_eq!(a.range_m, b.range_m);
        }
        // Only the sonar's stamps: the lidar's are the nominal ones.
        assert_eq!(late.lidar, nominal.lidar);
    }

    #[test]
    fn wider_wheels_move_the_robot_more_than_the_encoders_say_and_a_wider_base_turns_less() {
        let s = Scenario::from_toml(
            r#"name = "drive"
[world]
walls = [{ from = [5.0, -5.0], to = [5.0, 5.0] }]
[robot]
start = { x = 0.0, y = 0.0, yaw_deg = 0.0 }
wheel_base_m = 0.23
turn_rate_deg_s = 45.0
[[drive]]
speed_mps = 0.2
distance_m = 1.0
[[drive]]
turn_deg = 90.0
[sensors.odometer]
noise_m = 0.0
"#,
            std::path::Path::new("drive.toml"),
        )
        .unwrap();
        let end = |r: &Recording| *r.truth.as_ref().unwrap().last().unwrap();
        let odo = |r: &Recording| *r.odometry.as_ref().unwrap().last().unwrap();
        let nominal = record(&s, &[], Nuisances::default(), 3);
        let wide = record(
            &s,
            &[Concealed::WheelRadius {
                left_scale: 1.05,
                right_scale: 1.05,
            }],
            Nuisances::default(),
            3,
        );
        // Both wheels 5 % larger: 5 % farther and a 5 % larger turn, the encoders unchanged
        // (to their 1 mm ticks).
        let (n, w) = (end(&nominal), end(&wide));
        assert!((w.x_m.hypot(w.y_m) / n.x_m.hypot(n.y_m) - 1.05).abs() < 0.01);
        assert!((w.yaw_rad / n.yaw_rad - 1.05).abs() < 0.001);
        assert!((odo(&wide).left_m - odo(&nominal).left_m).abs() <= 0.0011);
        let base = record(
            &s,
            &[Concealed::WheelBase { scale: 1.1 }],
            Nuisances::default(),
            3,
        );
        // The turn comes out 1/1.1 as large; the straight run and the encoders are the same.
        assert!((end(&base).yaw_rad / n.yaw_rad - 1.0 / 1.1).abs() < 0.001);
        assert!((odo(&base).right_m - odo(&nominal).right_m).abs() <= 0.0011);
    }

    /// A straight run of 1 m at 0.2 m/s, then a stop.
    fn run_and_stop() -> Scenario {
        Scenario::from_toml(
            r#"name = "run"
duration_s = 8.0
[world]
walls = [{ from = [5.0, -5.0], to = [5.0, 5.0] }]
[robot]
start = { x = 0.0, y = 0.0, yaw_deg = 0.0 }
wheel_base_m = 0.23
[[drive]]
speed_mps = 0.2
distance_m = 1.0
[sensors.odometer]
noise_m = 0.0
"#,
            std::path::Path::new("run.toml"),
        )
        .unwrap()
    }

    /// Slip that braking gives back leaves the encoders on the travel once stopped; slip only
    /// while speeding up keeps its lead `g v`; a saturating tyre scaled at the largest step
    /// leads by the same there.
    #[test]
    fn a_slip_keeps_what_braking_does_not_give_back() {
        let s = run_and_stop();
        let last = |slip: Option<Concealed>| {
            let r = record(
                &s,
                &slip.into_iter().collect::<Vec<_>>(),
                Nuisances::default(),
                3,
            );
            r.odometry.unwrap().last().unwrap().left_m
        };
        let plain = last(None);
        let slip = |share: f64, traction: Traction| {
            last(Some(Concealed::WheelSlip {
                gain_s: 0.1,
                braking_share: share,
                traction,
            }))
        };
        // Even slip: back on the travel, to the 1 mm tick.
        assert!((slip(1.0, Traction::Linear) - plain).abs() <= 0.0011);
        // Speeding up only: ahead by g v = 0.1 s × 0.2 m/s = 20 mm; a lead at every change,
        // twice that.
        assert!((slip(0.0, Traction::Linear) - plain - 0.02).abs() <= 0.0011);
        assert!((slip(-1.0, Traction::Linear) - plain - 0.04).abs() <= 0.0011);
        // The odometer's 20 Hz sees the step as 4 m/s² over one sample.
        let saturating = Traction::Saturating {
            accel_mps2: 2.0,
            top_mps2: 4.0,
        };
        assert!((slip(0.0, saturating) - plain - 0.02).abs() <= 0.0011);
    }

    /// Every drive response reaches `1 − 1/e` of a step at its response time, within 5 %.
    #[test]
    fn every_drive_response_reaches_its_share_of_a_step_at_its_time() {
        let spans = [motion::Span {
            from_s: 0.0,
            to_s: 3.0,
            left_mps: 0.2,
            right_mps: 0.2,
        }];
        let start = Pose {
            x: 0.0,
            y: 0.0,
            yaw: 0.0,
        };
        let tau = 0.3;
        for response in [
            DriveResponse::FirstOrder,
            DriveResponse::SecondOrder { damping: 0.5 },
            DriveResponse::SecondOrder { damping: 1.0 },
            DriveResponse::SlewLimited {
                accel_mps2: (1.0 - (-1.0f64).exp()) * 0.2 / tau,
            },
            DriveResponse::DeadTime { share: 0.5 },
        ] {
            let drive = Drive {
                lag: Some((tau, response)),
                ..Drive::default()
            };
            let m = motion::integrate(&spans, start, 0.23, 3.0, drive, &mut Stream::new(1, "d"));
            let reached = m
                .speed
                .iter()
                .position(|v| v[0] >= 0.2 * (1.0 - (-1.0f64).exp()))
                .unwrap() as f64
                * motion::STEP_S;
            assert!(
                (reached / tau - 1.0).abs() < 0.05,
                "{response:?}: {reached}"
            );
        }
    }

    /// Facing a wall 2 m away, the nearest echo in a 15° cone reads 2 m; the echoes' centroid
    /// reads long (the cone's edges are farther); a threshold's cone, 15° at 2 m, also reads
    /// 2 m head-on.
    #[test]
    fn a_sonar_reads_the_echo_its_form_picks() {
        let s = facing_a_wall();
        let sonar = |pick: EchoPick| {
            let beam = Concealed::SonarBeamWidth {
                half_angle_deg: 15.0,
                pick,
            };
            let r = record(&s, &[beam], Nuisances::default(), 7);
            mean(
                &r.sonar
                    .unwrap()
                    .iter()
                    .map(|p| p.range_m)
                    .collect::<Vec<_>>(),
            )
        };
        assert!((sonar(EchoPick::Nearest) - 2.0).abs() < 0.004);
        assert!((sonar(EchoPick::Threshold) - 2.0).abs() < 0.004);
        // A lobe of 15° (σ 7.5°) over ±30°, each echo 2/cos φ weighted by its lobe and
        // spreading: `1 + σ²/2` is 0.86 % long, 17 mm; the noise's mean within 4 mm.
        let centroid = sonar(EchoPick::BeamCentroid);
        assert!((centroid - 2.017).abs() < 0.004, "{centroid}");
    }

    #[test]
    fn nuisances_are_drawn_from_the_seed_alone() {
        let a = Nuisances::draw(&mut Stream::new(3, "n"));
        assert_eq!(a, Nuisances::draw(&mut Stream::new(3, "n")));
        assert_ne!(a, Nuisances::draw(&mut Stream::new(4, "n")));
    }
}
