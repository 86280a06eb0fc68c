//! Issue 5 fixtures: the EM paper's experiment (Sec. VI), [`hilsim_calibrator::em::experiment`],
//! simulated: shared by the issue-5 tests (each includes this file with `#[path]`). As a test
//! target of its own it holds one smoke test.
#![allow(dead_code)]

#[allow(unused_imports)] // Each test uses its own few.
pub use hilsim_calibrator::em::experiment::{
    Run, LIDAR_ALPHA, LIDAR_BETA2, ODOMETER_NOISE_M, ODOMETER_SLIP, SONAR_ALPHA, SONAR_BETA0,
};
use hilsim_lidar_emulator::Emulation;
use hilsim_recording::Recording;
use hilsim_sim::Scenario;

/// A run simulated.
pub trait Record {
    /// Simulates the run; the recording carries the truth.
    ///
    /// # Panics
    /// When the scenario is invalid (a bug in the experiment).
    fn record(&self) -> Recording;
}

impl Record for Run {
    fn record(&self) -> Recording {
        let scenario = Scenario::from_toml(&self.scenario_toml(), "issue-5.toml".as_ref())
            .expect("fixture scenario is valid");
        Emulation::new(&scenario, self.seed)
            .expect("fixture sensors are valid")
            .run()
            .recording
    }
}

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
