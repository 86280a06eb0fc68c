//! A run must be a pure function of (scenario, seed): the same seed gives the same
//! samples in process and on disk, each sensor draws from its own stream (adding a sonar leaves
//! the lidar's samples alone), and another seed gives other noise.

use hilsim_lidar_emulator::Emulation;
use hilsim_recording::{LidarSample, OdometrySample, Recording, SonarSample};
use hilsim_sim::Scenario;

/// The robot reverses from a board in a room, turns and drives on, with every sensor noisy and
/// the lidar's motor wobbling. `sensors` are the `[sensors.*]` tables.
fn scenario(sensors: &str) -> Scenario {
    let text = format!(
        r#"
        name = "determinism"
        [world]
        boards = [{{ center = [-0.009, 0.0], length = 1.2 }}]
        cylinders = [{{ center = [2.0, 1.5], radius = 0.1 }}]
        walls = [
            {{ from = [-0.5, -3.0], to = [5.0, -3.0] }},
            {{ from = [5.0, -3.0], to = [5.0, 3.0] }},
            {{ from = [5.0, 3.0], to = [-0.5, 3.0] }},
            {{ from = [-0.5, 3.0], to = [-0.5, -3.0] }},
        ]
        [robot]
        start = {{ x = 0.5, y = 0.0, yaw_deg = 180.0 }}
        wheel_base_m = 0.23
        [[drive]]
        speed_mps = -0.3
        distance_m = 0.6
        [[drive]]
        turn_deg = 45.0
        [[drive]]
        speed_mps = 0.2
        distance_m = 0.2
        {sensors}
        "#
    );
    Scenario::from_toml(&text, "determinism.toml".as_ref()).unwrap()
}

/// A noisy lidar at a steady 300 rpm.
const STEADY_LIDAR: &str = r#"
        [sensors.lidar]
        bias = [0.0525, 0.8838, 0.0584]
        noise = [0.0, 0.0, 0.004]
        angle_noise_deg = 0.5
"#;
/// The same with its motor wobbling by ±3 rpm (a seeded phase: a stream of its own).
const LIDAR: &str = r#"
        [sensors.lidar]
        bias = [0.0525, 0.8838, 0.0584]
        noise = [0.0, 0.0, 0.004]
        angle_noise_deg = 0.5
        rpm_wobble = 3.0
"#;
const SONAR: &str = r#"
        [sensors.sonar]
        bias = [0.021, 1.028]
        noise = [0.008]
"#;
const ODOMETER: &str = r#"
        [sensors.odometer]
        slip = 0.027
        noise_m = 0.004
"#;

/// Every sample of a run, taken step by step in process.
#[derive(Debug, PartialEq)]
struct Samples {
    lidar: Vec<LidarSample>,
    sonar: Vec<SonarSample>,
    odometry: Vec<OdometrySample>,
}

fn step_through(s: &Scenario, seed: u64) -> Samples {
    let mut emulation = Emulation::new(s, seed).unwrap();
    let mut out = Samples {
        lidar: Vec::new(),
        sonar: Vec::new(),
        odometry: Vec::new(),
    };
    while let Some(step) = emulation.step() {
        out.lidar.extend(step.lidar.iter().map(|r| r.to_sample()));
        out.sonar.extend_from_slice(&step.sonar);
        out.odometry.extend_from_slice(&step.odometry);
    }
    out
}

