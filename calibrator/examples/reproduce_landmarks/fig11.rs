//! Fig. 11: the MSE ratio vs the number of landmarks, σθ = 2°.

use std::time::Instant;

use hilsim_fixtures::landmark_study::Setup;

use crate::{mc, seed, Args, LANDMARK_COUNTS};

pub fn run(a: &Args, total: &mut usize) {
    let t = Instant::now();
    println!("## Fig. 11: MSE ratio vs L (sigma_theta = 2 deg), mean reading, mean over runs\n");
    println!(
        "| sigma_s (m) | L | paper | refined | paper noisy | refined noisy | paper order-2 rate |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (i, ss) in [0.01, 0.03, 0.1].iter().enumerate() {
        for (j, l) in LANDMARK_COUNTS.iter().enumerate() {
            let setup = Setup::paper().landmarks(*l).noise(*ss, 2.0);
            let s = mc(&setup, a.runs, seed(a.seed, 11, (i * 10 + j) as u64), total);
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
}
