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
//!
//! One module per table or figure: `fig7`, `fig8`, `fig9_10`, `fig11`, `paper_setup` (the
//! paper's setup with five landmarks), `raw_scans` (the calibrator on emulated recordings).

mod fig11;
mod fig7;
mod fig8;
mod fig9_10;
mod paper_setup;
mod raw_scans;

use std::time::Instant;

use hilsim_fixtures::landmark_study::{monte_carlo, Setup, Summary};

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

/// The numbers of landmarks of Figs. 8 and 11.
const LANDMARK_COUNTS: [usize; 7] = [1, 2, 3, 4, 5, 6, 8];

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
    fig7::run(&a, &mut total);
    fig8::run(&a, &mut total);
    fig9_10::run(&a, &mut total);
    fig11::run(&a, &mut total);
    paper_setup::run(&a, &mut total);
    raw_scans::run(&a);
    let secs = start.elapsed().as_secs_f64();
    println!(
        "Total: {total} Monte Carlo runs in {secs:.1} s on {threads} threads ({:.0} runs/s overall).",
        total as f64 / secs
    );
}
