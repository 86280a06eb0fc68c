//! The commonest real mismatches as `[effects]`: a lidar mounted rotated or
//! off-centre, sensors whose timestamps lag, wheels whose radii are not nominal, an effective
//! wheel base that is not the nominal one. Each changes the recording exactly as its physics
//! says, and `meta.toml` keeps what the scenario declares.
//!
//! Sensors here are noiseless and unbiased, so readings are deterministic functions of the
//! geometry; tolerances are millimetre rounding plus rapier's f32 geometry (0.6 mm), or the
//! odometer's 1 mm ticks.

use hilsim_lidar_emulator::Emulation;
use hilsim_recording::{LidarSample, Recording};
use hilsim_sim::scenario::{DriveWheelBase, LidarMountOffset, OdometerWheelRadius, SensorLatency};
use hilsim_sim::Scenario;

/// Rounding to millimetres plus f32 geometry.
const MM_TOL: f64 = 0.6e-3;

const SENSORS: &str = "[sensors.lidar]\nbias = [0.0, 1.0]\nnoise = [0.0]\nangle_noise_deg = 0.0\n\
     [sensors.sonar]\nbias = [0.0, 1.0]\nnoise = [0.0]\n[sensors.odometer]\nnoise_m = 0.0\nslip = 0.0\n";

/// A robot at the origin facing +x in an irregular room (so that a rotated scan differs), with
/// the given duration, drive and sensors.
fn scenario(duration_s: f64, drive: &str) -> Scenario {
    let text = format!(
        "name = \"fx\"\nduration_s = {duration_s}\n[world]\nwalls = [\n  {{ from = [3.0, -2.0], to = [3.0, 2.5] }},\n  \
         {{ from = [3.0, 2.5], to = [-2.0, 3.0] }},\n  {{ from = [-2.0, 3.0], to = [-2.5, -2.0] }},\n  \
         {{ from = [-2.5, -2.0], to = [3.0, -2.0] }},\n]\n\
         cylinders = [{{ center = [1.5, 0.8], radius = 0.2 }}]\n\
         [robot]\nstart = {{ x = 0.0, y = 0.0 }}\nwheel_base_m = 0.23\n{drive}\n{SENSORS}"
    );
    Scenario::from_toml(&text, "fx.toml".as_ref()).unwrap()
}

fn record(s: &Scenario) -> Recording {
    Emulation::new(s, s.seed).unwrap().run().recording
}

/// The first revolution's reading at `angle` degrees.
fn at(readings: &[LidarSample], angle: f64) -> &LidarSample {
    readings
        .iter()
        .find(|r| r.rev == 0 && (r.angle_deg - angle).abs() < 1e-9)
        .unwrap()
}

#[test]
fn a_rotated_lidar_sees_the_world_turned_by_its_offset() {
    let nominal = scenario(0.25, "");
    let mut rotated = nominal.clone();
    rotated.effects.lidar_mount_offset = Some(LidarMountOffset {
        yaw_deg: 5.0,
        ..Default::default()
    });
    let (a, b) = (record(&nominal), record(&rotated));
    let (la, lb) = (a.lidar.as_deref().unwrap(), b.lidar.as_deref().unwrap());
    // The robot stands still: beam k of the rotated unit points where beam k + 5 of the nominal
    // one does.
    let mut compared = 0;
    for k in 0..355 {
        let (ra, rb) = (at(la, f64::from(k + 5)), at(lb, f64::from(k)));
        if let (Some(ta), Some(tb)) = (ra.true_range_m, rb.true_range_m) {
            assert!((ta - tb).abs() < MM_TOL, "beam {k}: {tb} vs {ta}");
            compared += 1;
        }
    }
    assert!(compared > 300, "{compared} beams compared");
    // And beam 0 itself differs (the room is not a circle): the offset is not a no-op.
    assert!((at(la, 0.0).range_m - at(lb, 0.0).range_m).abs() > 0.01);
    assert_eq!(
        b.meta.lidar, a.meta.lidar,
        "meta.toml keeps the declared mount"
    );
}

#[test]
fn an_off_centre_lidar_measures_from_where_it_is() {
    let nominal = scenario(0.25, "");
    let mut shifted = nominal.clone();
    shifted.effects.lidar_mount_offset = Some(LidarMountOffset {
        x_m: 0.05,
        ..Default::default()
    });
    let (a, b) = (record(&nominal), record(&shifted));
    let (la, lb) = (a.lidar.as_deref().unwrap(), b.lidar.as_deref().unwrap());
    // The wall ahead (x = 3) is 5 cm nearer along beam 0; the one behind 5 cm farther.
    let d0 = at(la, 0.0).true_range_m.unwrap() - at(lb, 0.0).true_range_m.unwrap();
    let d180 = at(lb, 180.0).true_range_m.unwrap() - at(la, 180.0).true_range_m.unwrap();
    assert!(
        (d0 - 0.05).abs() < MM_TOL && (d180 - 0.05).abs() < MM_TOL,
        "{d0} {d180}"
    );
}

