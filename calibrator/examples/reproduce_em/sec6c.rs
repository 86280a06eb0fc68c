//! Sec. VI-C, Figs. 8–9: heading errors.

use hilsim_calibrator::em::EmOptions;
use hilsim_calibrator::Sensor;
use hilsim_fixtures::em_experiment::{Run, LIDAR_ALPHA, LIDAR_BETA2, SONAR_ALPHA};
use rayon::prelude::*;

use crate::common::*;

/// Sec. VI-C, Figs. 8–9: heading errors.
pub fn sec6c(runs: u64, step_deg: f64) {
    println!("## Sec. VI-C (Figs. 8–9): heading error\n");
    println!(
        "The robot starts rotated by the heading error from facing the board squarely \
         (`robot.start.yaw_deg = 180 + error`) and reverses along its heading at 0.1 m/s; \
         {runs} runs per heading, no actuation error (so that the ±2 % scale scatter does not \
         mask the heading's effect); EM lidar-only and lidar+odo+sonar. Mean over the runs \
         (the SE of the NMSE is given once per row).\n"
    );
    println!(
        "| heading ° | raw NMSE | EM lidar NMSE | EM l+o+s NMSE | α0 | α1 | α2 | β2 | sonar α1 |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
    let n = (5.0 / step_deg).round() as i64;
    for i in -n..=n {
        let heading = i as f64 * step_deg;
        let rows: Vec<[f64; 8]> = (1..=runs)
            .into_par_iter()
            .map(|seed| {
                let rec = Run {
                    heading_error_deg: heading,
                    scale_sd: 0.0,
                    wander_sd: 0.0,
                    seed,
                    ..Run::default()
                }
                .record();
                let l = run_em(&rec, &lidar_only());
                let los = run_em(&rec, &EmOptions::default());
                let lidar = &l.calibration.sensors[&Sensor::Lidar];
                let sonar = &los.calibration.sensors[&Sensor::Sonar];
                let m = l.calibration.metrics.expect("truth");
                [
                    m.nmse_raw,
                    m.nmse_calibrated,
                    nmse(&los.calibration),
                    lidar.alpha[0],
                    lidar.alpha[1],
                    lidar.alpha[2],
                    lidar.beta[2],
                    sonar.alpha[1],
                ]
            })
            .collect();
        let col = |i: usize| rows.iter().map(|r| r[i]).collect::<Vec<_>>();
        println!(
            "| {heading:+.2} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.5} | {:.4} |",
            fmt_mean_se(&col(0)),
            fmt_mean_se(&col(1)),
            fmt_mean_se(&col(2)),
            mean_se(&col(3)).0,
            mean_se(&col(4)).0,
            mean_se(&col(5)).0,
            mean_se(&col(6)).0,
            mean_se(&col(7)).0,
        );
    }
    println!(
        "\nTrue values: α = [{}, {}, {}], β2 = {}, sonar α1 = {} (times cos(heading) for the \
         sonar, which reads the perpendicular distance).",
        LIDAR_ALPHA[0], LIDAR_ALPHA[1], LIDAR_ALPHA[2], LIDAR_BETA2, SONAR_ALPHA[1]
    );
}
