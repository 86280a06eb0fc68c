//! Sec. VI-A, Fig. 3.

use hilsim_calibrator::em::{EStep, EmOptions};
use hilsim_calibrator::groundtruth;
use hilsim_calibrator::stats::median;
use hilsim_fixtures::em_experiment::Run;
use rayon::prelude::*;

use crate::common::*;

/// Sec. VI-A, Fig. 3: NMSE per estimator and speed, with and without actuation error.
pub fn fig3(seeds: u64) {
    println!("## Sec. VI-A (Fig. 3): NMSE of the distance estimates\n");
    println!(
        "{seeds} seeds per cell; reverse from 0.5 m to 4 m; the paper's NMSE over the samples \
         with a valid lidar reading. EM: default options (E-step `{}`, q = {}, SQUAREM). \
         Dead reckoning: the start distance plus the commanded displacement.\n",
        EStep::default().name(),
        EmOptions::default().process_noise_rel
    );
    for (label, (scale, wander)) in [
        ("no actuation error", (0.0, 0.0)),
        ("actuation error", ACTUATION),
    ] {
        println!(
            "### {label} (scale_sd = {scale}, wander_sd = {wander})\n\n\
             NMSE median (mean) over the seeds.\n\n\
             | speed m/s | raw lidar | dead reckoning | EM lidar | EM lidar+sonar | EM lidar+odo | EM lidar+odo+sonar | ground truth (train) |\n\
             |---|---|---|---|---|---|---|---|"
        );
        let mut ratio_rows = Vec::new();
        for speed in SPEEDS {
            let rows: Vec<[f64; 7]> = (1..=seeds)
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
                    let l = run_em(&rec, &lidar_only());
                    let lo = run_em(&rec, &lidar_odometer());
                    let los = run_em(&rec, &EmOptions::default());
                    let ls = run_em(
                        &rec,
                        &EmOptions {
                            use_odometer: false,
                            ..EmOptions::default()
                        },
                    );
                    let gt = groundtruth::calibrate(&rec, &groundtruth::Options::default())
                        .expect("ground truth fits");
                    let m = l.calibration.metrics.expect("truth");
                    [
                        m.nmse_raw,
                        dead_reckoning_nmse(&l.samples),
                        m.nmse_calibrated,
                        nmse(&lo.calibration),
                        nmse(&los.calibration),
                        nmse(&gt),
                        nmse(&ls.calibration),
                    ]
                })
                .collect();
            let col = |i: usize| rows.iter().map(|r| r[i]).collect::<Vec<_>>();
            println!(
                "| {speed} | {} | {} | {} | {} | {} | {} | {} |",
                fmt_median_mean(&col(0)),
                fmt_median_mean(&col(1)),
                fmt_median_mean(&col(2)),
                fmt_median_mean(&col(6)),
                fmt_median_mean(&col(3)),
                fmt_median_mean(&col(4)),
                fmt_median_mean(&col(5)),
            );
            let ratio = |a: usize, b: usize| {
                let r: Vec<f64> = rows.iter().map(|r| r[a] / r[b]).collect();
                let min = r.iter().copied().fold(f64::INFINITY, f64::min);
                let max = r.iter().copied().fold(0.0, f64::max);
                format!("{:.3} ({min:.3}–{max:.3})", median(&mut r.to_vec()))
            };
            ratio_rows.push(format!(
                "| {speed} | {} | {} | {} | {} | {} |",
                ratio(0, 2),
                ratio(2, 3),
                ratio(2, 4),
                ratio(1, 3),
                ratio(0, 5)
            ));
        }
        println!(
            "\nRatios of NMSE per run, median (min–max): the paper's \"MSE falls 3–6×\" is raw / \
             EM lidar; its \"sonar adds up to 1.2×\" is EM lidar / EM lidar+odo+sonar.\n\n\
             | speed m/s | raw / EM lidar | EM lidar / EM lidar+odo | EM lidar / EM lidar+odo+sonar | dead reckoning / EM lidar+odo | raw / ground truth |\n\
             |---|---|---|---|---|---|"
        );
        for r in ratio_rows {
            println!("{r}");
        }
        println!();
    }
}
