//! The E-step variants against each other.

use hilsim_calibrator::em::{EStep, EmOptions};
use hilsim_calibrator::{Calibration, Sensor};
use hilsim_fixtures::em_experiment::{Run, LIDAR_ALPHA};
use rayon::prelude::*;

use crate::common::*;

/// The E-step variants against each other.
pub fn estep(seeds: u64) {
    println!("## E-step variants (beyond the paper)\n");
    println!(
        "EM lidar+odo+sonar with each E-step, {seeds} seeds per row, the same recordings for \
         every variant. NMSE mean ± SE; `Δ vs paper` is the mean paired difference of NMSE \
         (variant − paper) ± its SE; `bias err` is the RMS over d ∈ [0.5, 4] m of the fitted \
         lidar bias against the true one (meaningful without actuation error only: with it, \
         the commands' unknown scale distorts α). Time per iteration: `cargo bench -p \
         hilsim-calibrator --bench em`.\n"
    );
    println!(
        "| setting | speed | E-step | NMSE | Δ vs paper | bias err mm | iterations |\n\
         |---|---|---|---|---|---|---|"
    );
    let variants = [EStep::Paper, EStep::SecondOrder, EStep::Relinearized];
    for (label, (scale, wander)) in [("no actuation", (0.0, 0.0)), ("actuation", ACTUATION)] {
        for speed in [0.1, 0.3] {
            let rows: Vec<Vec<[f64; 3]>> = (1..=seeds)
                .into_par_iter()
                .map(|seed| {
                    let rec = Run {
                        speed_mps: speed,
                        scale_sd: scale,
                        wander_sd: wander,
                        seed,
                        ..Run::default()
                    }
                    .record();
                    variants
                        .iter()
                        .map(|&v| {
                            let o = run_em(
                                &rec,
                                &EmOptions {
                                    e_step: v,
                                    ..EmOptions::default()
                                },
                            );
                            [
                                nmse(&o.calibration),
                                bias_error(&o.calibration),
                                o.calibration.iterations as f64,
                            ]
                        })
                        .collect()
                })
                .collect();
            for (vi, v) in variants.iter().enumerate() {
                let col = |i: usize| rows.iter().map(|r| r[vi][i]).collect::<Vec<_>>();
                let diff: Vec<f64> = rows.iter().map(|r| r[vi][0] - r[0][0]).collect();
                let (dm, dse) = mean_se(&diff);
                println!(
                    "| {label} | {speed} | {} | {} | {dm:+.2e} ± {dse:.1e} | {:.3} | {:.0} |",
                    v.name(),
                    fmt_mean_se(&col(0)),
                    1e3 * mean_se(&col(1)).0,
                    mean_se(&col(2)).0,
                );
            }
        }
    }
}

/// RMS over [0.5, 4] m of the fitted lidar bias minus the true bias.
fn bias_error(c: &Calibration) -> f64 {
    let a = &c.sensors[&Sensor::Lidar].alpha;
    let t = LIDAR_ALPHA;
    let n = 100;
    let sum: f64 = (0..=n)
        .map(|i| {
            let d = 0.5 + 3.5 * i as f64 / n as f64;
            let fit = a[0] + a[1] * d + a[2] * d * d;
            let truth = t[0] + t[1] * d + t[2] * d * d;
            (fit - truth).powi(2)
        })
        .sum();
    (sum / (n + 1) as f64).sqrt()
}
