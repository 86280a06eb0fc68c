//! Figs. 9 and 10: the MSE ratio and the order selection vs σθ and σs, L = 2.

use std::time::Instant;

use hilsim_fixtures::landmark_study::{Setup, Summary};

use crate::{mc, seed, Args};

const THETAS: [f64; 5] = [0.1, 0.5, 1.0, 2.0, 5.0];
const SIGMAS: [f64; 5] = [0.001, 0.01, 0.03, 0.1, 0.3];

pub fn run(a: &Args, total: &mut usize) {
    let t = Instant::now();
    let grid = grid(a, total);
    let fig9 = grid.len() * THETAS.len() * a.runs;
    let fig9_s = t.elapsed().as_secs_f64();
    println!("## Fig. 9: MSE ratio (31) vs sigma_theta and sigma_s (L = 2)\n");
    println!(
        "Mean over runs, as the paper averages its points. 'Mean reading': test readings f(d) \
         without noise (the calibration's model error alone); 'noisy': fresh readings with the \
         model's noise, beta = 0.05 alpha.\n"
    );
    table(&grid, "Paper, mean reading (median in brackets)", &|s| {
        format!(
            "{:.1} ({:.1})",
            s.mean_ratio.paper_mean, s.median_ratio.paper_mean
        )
    });
    table(&grid, "Refined, mean reading (median in brackets)", &|s| {
        format!(
            "{:.1} ({:.1})",
            s.mean_ratio.refined_mean, s.median_ratio.refined_mean
        )
    });
    table(&grid, "Paper / refined, noisy readings", &|s| {
        format!(
            "{:.2} / {:.2}",
            s.mean_ratio.paper_noisy, s.mean_ratio.refined_noisy
        )
    });
    println!("## Fig. 10: order selection (L = 2, true order 2)\n");
    table(
        &grid,
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
        &grid,
        "Rate of order 1 (too simple): paper AIC / refined AIC",
        &|s| format!("{:.2} / {:.2}", s.order_rate(0, 1), s.order_rate(2, 1)),
    );
    println!(
        "(Figs. 9-10: {fig9} runs in {fig9_s:.1} s, {:.0} runs/s)\n",
        fig9 as f64 / fig9_s
    );
}

/// The Monte Carlo summaries, a row per σs and a column per σθ.
fn grid(a: &Args, total: &mut usize) -> Vec<Vec<Summary>> {
    let mut grid: Vec<Vec<Summary>> = Vec::new();
    for (i, ss) in SIGMAS.iter().enumerate() {
        let mut row = Vec::new();
        for (j, th) in THETAS.iter().enumerate() {
            let setup = Setup::paper().landmarks(2).noise(*ss, *th);
            row.push(mc(
                &setup,
                a.runs,
                seed(a.seed, 9, (i * 10 + j) as u64),
                total,
            ));
        }
        grid.push(row);
    }
    grid
}

/// One table over the grid: `f` of each point.
fn table(grid: &[Vec<Summary>], title: &str, f: &dyn Fn(&Summary) -> String) {
    println!("### {title}\n");
    print!("| sigma_s (m) \\ sigma_theta (deg) |");
    for th in THETAS {
        print!(" {th} |");
    }
    println!();
    print!("|---|");
    for _ in THETAS {
        print!("---|");
    }
    println!();
    for (ss, row) in SIGMAS.iter().zip(grid) {
        print!("| {ss} |");
        for s in row {
            print!(" {} |", f(s));
        }
        println!();
    }
    println!();
}
