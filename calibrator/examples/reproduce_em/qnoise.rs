//! Sensitivity to the assumed process noise, and estimating it.

use hilsim_calibrator::em::EmOptions;
use hilsim_fixtures::em_experiment::Run;
use rayon::prelude::*;

use crate::common::*;

/// Sensitivity to the assumed process noise, and estimating it.
pub fn qnoise(seeds: u64) {
    println!("## Process-noise scale q (the paper's σ_d, \"assumed known\")\n");
    println!(
        "EM lidar+odo+sonar at 0.1 m/s, {seeds} seeds; NMSE mean ± SE and iterations.\n\n\
         | setting | q | NMSE | iterations | q at the end |\n|---|---|---|---|---|"
    );
    let qs: [(f64, bool); 6] = [
        (0.005, false),
        (0.01, false),
        (0.02, false),
        (0.05, false),
        (0.1, false),
        (0.02, true),
    ];
    for (label, (scale, wander)) in [("no actuation", (0.0, 0.0)), ("actuation", ACTUATION)] {
        let rows: Vec<Vec<[f64; 3]>> = (1..=seeds)
            .into_par_iter()
            .map(|seed| {
                let rec = Run {
                    scale_sd: scale,
                    wander_sd: wander,
                    seed,
                    ..Run::default()
                }
                .record();
                qs.iter()
                    .map(|&(q, estimate)| {
                        let o = run_em(
                            &rec,
                            &EmOptions {
                                process_noise_rel: q,
                                estimate_process_noise: estimate,
                                ..EmOptions::default()
                            },
                        );
                        [
                            nmse(&o.calibration),
                            o.calibration.iterations as f64,
                            o.process_noise_rel,
                        ]
                    })
                    .collect()
            })
            .collect();
        for (qi, (q, estimate)) in qs.iter().enumerate() {
            let col = |i: usize| rows.iter().map(|r| r[qi][i]).collect::<Vec<_>>();
            println!(
                "| {label} | {}{q} | {} | {:.0} | {:.4} |",
                if *estimate { "estimated from " } else { "" },
                fmt_mean_se(&col(0)),
                mean_se(&col(1)).0,
                mean_se(&col(2)).0,
            );
        }
    }
}
