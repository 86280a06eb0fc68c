//! Fig. 8: the landmark position error vs the number of landmarks, σθ = 2°.

use std::time::Instant;

use hilsim_fixtures::landmark_study::Setup;

use crate::{mc, seed, Args, LANDMARK_COUNTS};

pub fn run(a: &Args, total: &mut usize) {
    let t = Instant::now();
    println!("## Fig. 8: landmark position error vs L (sigma_theta = 2 deg)\n");
    println!("| sigma_s (m) | L | paper bias radial (mm) | paper spread (mm) | refined bias radial (mm) | refined spread (mm) |");
    println!("|---|---|---|---|---|---|");
    for (i, ss) in [0.01, 0.1].iter().enumerate() {
        for (j, l) in LANDMARK_COUNTS.iter().enumerate() {
            let setup = Setup::paper().landmarks(*l).noise(*ss, 2.0);
            let s = mc(&setup, a.runs, seed(a.seed, 8, (i * 10 + j) as u64), total);
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
}
