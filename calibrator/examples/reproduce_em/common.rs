//! What the sections share: the experiment's settings, statistics and tables.

use hilsim_calibrator::em::{self, EmOptions, EmOutcome};
use hilsim_calibrator::stats::median;
use hilsim_calibrator::target_samples::{distance_metrics, TargetSamples};
use hilsim_calibrator::Calibration;

/// The paper's speeds (Sec. VI).
pub const SPEEDS: [f64; 3] = [0.1, 0.2, 0.3];
/// The actuation error of the runs "with actuation error": a fixed speed-scale error of sd 2 %
/// and a wander of sd 1 % with a 10 s correlation time.
pub const ACTUATION: (f64, f64) = (0.02, 0.01);
/// The paper's Sec. V test windows: 12 samples.
pub const WINDOW: usize = 12;

/// Mean and standard error.
pub fn mean_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, (var / n).sqrt())
}

/// "median (mean)" of NMSE values: the mean of runs with a speed-scale error is dominated by
/// the few runs with the largest errors.
pub fn fmt_median_mean(v: &[f64]) -> String {
    let (m, _) = mean_se(v);
    format!("{:.2e} ({m:.2e})", median(&mut v.to_vec()))
}

pub fn fmt_mean_se(v: &[f64]) -> String {
    let (m, se) = mean_se(v);
    format!("{m:.2e} ± {se:.1e}")
}

pub fn lidar_only() -> EmOptions {
    EmOptions {
        use_odometer: false,
        use_sonar: false,
        ..EmOptions::default()
    }
}

pub fn lidar_odometer() -> EmOptions {
    EmOptions {
        use_sonar: false,
        ..EmOptions::default()
    }
}

pub fn nmse(c: &Calibration) -> f64 {
    c.metrics.expect("the simulation has truth").nmse_calibrated
}

/// NMSE of dead reckoning (start + commanded displacement) over the valid lidar samples.
pub fn dead_reckoning_nmse(s: &TargetSamples) -> f64 {
    let truth = s.truth_m.as_ref().expect("truth");
    let dr: Vec<Option<f64>> = (0..s.len()).map(|k| s.dead_reckoning(k)).collect();
    distance_metrics(truth, &s.lidar_m, &dr)
        .expect("samples")
        .nmse_calibrated
}

pub fn run_em(rec: &hilsim_recording::Recording, opts: &EmOptions) -> EmOutcome {
    em::run(rec, opts).unwrap_or_else(|e| panic!("EM failed: {e}"))
}
