//! Sec. V / VI-B: reusing a calibration.

use hilsim_calibrator::em::EmOptions;
use hilsim_calibrator::target_samples::{distance_metrics, TargetSamples};
use hilsim_calibrator::{groundtruth, smoothing, Calibration, Sensor};
use hilsim_fixtures::em_experiment::Run;
use rayon::prelude::*;

use crate::common::*;

/// Sec. V / VI-B: train at 0.1 m/s, smooth the other speeds with the trained parameters.
pub fn sec6b(seeds: u64) {
    println!("## Sec. VI-B (Fig. 5): train at 0.1 m/s, reuse on the other speeds\n");
    println!(
        "Per seed: train EM (three sensor sets) and the ground-truth baseline on a 0.1 m/s run, \
         then apply them to independent runs (other seeds) at each speed: one smoother pass over \
         the whole run (known start distance), over the paper's {WINDOW}-sample windows (start \
         distance unknown: taken from the calibrated lidar), and the ground-truth model's \
         inversion. `full EM` re-runs EM on the test run itself. NMSE median (mean) over {seeds} \
         seeds.\n"
    );
    let configs = [lidar_only(), lidar_odometer(), EmOptions::default()];
    for (label, (scale, wander)) in [
        ("no actuation error", (0.0, 0.0)),
        ("actuation error", ACTUATION),
    ] {
        println!(
        "### {label}\n\n\
         | speed m/s | raw lidar | smooth lidar | smooth lidar+odo | smooth lidar+odo+sonar | windows lidar | windows lidar+odo+sonar | ground truth (test) | full EM lidar (test) |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
        for speed in SPEEDS {
            let rows: Vec<[f64; 8]> = (1..=seeds)
                .into_par_iter()
                .map(|seed| {
                    let train = Run {
                        seed,
                        scale_sd: scale,
                        wander_sd: wander,
                        ..Run::default()
                    }
                    .record();
                    let test = Run {
                        speed_mps: speed,
                        seed: 1000 + seed,
                        scale_sd: scale,
                        wander_sd: wander,
                        ..Run::default()
                    }
                    .record();
                    let trained: Vec<Calibration> = configs
                        .iter()
                        .map(|o| run_em(&train, o).calibration)
                        .collect();
                    let gt = groundtruth::calibrate(&train, &groundtruth::Options::default())
                        .expect("ground truth fits");
                    let full = run_em(&test, &lidar_only());
                    let samples = &full.samples;
                    let truth = samples.truth_m.as_ref().expect("truth");
                    let score = |est: &[Option<f64>]| {
                        distance_metrics(truth, &samples.lidar_m, est)
                            .expect("samples")
                            .nmse_calibrated
                    };
                    let whole = |cal: &Calibration, opts: &EmOptions| {
                        let e = smoothing::smooth_samples(samples, cal, opts).expect("smooths");
                        score(&e.iter().map(|e| Some(e.distance_m)).collect::<Vec<_>>())
                    };
                    let windows = |cal: &Calibration, opts: &EmOptions| {
                        let mut est = vec![None; samples.len()];
                        for start in (0..samples.len()).step_by(WINDOW) {
                            let end = (start + WINDOW).min(samples.len());
                            let w = window(samples, start, end);
                            if w.lidar_count() == 0 {
                                continue;
                            }
                            if let Ok(e) = smoothing::smooth_samples(&w, cal, opts) {
                                for (i, e) in e.iter().enumerate() {
                                    est[start + i] = Some(e.distance_m);
                                }
                            }
                        }
                        score(&est)
                    };
                    let lidar_model = &gt.sensors[&Sensor::Lidar];
                    let inverted: Vec<Option<f64>> = samples
                        .lidar_m
                        .iter()
                        .map(|y| y.and_then(|y| groundtruth::invert(&lidar_model.alpha, y)))
                        .collect();
                    [
                        full.calibration.metrics.expect("truth").nmse_raw,
                        whole(&trained[0], &configs[0]),
                        whole(&trained[1], &configs[1]),
                        whole(&trained[2], &configs[2]),
                        windows(&trained[0], &configs[0]),
                        windows(&trained[2], &configs[2]),
                        score(&inverted),
                        nmse(&full.calibration),
                    ]
                })
                .collect();
            let cells: Vec<String> = (0..8)
                .map(|i| fmt_median_mean(&rows.iter().map(|r| r[i]).collect::<Vec<_>>()))
                .collect();
            println!("| {speed} | {} |", cells.join(" | "));
        }
        println!();
    }
}

/// Samples `start..end` as a recording of their own with an unknown start distance.
fn window(s: &TargetSamples, start: usize, end: usize) -> TargetSamples {
    let c0 = s.commanded_m[start];
    TargetSamples {
        t_s: s.t_s[start..end].to_vec(),
        commanded_m: s.commanded_m[start..end].iter().map(|c| c - c0).collect(),
        lidar_m: s.lidar_m[start..end].to_vec(),
        odometer_travel_m: None,
        sonar_m: s.sonar_m.as_ref().map(|v| v[start..end].to_vec()),
        truth_m: s.truth_m.as_ref().map(|v| v[start..end].to_vec()),
        start_distance_m: None,
        beam_cos: s.beam_cos,
        turns: s.turns,
    }
}