#[test]
fn the_same_seed_gives_identical_samples_in_process_and_on_disk() {
    let s = scenario(&format!("{LIDAR}{SONAR}{ODOMETER}"));
    let first = step_through(&s, 42);
    // 2 s reversing, 1 s turning at 45°/s, 1 s forward: 4 s of samples from every sensor.
    // 4 s at 1,800 readings/s, give or take the ±1 % wobble.
    assert!(
        first.lidar.len().abs_diff(7200) <= 72,
        "{}",
        first.lidar.len()
    );
    assert_eq!(first.sonar.len(), 40);
    assert_eq!(first.odometry.len(), 80);
    // Identical, bit for bit (`==` on every f64), a second time in the same process.
    assert_eq!(step_through(&s, 42), first);

    // `run` collects exactly what `step` yields (the lidar's whole revolutions only, as a real
    // unit delivers them), and the recording survives the disk unchanged (floats are written in
    // shortest round-trip form).
    let recording = Emulation::new(&s, 42).unwrap().run().recording;
    let whole_revolutions = first.lidar.len() - first.lidar.len() % 360;
    assert_eq!(
        recording.lidar.as_deref(),
        Some(&first.lidar[..whole_revolutions])
    );
    assert_eq!(recording.sonar.as_deref(), Some(&first.sonar[..]));
    assert_eq!(recording.odometry.as_deref(), Some(&first.odometry[..]));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run");
    recording.write_dir(&path).unwrap();
    let back = Recording::read_dir(&path).unwrap();
    assert_eq!(back, recording);
    // And writing it again gives byte-identical files.
    let again = dir.path().join("again");
    Emulation::new(&s, 42)
        .unwrap()
        .run()
        .recording
        .write_dir(&again)
        .unwrap();
    for (name, _) in recording.tables() {
        let a = std::fs::read(path.join(name)).unwrap();
        let b = std::fs::read(again.join(name)).unwrap();
        assert!(a == b, "{name} differs between two runs of the same seed");
    }
}

#[test]
fn adding_a_sensor_does_not_change_another_sensors_samples() {
    let lidar_only = step_through(&scenario(LIDAR), 42);
    let all = step_through(&scenario(&format!("{LIDAR}{SONAR}{ODOMETER}")), 42);
    assert!(!lidar_only.lidar.is_empty());
    assert_eq!(lidar_only.lidar, all.lidar);
    let sonar_only = step_through(&scenario(SONAR), 42);
    assert!(!sonar_only.sonar.is_empty());
    assert_eq!(sonar_only.sonar, all.sonar);
    let odometer_only = step_through(&scenario(ODOMETER), 42);
    assert_eq!(odometer_only.odometry, all.odometry);
}

#[test]
fn another_seed_gives_other_noise_on_the_same_trajectory() {
    // A steady motor, so that both runs read at the same instants and angles.
    let s = scenario(&format!("{STEADY_LIDAR}{SONAR}{ODOMETER}"));
    let a = Emulation::new(&s, 42).unwrap().run().recording;
    let b = Emulation::new(&s, 43).unwrap().run().recording;
    // The world and the drive do not depend on the seed.
    assert_eq!(a.truth, b.truth);
    assert_eq!(a.commands, b.commands);
    let (la, lb) = (a.lidar.unwrap(), b.lidar.unwrap());
    assert_eq!(la.len(), lb.len());
    let mut both_valid = 0;
    let mut differ = 0;
    for (x, y) in la.iter().zip(&lb) {
        assert_eq!((x.t_s, x.rev, x.angle_deg), (y.t_s, y.rev, y.angle_deg));
        if !x.invalid && !y.invalid {
            both_valid += 1;
            differ += usize::from(x.range_m != y.range_m);
        }
    }
    // Here σ = 4 mm·d² with d ≳ 0.3 m: at least ~0.4 mm, mostly several mm. Two independent draws
    // reported in whole millimetres coincide with probability ≈ 1/(2√π·σ/mm) when σ ≳ 1 mm, so
    // most readings must differ (the angle noise moves the true range too).
    assert!(both_valid > 5000, "{both_valid}");
    assert!(
        differ * 10 > both_valid * 8,
        "{differ} of {both_valid} differ"
    );
    let (sa, sb) = (a.sonar.unwrap(), b.sonar.unwrap());
    assert_eq!(sa.len(), sb.len());
    let sonar_differ = sa
        .iter()
        .zip(&sb)
        .filter(|(x, y)| x.range_m != y.range_m)
        .count();
    // σ = 8 mm against 1 mm resolution: two draws agree with probability ≈ 1/(2√π·8) ≈ 3.5 %.
    assert!(
        sonar_differ * 10 > sa.len() * 8,
        "{sonar_differ} of {}",
        sa.len()
    );
    let (oa, ob) = (a.odometry.unwrap(), b.odometry.unwrap());
    let odometry_differ = oa.iter().zip(&ob).filter(|(x, y)| x != y).count();
    // σ = 4 mm per reading against 1 mm ticks: most readings differ (at t = 0 too: noise is added
    // to every reading).
    assert!(
        odometry_differ * 10 > oa.len() * 8,
        "{odometry_differ} of {}",
        oa.len()
    );
}
