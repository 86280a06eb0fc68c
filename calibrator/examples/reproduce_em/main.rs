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

mod common;
mod estep;
mod fig3;
mod qnoise;
mod sec6b;
mod sec6c;

use std::time::Instant;

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
            "fig3" => fig3::fig3(args.seeds),
            "sec6b" => sec6b::sec6b(args.seeds),
            "sec6c" => sec6c::sec6c(args.runs, args.step_deg),
            "estep" => estep::estep(args.seeds),
            "qnoise" => qnoise::qnoise(args.seeds),
            other => panic!("unknown section {other}"),
        }
        println!(
            "\n_{section}: {:.1} s wall-clock_\n",
            t.elapsed().as_secs_f64()
        );
    }
}
