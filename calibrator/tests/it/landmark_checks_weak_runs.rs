//! The landmark calibrator on a run it cannot calibrate — two stops 0.6 m apart, landmarks 1 to
//! 3 m away — returned a straight line for a quadratic bias with every check passed: the
//! distance span was counted over all landmarks (metres, near and far ones together) while each
//! landmark was seen over the 0.6 m step only, and nothing counted the stops. Such a run must
//! fail `landmarks.stops` and `landmarks.distance_span_m`; landmarks-5 must pass every check.

use hilsim_calibrator::landmarks::checks::{stops_needed, MIN_DISTANCE_SPAN_M};
use hilsim_calibrator::landmarks::{analyse, Options};
use hilsim_calibrator::Calibration;
use hilsim_sim::Scenario;

/// Two stops 0.6 m apart among four cylinders 1-3 m away, the papers' quadratic bias and noise
/// (the landmark paper's Sec. 4.1).
const TWO_STOPS: &str = r#"
name = "two-stops"
description = "two stops 0.6 m apart among landmarks 1-3 m away"
[world]
cylinders = [
    { center = [1.0, 1.2], radius = 0.12 },
    { center = [2.0, -1.1], radius = 0.12 },
    { center = [3.0, 1.6], radius = 0.12 },
    { center = [0.2, -1.5], radius = 0.12 },
]
walls = [
    { from = [-1.5, -3.0], to = [6.0, -3.0] },
    { from = [6.0, -3.0], to = [6.0, 3.0] },
    { from = [6.0, 3.0], to = [-1.5, 3.0] },
    { from = [-1.5, 3.0], to = [-1.5, -3.0] },
]
[robot]
start = { x = 0.0, y = 0.0 }
wheel_base_m = 0.23
[[drive]]
stop_s = 2.0
[[drive]]
speed_mps = 0.1
distance_m = 0.6
[[drive]]
stop_s = 2.0
[sensors.lidar]
bias = [0.0525, 0.8838, 0.0584]
noise = [0.002625, 0.04419, 0.00292]
angle_noise_deg = 0.5
"#;

fn check<'a>(cal: &'a Calibration, name: &str) -> &'a hilsim_calibrator::checks::Check {
    cal.checks
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("{name} missing: {:#?}", cal.checks))
}

#[test]
fn two_stops_at_close_distances_fail_the_stop_count_and_the_span() {
    let scenario = Scenario::from_toml(TWO_STOPS, "two-stops.toml".as_ref()).expect("parses");
    // Seed 3 drew the reported result (a line, every check passed); the checks must not depend
    // on the draw, so four seeds.
    for seed in 1..=4 {
        let rec = hilsim_lidar_emulator::Emulation::new(&scenario, seed)
            .expect("sensors build")
            .run()
            .recording;
        let a = analyse(&rec, &Options::default()).expect("calibrates, with failed checks");
        let cal = &a.calibration;
        assert_eq!(a.stops.len(), 2, "seed {seed}");
        // The cause: across landmarks the distances span over the old 1 m threshold.
        let ranges: Vec<f64> = a
            .estimate
            .used
            .iter()
            .map(|&i| a.observations.observations[i].range_m)
            .collect();
        let across = ranges.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - ranges.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(across > 1.0, "seed {seed}: {across} m across landmarks");
        let stops = check(cal, "landmarks.stops");
        assert!(!stops.pass, "seed {seed}: {stops:?}");
        assert_eq!(stops.value, 2.0, "seed {seed}");
        assert_eq!(
            stops.threshold,
            stops_needed(2.max(cal.order.unwrap_or(0))) as f64
        );
        assert!(
            stops.detail.contains("order 2 (the papers' quadratic) 4"),
            "{}",
            stops.detail
        );
        // Along one landmark: at most the 0.6 m step between the stops.
        let span = check(cal, "landmarks.distance_span_m");
        assert!(
            !span.pass && span.value <= 0.6 + 1e-9,
            "seed {seed}: {span:?}"
        );
        assert_eq!(span.threshold, MIN_DISTANCE_SPAN_M);
    }
}

#[test]
fn landmarks_5_passes_every_check() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/landmarks-5.toml");
    let scenario = Scenario::load(path.as_ref()).expect("landmarks-5.toml loads");
    let rec = hilsim_lidar_emulator::Emulation::new(&scenario, scenario.seed)
        .expect("sensors build")
        .run()
        .recording;
    let cal = analyse(&rec, &Options::default())
        .expect("calibrates")
        .calibration;
    for c in &cal.checks {
        assert!(c.pass, "{c:?}");
    }
    // Eleven stops over 3 m: the cylinder at (4.2, -0.5) m, approached, is seen over 1.2-4.1 m.
    assert_eq!(check(&cal, "landmarks.stops").value, 11.0);
    assert!(check(&cal, "landmarks.distance_span_m").value > 2.5);
}
