//! The predictive distributions `hilsim diagnose` compares data with are the emulator's
//! own: the predicted mean and spread of a reading match those of many emulated readings, on a
//! surface met obliquely (where the direction noise adds spread) and at an edge (where it splits
//! the readings between two surfaces).
//!
//! Each check is on n = 300 readings of one beam from a robot that stands still (60 s at 5
//! revolutions per second), each with its own noise; tolerances are five standard errors.

use hilsim_lidar_emulator::effects::LidarEffects;
use hilsim_lidar_emulator::prediction::LidarPredictor;
use hilsim_lidar_emulator::Emulation;
use hilsim_sim::{Pose, Scenario, World};

const SCENARIO: &str = r#"name = "still"
seed = 17
duration_s = 60.1
[world]
walls = [{ from = [2.0, -6.0], to = [2.0, 6.0] }]
cylinders = [{ center = [1.5, 1.0], radius = 0.1 }]
[robot]
start = { x = 0.0, y = 0.0 }
wheel_base_m = 0.23
[sensors.lidar]
bias = [0.0525, 0.8838, 0.0584]
noise = [0.003, 0.0, 0.002]
angle_noise_deg = 0.5
"#;

/// The readings of beam `angle` over the run.
fn readings(s: &Scenario, angle: u16) -> Vec<f64> {
    let rec = Emulation::new(s, s.seed).unwrap().run().recording;
    rec.lidar
        .unwrap()
        .iter()
        .filter(|r| r.angle_deg == f64::from(angle) && !r.invalid)
        .map(|r| r.range_m)
        .collect()
}

fn moments(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
    (m, var.sqrt())
}

#[test]
fn an_oblique_surface_is_predicted_with_the_direction_noise_in_its_spread() {
    let s = Scenario::from_toml(SCENARIO, "still.toml".as_ref()).unwrap();
    let world = World::new(&s);
    let predictor =
        LidarPredictor::new(s.sensors.lidar.as_ref().unwrap(), LidarEffects::default()).unwrap();
    // Beam 300° (−60°): the wall x = 2 at 4 m, met at 60°: the direction noise (0.5°) moves the
    // range by d tan θ σ ≈ 0.06 m, three times the range noise (0.035 m).
    let p = predictor.predict(&world, &Pose::new(0.0, 0.0, 0.0), 300.0, 0.0);
    assert_eq!(p.components.len(), 1, "{p:?}");
    let g = p.components[0];
    let v = readings(&s, 300);
    assert_eq!(v.len(), 300);
    let (m, sd) = moments(&v);
    // The sample mean's standard error is sd/√n; the sample sd's is sd/√(2n) (Gaussian).
    let n = v.len() as f64;
    assert!(
        (m - g.mean_m).abs() < 5.0 * g.sd_m / n.sqrt(),
        "{m} vs {}",
        g.mean_m
    );
    assert!(
        (sd - g.sd_m).abs() < 5.0 * g.sd_m / (2.0 * n).sqrt(),
        "{sd} vs {}",
        g.sd_m
    );
    // Without the direction noise's share the spread would be far too small.
    let range_only = 0.003 + 0.002 * 4.0f64.powi(2);
    assert!(g.sd_m > 1.5 * range_only);
}

#[test]
fn an_edge_splits_the_prediction_between_its_two_surfaces() {
    let s = Scenario::from_toml(SCENARIO, "still.toml".as_ref()).unwrap();
    let world = World::new(&s);
    let predictor =
        LidarPredictor::new(s.sensors.lidar.as_ref().unwrap(), LidarEffects::default()).unwrap();
    // The cylinder's lower edge seen from the origin: the tangent at atan2(1, 1.5) − asin(0.1 /
    // |(1.5, 1)|) = 33.69° − 3.18° = 30.51°. Beam 31° lies 0.49° inside it: about one beam in six
    // (Φ(−0.98) = 0.16) misses it and reaches the wall behind.
    let p = predictor.predict(&world, &Pose::new(0.0, 0.0, 0.0), 31.0, 0.0);
    assert!(p.near_edge);
    let v = readings(&s, 31);
    // Readings nearer than 2 m are the cylinder's (~1.7 m), the rest the wall's (~2.3 m).
    let split = 2.0;
    let near_share = v.iter().filter(|r| **r < split).count() as f64 / v.len() as f64;
    let predicted: f64 = p
        .components
        .iter()
        .filter(|c| c.mean_m < split)
        .map(|c| c.weight)
        .sum();
    // A proportion's standard error is √(p(1 − p)/n) ≤ 0.022 here (p ≈ 0.84, n = 300): 5 of them
    // is 0.11.
    assert!(
        (near_share - predicted).abs() < 0.11,
        "{near_share} vs {predicted}"
    );
    assert!(predicted > 0.7 && predicted < 0.95, "{predicted}");
}
