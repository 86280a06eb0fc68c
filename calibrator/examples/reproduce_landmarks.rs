//! Reproduces the simulation study of the landmark paper (Alhashimi, Magnusson, Knorn,
//! Varagnolo, Sensors 2021, Sec. 4.1–4.2: Figs. 7–11) with the pure-maths model, then runs the
//! whole calibrator from raw scans on simulated `landmarks-5` recordings. Prints Markdown tables
//! (pasted into `docs/reproduce-landmarks.md`).
//!
//! ```text
//! cargo run --release -p hilsim-calibrator --example reproduce_landmarks            # 1000 runs
//! cargo run --release -p hilsim-calibrator --example reproduce_landmarks -- --runs 200 --seeds 10
//! ```
//!
//! Monte Carlo runs are spread over every core by rayon (`RAYON_NUM_THREADS` limits them); each
//! run draws from its own seed, so the tables do not depend on the number of cores.

use std::time::Instant;

use hilsim_calibrator::landmarks::monte_carlo::{monte_carlo, Setup, Summary};
use hilsim_calibrator::landmarks::{analyse, Estimator, Options};

struct Args {
    runs: usize,
    seeds: u64,
    seed: u64,
}

fn args() -> Args {
    let mut a = Args {
        runs: 1000,
        seeds: 20,
        seed: 2021,
    };
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let mut it = argv.iter();
    while let Some(k) = it.next() {
        let mut val = || -> u64 {
            it.next()
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| panic!("{k} needs a whole number"))
        };
        match k.as_str() {
            "--runs" => a.runs = val() as usize,
            "--seeds" => a.seeds = val(),
            "--seed" => a.seed = val(),
            other => panic!("unknown argument {other}; use --runs N, --seeds N, --seed N"),
        }
    }
    a
}

/// A study's seed from the section and point, so that every point is reproducible alone.
fn seed(base: u64, section: u64, point: u64) -> u64 {
    base.wrapping_mul(1_000_003)
        .wrapping_add(section * 10_007)
        .wrapping_add(point)
}

fn mc(setup: &Setup, runs: usize, s: u64, total: &mut usize) -> Summary {
    *total += runs;
    monte_carlo(setup, runs, s)
}

