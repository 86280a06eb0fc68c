//! The paper's defaults, L = 5: the gain beyond the paper.

use std::time::Instant;

use hilsim_fixtures::landmark_study::Setup;

use crate::{mc, seed, Args};

pub fn run(a: &Args, total: &mut usize) {
    let t = Instant::now();
    println!("## The paper's setup, L = 5: paper vs refined\n");
    println!("| sigma_s (m) | sigma_theta (deg) | paper mean reading | refined mean reading | paper noisy | refined noisy | paper spread (mm) | refined spread (mm) | paper AIC order-2 | refined AIC order-2 |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (i, (ss, th)) in [(0.01, 1.0), (0.01, 2.0), (0.03, 1.0), (0.1, 2.0)]
        .iter()
        .enumerate()
    {
        let setup = Setup::paper().noise(*ss, *th);
        let s = mc(&setup, a.runs, seed(a.seed, 12, i as u64), total);
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
}
