//! Fig. 7: bias and spread of the landmark position estimator vs σs, for several σθ, L = 1.

use std::time::Instant;

use hilsim_fixtures::landmark_study::Setup;

use crate::{mc, seed, Args};

pub fn run(a: &Args, total: &mut usize) {
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
            let s = mc(&setup, a.runs, seed(a.seed, 7, (i * 10 + j) as u64), total);
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
}