#[test]
fn latency_stamps_each_sensor_late_by_its_own_delay() {
    let nominal = scenario(2.0, "[[drive]]\nspeed_mps = 0.2\ndistance_m = 0.3\n");
    let mut late = nominal.clone();
    late.effects.sensor_latency = Some(SensorLatency {
        lidar_s: 0.05,
        sonar_s: 0.12,
        odometer_s: 0.03,
    });
    let (a, b) = (record(&nominal), record(&late));
    let pairs = |x: &[f64], y: &[f64], delay: f64| {
        assert_eq!(x.len(), y.len());
        for (u, v) in x.iter().zip(y) {
            assert!(
                (v - u - delay).abs() < 1.5e-6,
                "{u} → {v}, expected +{delay}"
            );
        }
    };
    let times = |r: &Recording| {
        (
            r.lidar.iter().flatten().map(|s| s.t_s).collect::<Vec<_>>(),
            r.sonar.iter().flatten().map(|s| s.t_s).collect::<Vec<_>>(),
            r.odometry
                .iter()
                .flatten()
                .map(|s| s.t_s)
                .collect::<Vec<_>>(),
        )
    };
    let ((la, sa, oa), (lb, sb, ob)) = (times(&a), times(&b));
    pairs(&la, &lb, 0.05);
    pairs(&sa, &sb, 0.12);
    pairs(&oa, &ob, 0.03);
    // What is measured is not changed, only when it is said to be.
    let ranges = |r: &Recording| {
        r.lidar
            .iter()
            .flatten()
            .map(|s| s.range_m)
            .collect::<Vec<_>>()
    };
    assert_eq!(ranges(&a), ranges(&b));
    assert_eq!(a.truth, b.truth);
}

#[test]
fn larger_wheels_drive_farther_while_the_encoders_report_the_command() {
    // 0.5 m commanded at 0.2 m/s; wheels 4 % larger than nominal.
    let nominal = scenario(4.0, "[[drive]]\nspeed_mps = 0.2\ndistance_m = 0.5\n");
    let mut large = nominal.clone();
    large.effects.odometer_wheel_radius = Some(OdometerWheelRadius {
        left_scale: 1.04,
        right_scale: 1.04,
    });
    let (a, b) = (record(&nominal), record(&large));
    let end_x = |r: &Recording| r.truth.as_ref().unwrap().last().unwrap().x_m;
    let travelled = |r: &Recording| r.odometry.as_ref().unwrap().last().unwrap().left_m;
    // The robot goes 4 % farther (the physics step quantises the stop: 1 % of a step's travel).
    assert!(
        (end_x(&b) / end_x(&a) - 1.04).abs() < 0.002,
        "{} vs {}",
        end_x(&b),
        end_x(&a)
    );
    // The encoders count turns of the nominal radius: the same travel as the nominal run, to a
    // tick.
    assert!(
        (travelled(&b) - travelled(&a)).abs() <= 0.0011,
        "{} vs {}",
        travelled(&b),
        travelled(&a)
    );
    assert_eq!(b.meta.robot, a.meta.robot);
}

#[test]
fn unequal_wheels_make_a_straight_command_curve() {
    let mut curved = scenario(4.0, "[[drive]]\nspeed_mps = 0.2\ndistance_m = 0.5\n");
    curved.effects.odometer_wheel_radius = Some(OdometerWheelRadius {
        left_scale: 1.0,
        right_scale: 1.02,
    });
    let r = record(&curved);
    let last = r.truth.as_ref().unwrap().last().unwrap();
    // The right wheel covers 2 % more: the robot turns left by (0.02 · 0.5 m) / 0.23 m ≈ 2.5°.
    let expected = (0.02 * 0.5_f64 / 0.23).to_degrees();
    assert!(
        (last.yaw_rad.to_degrees() - expected).abs() < 0.15,
        "{}",
        last.yaw_rad.to_degrees()
    );
    // The encoders see a straight run.
    let odo = r.odometry.as_ref().unwrap().last().unwrap();
    assert!((odo.right_m - odo.left_m).abs() <= 0.0011);
}

#[test]
fn a_wider_effective_wheel_base_turns_less() {
    let nominal = scenario(6.0, "[[drive]]\nturn_deg = 90.0\n");
    let mut wide = nominal.clone();
    wide.effects.drive_wheel_base = Some(DriveWheelBase { scale: 1.1 });
    let yaw = |r: &Recording| {
        r.truth
            .as_ref()
            .unwrap()
            .last()
            .unwrap()
            .yaw_rad
            .to_degrees()
    };
    let (a, b) = (record(&nominal), record(&wide));
    assert!(
        (yaw(&a) - 90.0).abs() < 0.5,
        "the nominal robot turns 90°: {}",
        yaw(&a)
    );
    // The turn is commanded for the nominal base: it comes out 1/1.1 as large.
    assert!(
        (yaw(&b) - yaw(&a) / 1.1).abs() < 0.2,
        "{} vs {}",
        yaw(&b),
        yaw(&a)
    );
    // The encoders report the wheels' true travel, the same as commanded.
    let wheels = |r: &Recording| {
        let o = r.odometry.as_ref().unwrap().last().unwrap();
        (o.left_m, o.right_m)
    };
    let ((al, ar), (bl, br)) = (wheels(&a), wheels(&b));
    assert!((al - bl).abs() <= 0.0011 && (ar - br).abs() <= 0.0011);
    assert_eq!(
        b.meta.robot.wheel_base_m, 0.23,
        "meta.toml keeps the nominal base"
    );
}
