//! A sensor that reports nothing the world could give — every reading invalid, or one value
//! whatever it faces — is a mismatch the verdict names, never a sensor left out of the
//! comparison while the rest "agrees with the simulation".
//!
//! A short run (13 s in a 4 m × 3 m room) with truth; no catalogued effect is tried, so each
//! diagnosis is quick and the verdict is the health check's and the tests' alone.

use std::path::Path;
use std::sync::OnceLock;

use hilsim_diagnose::{diagnose, Diagnosis, Options, Sensor, SimPhysics, Verdict};
use hilsim_fixtures::rooms::ROOM_4X3;
use hilsim_lidar_emulator::Emulation;
use hilsim_recording::Recording;
use hilsim_sim::Scenario;

/// The room's furniture (added to [`ROOM_4X3`]'s `[world]`), robot, drive and sensors.
const FURNISHED: &str = r#"cylinders = [{ center = [2.8, 1.9], radius = 0.12 }]

[robot]
start = { x = 0.8, y = 0.8, yaw_deg = 0.0 }
wheel_base_m = 0.23
turn_rate_deg_s = 60.0

[[drive]]
stop_s = 0.5
[[drive]]
speed_mps = 0.3
distance_m = 1.5
[[drive]]
turn_deg = 90.0
[[drive]]
speed_mps = 0.25
distance_m = 1.0
[[drive]]
stop_s = 0.5

[sensors.lidar]
bias = [0.0525, 0.8838, 0.0584]
noise = [0.003, 0.0, 0.002]
[sensors.sonar]
bias = [0.021, 1.028]
noise = [0.008]
max_range_m = 5.0
[sensors.odometer]
noise_m = 0.002
"#;

fn scenario() -> Scenario {
    let text = format!("name = \"dead-sensor-room\"\nseed = 3\n\n{ROOM_4X3}{FURNISHED}");
    Scenario::from_toml(&text, Path::new("dead-sensor-room.toml")).expect("the test's scenario")
}

/// The room's run, recorded once for every test of this module (each changes its own copy).
fn recording() -> Recording {
    static RUN: OnceLock<Recording> = OnceLock::new();
    RUN.get_or_init(|| {
        Emulation::new(&scenario(), 3)
            .expect("the emulation")
            .run()
            .recording
    })
    .clone()
}

fn diagnosed(recording: &Recording) -> Diagnosis {
    let physics = SimPhysics::new(&scenario()).expect("the physics");
    let options = Options {
        effects: Vec::new(),
        ..Options::default()
    };
    diagnose(&physics, recording, &options).expect("a diagnosis")
}

fn assert_names_dead(d: &Diagnosis, sensor: Sensor, word: &str) {
    assert_eq!(d.verdict, Verdict::Unexplained, "{}", d.explanation);
    assert_eq!(d.unexplained.first().map(|e| e.sensor), Some(sensor));
    assert!(d.explanation.contains(word), "{}", d.explanation);
}

#[test]
fn a_faithful_run_is_healthy() {
    let d = diagnosed(&recording());
    assert_eq!(d.verdict, Verdict::None, "{}", d.explanation);
}

#[test]
fn a_lidar_stuck_at_one_range_is_a_mismatch() {
    let mut rec = recording();
    for s in rec.lidar.as_mut().unwrap() {
        s.range_m = 2.5;
    }
    assert_names_dead(&diagnosed(&rec), Sensor::Lidar, "stuck");
}

#[test]
fn a_lidar_whose_every_reading_is_invalid_is_a_mismatch() {
    let mut rec = recording();
    for s in rec.lidar.as_mut().unwrap() {
        s.invalid = true;
    }
    assert_names_dead(&diagnosed(&rec), Sensor::Lidar, "dead");
}

#[test]
fn a_sonar_stuck_at_one_range_is_a_mismatch() {
    let mut rec = recording();
    for s in rec.sonar.as_mut().unwrap() {
        s.range_m = 1.0;
    }
    assert_names_dead(&diagnosed(&rec), Sensor::Sonar, "stuck");
}
