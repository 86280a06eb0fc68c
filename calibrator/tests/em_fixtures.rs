//! Fixtures: a smoke test of the simulated experiment the EM tests share
//! (`fixtures/mod.rs`).

mod fixtures;

use fixtures::{Record, Run};

#[test]
fn the_fixture_runs_the_papers_experiment() {
    let rec = Run {
        speed_mps: 0.3,
        ..Run::default()
    }
    .record();
    let d0 = rec.meta.world.target_start_distance_m.unwrap();
    assert!((d0 - 0.5).abs() < 1e-3, "start distance {d0}");
    assert!(rec.sonar.is_some() && rec.odometry.is_some() && rec.truth.is_some());
}