fn main() {
    let a = args();
    let threads = rayon::current_num_threads();
    println!(
        "# Landmark calibration: reproduction ({} runs per point, seed {}, {threads} threads)\n",
        a.runs, a.seed
    );
    println!(
        "Model: alpha = [0.0525, 0.8838, 0.0584], beta = 0.05 alpha, 20 positions 0.15 m apart, \
         landmarks of radius 0.12 m at random 0.5-2.5 m beside the path, 0.2-5 m from every \
         position.\n"
    );
    let start = Instant::now();
    let mut total = 0usize;

    // Fig. 7: bias and spread of the landmark position estimator vs σs, for several σθ, L = 1.
    let t = Instant::now();
    let sigmas_s = [0.001, 0.003, 0.01, 0.03, 0.1, 0.3];
    let thetas7 = [0.5, 1.0, 2.0, 5.0];
    println!("## Fig. 7: landmark position error vs sigma_s (L = 1)\n");
    println!(
        "Bias = |mean error| (radial, tangential with respect to the path's middle), spread = \
         sqrt(variance); millimetres. Paper: eq. (23) with W_l; refined: the joint refinement.\n"
    );
    println!("| sigma_theta (deg) | sigma_s (m) | paper bias radial | paper bias tangential | paper spread | refined bias radial | refined spread |");
    println!("|---|---|---|---|---|---|---|");
    for (i, th) in thetas7.iter().enumerate() {
        for (j, ss) in sigmas_s.iter().enumerate() {
            let setup = Setup::paper().landmarks(1).noise(*ss, *th);
            let s = mc(
                &setup,
                a.runs,
                seed(a.seed, 7, (i * 10 + j) as u64),
                &mut total,
            );
            let p = s.paper_positions;
            let r = s.refined_positions;
            println!(
                "| {th} | {ss} | {:.1} ± {:.1} | {:.1} ± {:.1} | {:.1} | {:.1} ± {:.1} | {:.1} |",
                p.bias_radial * 1e3,
                p.bias_se[0] * 1e3,
                p.bias_tangential * 1e3,
                p.bias_se[1] * 1e3,
                p.variance.sqrt() * 1e3,
                r.bias_radial * 1e3,
                r.bias_se[0] * 1e3,
                r.variance.sqrt() * 1e3,
            );
        }
    }
    println!("\n({:.1} s)\n", t.elapsed().as_secs_f64());

    // Fig. 8: vs the number of landmarks, σθ = 2°.
    let t = Instant::now();
    let ls = [1usize, 2, 3, 4, 5, 6, 8];
    println!("## Fig. 8: landmark position error vs L (sigma_theta = 2 deg)\n");
    println!("| sigma_s (m) | L | paper bias radial (mm) | paper spread (mm) | refined bias radial (mm) | refined spread (mm) |");
    println!("|---|---|---|---|---|---|");
    for (i, ss) in [0.01, 0.1].iter().enumerate() {
        for (j, l) in ls.iter().enumerate() {
            let setup = Setup::paper().landmarks(*l).noise(*ss, 2.0);
            let s = mc(
                &setup,
                a.runs,
                seed(a.seed, 8, (i * 10 + j) as u64),
                &mut total,
            );
            println!(
                "| {ss} | {l} | {:.1} ± {:.1} | {:.1} | {:.1} ± {:.1} | {:.1} |",
                s.paper_positions.bias_radial * 1e3,
                s.paper_positions.bias_se[0] * 1e3,
                s.paper_positions.variance.sqrt() * 1e3,
                s.refined_positions.bias_radial * 1e3,
                s.refined_positions.bias_se[0] * 1e3,
                s.refined_positions.variance.sqrt() * 1e3,
            );
        }
    }
    println!("\n({:.1} s)\n", t.elapsed().as_secs_f64());

    // Figs. 9 and 10: MSE ratio and order selection vs σθ and σs, L = 2.
    let t = Instant::now();
    let thetas = [0.1, 0.5, 1.0, 2.0, 5.0];
    let sigmas9 = [0.001, 0.01, 0.03, 0.1, 0.3];
    let mut grid: Vec<Vec<Summary>> = Vec::new();
    for (i, ss) in sigmas9.iter().enumerate() {
        let mut row = Vec::new();
        for (j, th) in thetas.iter().enumerate() {
            let setup = Setup::paper().landmarks(2).noise(*ss, *th);
            row.push(mc(
                &setup,
                a.runs,
                seed(a.seed, 9, (i * 10 + j) as u64),
                &mut total,
            ));
        }
        grid.push(row);
    }
    let fig9 = grid.len() * thetas.len() * a.runs;
    let fig9_s = t.elapsed().as_secs_f64();
    let table = |title: &str, f: &dyn Fn(&Summary) -> String| {
        println!("### {title}\n");
        print!("| sigma_s (m) \\ sigma_theta (deg) |");
        for th in thetas {
            print!(" {th} |");
        }
        println!();
        print!("|---|");
        for _ in thetas {
            print!("---|");
        }
        println!();
        for (ss, row) in sigmas9.iter().zip(&grid) {
            print!("| {ss} |");
            for s in row {
                print!(" {} |", f(s));
            }
            println!();
        }
        println!();
    };
    println!("## Fig. 9: MSE ratio (31) vs sigma_theta and sigma_s (L = 2)\n");
    println!(
        "Mean over runs, as the paper averages its points. 'Mean reading': test readings f(d) \
         without noise (the calibration's model error alone); 'noisy': fresh readings with the \
         model's noise, beta = 0.05 alpha.\n"
    );
    table("Paper, mean reading (median in brackets)", &|s| {
        format!(
            "{:.1} ({:.1})",
            s.mean_ratio.paper_mean, s.median_ratio.paper_mean
        )
    });
    table("Refined, mean reading (median in brackets)", &|s| {
        format!(
            "{:.1} ({:.1})",
            s.mean_ratio.refined_mean, s.median_ratio.refined_mean
        )
    });
    table("Paper / refined, noisy readings", &|s| {
        format!(
            "{:.2} / {:.2}",
            s.mean_ratio.paper_noisy, s.mean_ratio.refined_noisy
        )
    });
    println!("## Fig. 10: order selection (L = 2, true order 2)\n");
    table(
        "Rate of order 2: paper AIC / paper CV / refined (WLS) AIC",
        &|s| {
            format!(
                "{:.2} / {:.2} / {:.2}",
                s.order_rate(0, 2),
                s.order_rate(1, 2),
                s.order_rate(2, 2)
            )
        },
    );
    table(
        "Rate of order 1 (too simple): paper AIC / refined AIC",
        &|s| format!("{:.2} / {:.2}", s.order_rate(0, 1), s.order_rate(2, 1)),
    );
    println!(
        "(Figs. 9-10: {fig9} runs in {fig9_s:.1} s, {:.0} runs/s)\n",
        fig9 as f64 / fig9_s
    );

    // Fig. 11: MSE ratio vs L, σθ = 2°.
    let t = Instant::now();
    println!("## Fig. 11: MSE ratio vs L (sigma_theta = 2 deg), mean reading, mean over runs\n");
    println!(
        "| sigma_s (m) | L | paper | refined | paper noisy | refined noisy | paper order-2 rate |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (i, ss) in [0.01, 0.03, 0.1].iter().enumerate() {
        for (j, l) in ls.iter().enumerate() {
            let setup = Setup::paper().landmarks(*l).noise(*ss, 2.0);
            let s = mc(
                &setup,
                a.runs,
                seed(a.seed, 11, (i * 10 + j) as u64),
                &mut total,
            );
            println!(
                "| {ss} | {l} | {:.1} | {:.1} | {:.2} | {:.2} | {:.2} |",
                s.mean_ratio.paper_mean,
                s.mean_ratio.refined_mean,
                s.mean_ratio.paper_noisy,
                s.mean_ratio.refined_noisy,
                s.order_rate(0, 2)
            );
        }
    }
    println!("\n({:.1} s)\n", t.elapsed().as_secs_f64());

    // The paper's defaults, L = 5: the gain beyond the paper.
    let t = Instant::now();
    println!("## The paper's setup, L = 5: paper vs refined\n");
    println!("| sigma_s (m) | sigma_theta (deg) | paper mean reading | refined mean reading | paper noisy | refined noisy | paper spread (mm) | refined spread (mm) | paper AIC order-2 | refined AIC order-2 |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (i, (ss, th)) in [(0.01, 1.0), (0.01, 2.0), (0.03, 1.0), (0.1, 2.0)]
        .iter()
        .enumerate()
    {
        let setup = Setup::paper().noise(*ss, *th);
        let s = mc(&setup, a.runs, seed(a.seed, 12, i as u64), &mut total);
        println!(
            "| {ss} | {th} | {:.1} | {:.1} | {:.2} | {:.2} | {:.1} | {:.1} | {:.2} | {:.2} |",
            s.mean_ratio.paper_mean,
            s.mean_ratio.refined_mean,
            s.mean_ratio.paper_noisy,
            s.mean_ratio.refined_noisy,
            s.paper_positions.variance.sqrt() * 1e3,
            s.refined_positions.variance.sqrt() * 1e3,
            s.order_rate(0, 2),
            s.order_rate(2, 2),
        );
    }
    println!("\n({:.1} s)\n", t.elapsed().as_secs_f64());

    // From raw scans: landmarks-5 emulated at several seeds.
    let t = Instant::now();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/landmarks-5.toml");
    let scenario = hilsim_sim::Scenario::load(path.as_ref()).expect("landmarks-5.toml loads");
    println!(
        "## From raw scans: scenarios/landmarks-5.toml, seeds 1..={}\n",
        a.seeds
    );
    println!("| seed | detections | landmarks | worst position error (mm) | order paper / refined | MSE ratio paper | MSE ratio refined |");
    println!("|---|---|---|---|---|---|---|");
    let (mut sp, mut sr, mut n) = (0.0, 0.0, 0.0);
    let cylinders: Vec<[f64; 2]> = scenario.world.cylinders.iter().map(|c| c.center).collect();
    for sd in 1..=a.seeds {
        let rec = hilsim_lidar_emulator::Emulation::new(&scenario, sd)
            .expect("sensors build")
            .run()
            .recording;
        let paper = analyse(
            &rec,
            &Options {
                estimator: Estimator::Paper,
                ..Options::default()
            },
        );
        let refined = analyse(&rec, &Options::default());
        match (paper, refined) {
            (Ok(p), Ok(r)) => {
                let worst = r
                    .calibration
                    .landmarks
                    .iter()
                    .flatten()
                    .map(|e| {
                        cylinders
                            .iter()
                            .map(|c| (e[0] - c[0]).hypot(e[1] - c[1]))
                            .fold(f64::INFINITY, f64::min)
                    })
                    .fold(0.0, f64::max);
                let (mp, mr) = (
                    p.calibration.metrics.map_or(f64::NAN, |m| m.mse_ratio()),
                    r.calibration.metrics.map_or(f64::NAN, |m| m.mse_ratio()),
                );
                sp += mp;
                sr += mr;
                n += 1.0;
                println!(
                    "| {sd} | {} | {} | {:.1} | {} / {} | {mp:.1} | {mr:.1} |",
                    r.detections.len(),
                    r.tracks.len(),
                    worst * 1e3,
                    p.calibration.order.unwrap_or(0),
                    r.calibration.order.unwrap_or(0),
                );
            }
            (p, r) => println!("| {sd} | failed: {:?} / {:?} | | | | | |", p.err(), r.err()),
        }
    }
    println!(
        "\nMean MSE ratio over {n} seeds: paper {:.1}, refined {:.1} ({:.1} s)\n",
        sp / n,
        sr / n,
        t.elapsed().as_secs_f64()
    );
    let secs = start.elapsed().as_secs_f64();
    println!(
        "Total: {total} Monte Carlo runs in {secs:.1} s on {threads} threads ({:.0} runs/s overall).",
        total as f64 / secs
    );
}
