//! Reproduces the numerical results of the EM paper (Alhashimi, Varagnolo, Gustafsson, IEEE
//! Sensors J. 2017, Sec. VI) in simulation, and measures this implementation's own choices.
//!
//! ```text
//! cargo run --release -p hilsim-calibrator --example reproduce_em -- [SECTION…] [--seeds N] [--runs N]
//! ```
//!
//! Sections (default: all): `fig3` (Sec. VI-A), `sec6b` (Sec. V reuse), `sec6c` (heading
//! errors), `estep` (the E-step variants), `qnoise` (the process-noise scale). `--seeds` sets
//! the runs per cell of `fig3`, `sec6b`, `estep`, `qnoise` (default 20); `--runs` the runs per
//! heading of `sec6c` (default 100); `--step` its heading step in degrees (default 0.25).
//! Prints Markdown tables; `docs/reproduce-em.md` holds their output.

#[path = "../tests/issue_5_fixtures.rs"]
mod fixtures;

use std::time::Instant;

use fixtures::Run;
use hilsim_calibrator::em::{self, EStep, EmOptions, EmOutcome};
use hilsim_calibrator::target_samples::{distance_metrics, TargetSamples};
use hilsim_calibrator::{groundtruth, smoothing, Calibration, Sensor};
use rayon::prelude::*;

/// The paper's speeds (Sec. VI).
const SPEEDS: [f64; 3] = [0.1, 0.2, 0.3];
/// The actuation error of the runs "with actuation error": a fixed speed-scale error of sd 2 %
/// and a wander of sd 1 % with a 10 s correlation time (issue 5's example values).
const ACTUATION: (f64, f64) = (0.02, 0.01);
/// The paper's Sec. V test windows: 12 samples.
const WINDOW: usize = 12;

struct Args {
    sections: Vec<String>,
    seeds: u64,
    runs: u64,
    step_deg: f64,
}

fn parse_args() -> Args {
    let mut args = Args {
        sections: Vec::new(),
        seeds: 20,
        runs: 100,
        step_deg: 0.25,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .and_then(|v| v.parse::<f64>().ok())
                .unwrap_or_else(|| panic!("{name} needs a number"))
        };
        match a.as_str() {
            "--seeds" => args.seeds = value("--seeds") as u64,
            "--runs" => args.runs = value("--runs") as u64,
            "--step" => args.step_deg = value("--step"),
            s => args.sections.push(s.to_string()),
        }
    }
    if args.sections.is_empty() || args.sections.iter().any(|s| s == "all") {
        args.sections = ["fig3", "sec6b", "sec6c", "estep", "qnoise"]
            .map(String::from)
            .to_vec();
    }
    args
}

fn main() {
    let args = parse_args();
    println!(
        "<!-- reproduce_em {} --seeds {} --runs {} --step {}; {} threads -->",
        args.sections.join(" "),
        args.seeds,
        args.runs,
        args.step_deg,
        rayon::current_num_threads()
    );
    for section in &args.sections {
        let t = Instant::now();
        match section.as_str() {
            "fig3" => fig3(args.seeds),
            "sec6b" => sec6b(args.seeds),
            "sec6c" => sec6c(args.runs, args.step_deg),
            "estep" => estep(args.seeds),
            "qnoise" => qnoise(args.seeds),
            other => panic!("unknown section {other}"),
        }
        println!(
            "\n_{section}: {:.1} s wall-clock_\n",
            t.elapsed().as_secs_f64()
        );
    }
}

/// Mean and standard error.
fn mean_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, (var / n).sqrt())
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// "median (mean)" of NMSE values: the mean of runs with a speed-scale error is dominated by
/// the few runs with the largest errors.
fn fmt_median_mean(v: &[f64]) -> String {
    let (m, _) = mean_se(v);
    format!("{:.2e} ({m:.2e})", median(v))
}

fn fmt_mean_se(v: &[f64]) -> String {
    let (m, se) = mean_se(v);
    format!("{m:.2e} ± {se:.1e}")
}

fn lidar_only() -> EmOptions {
    EmOptions {
        use_odometer: false,
        use_sonar: false,
        ..EmOptions::default()
    }
}

fn lidar_odometer() -> EmOptions {
    EmOptions {
        use_sonar: false,
        ..EmOptions::default()
    }
}

fn nmse(c: &Calibration) -> f64 {
    c.metrics.expect("the simulation has truth").nmse_calibrated
}

/// NMSE of dead reckoning (start + commanded displacement) over the valid lidar samples.
fn dead_reckoning_nmse(s: &TargetSamples) -> f64 {
    let truth = s.truth_m.as_ref().expect("truth");
    let dr: Vec<Option<f64>> = (0..s.len()).map(|k| s.dead_reckoning(k)).collect();
    distance_metrics(truth, &s.lidar_m, &dr)
        .expect("samples")
        .nmse_calibrated
}

fn run_em(rec: &hilsim_recording::Recording, opts: &EmOptions) -> EmOutcome {
    em::run(rec, opts).unwrap_or_else(|e| panic!("EM failed: {e}"))
}

/// Sec. VI-A, Fig. 3: NMSE per estimator and speed, with and without actuation error.
fn fig3(seeds: u64) {
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
                format!("{:.3} ({min:.3}–{max:.3})", median(&r))
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

/// Sec. V / VI-B: train at 0.1 m/s, smooth the other speeds with the trained parameters.
fn sec6b(seeds: u64) {
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

/// Sec. VI-C, Figs. 8–9: heading errors.
fn sec6c(runs: u64, step_deg: f64) {
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
        fixtures::LIDAR_ALPHA[0],
        fixtures::LIDAR_ALPHA[1],
        fixtures::LIDAR_ALPHA[2],
        fixtures::LIDAR_BETA2,
        fixtures::SONAR_ALPHA[1]
    );
}

/// The E-step variants against each other.
fn estep(seeds: u64) {
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
    let t = fixtures::LIDAR_ALPHA;
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

/// Sensitivity to the assumed process noise, and estimating it.
fn qnoise(seeds: u64) {
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
