//! One run (its data set estimated and scored) and a Monte Carlo of runs on rayon's pool.

use rand::RngCore;
use rayon::prelude::*;

use super::result::{MseRatios, RunResult};
use super::rng::{run_seed, Xoshiro256pp};
use super::setup::Setup;
use super::simulate::{normal, simulate, Trial};
use super::summary::{summarise, Summary};
use crate::landmarks::estimate::{estimate, Estimate};
use crate::landmarks::inversion::Inverse;
use crate::landmarks::regression::horner;

/// One run from its seed.
#[must_use]
pub fn run_one(setup: &Setup, seed: u64) -> Option<RunResult> {
    let mut rng = Xoshiro256pp::seed_from_u64(seed);
    let trial = simulate(setup, &mut rng);
    let est = estimate(&trial.set, &setup.estimator).ok()?;
    let mid = setup.step_m * (setup.positions as f64 - 1.0) / 2.0;
    let local = |p: Option<[f64; 2]>, c: [f64; 2]| {
        p.map(|p| {
            let (ux, uy) = (c[0] - mid, c[1]);
            let n = ux.hypot(uy).max(1e-12);
            let (ux, uy) = (ux / n, uy / n);
            let (ex, ey) = (p[0] - c[0], p[1] - c[1]);
            [ex * ux + ey * uy, -ex * uy + ey * ux]
        })
    };
    let paper_errors = est
        .paper
        .positions
        .iter()
        .zip(&trial.landmarks)
        .map(|(p, c)| local(*p, *c))
        .collect();
    let refined_errors = est.refined.as_ref().map_or_else(Vec::new, |r| {
        r.positions()
            .iter()
            .zip(&trial.landmarks)
            .map(|(p, c)| local(*p, *c))
            .collect()
    });
    let mse = mse_ratios(setup, &trial, &est, &mut rng);
    Some(RunResult {
        paper_errors,
        refined_errors,
        mse,
        paper_orders: (est.paper.scan.aic_order, est.paper.scan.cv_order),
        refined_orders: est
            .refined
            .as_ref()
            .map_or((0, 0), |r| (r.wls.scan.aic_order, r.wls.scan.cv_order)),
    })
}

fn mse_ratios(
    setup: &Setup,
    trial: &Trial,
    est: &Estimate,
    rng: &mut impl RngCore,
) -> Option<MseRatios> {
    let dmax = est
        .paper
        .distances
        .iter()
        .copied()
        .fold(0.0f64, f64::max)
        .max(0.5);
    let domain = [0.0, 1.5 * dmax];
    let paper = Inverse::new(&est.paper.alpha, domain).ok()?;
    let refined = match &est.refined {
        Some(r) => Inverse::new(r.alpha(), domain).ok()?,
        None => paper.clone(),
    };
    let truth: Vec<f64> = est.used.iter().map(|&i| trial.distances[i]).collect();
    let noisy: Vec<f64> = truth
        .iter()
        .map(|d| horner(&setup.alpha, *d) + horner(&setup.beta, *d).max(0.0) * normal(rng))
        .collect();
    let mean: Vec<f64> = truth.iter().map(|d| horner(&setup.alpha, *d)).collect();
    let ratio = |raw: &[f64], inv: &Inverse| {
        let n = truth.len() as f64;
        let r: f64 = raw
            .iter()
            .zip(&truth)
            .map(|(a, d)| (a - d).powi(2))
            .sum::<f64>()
            / n;
        let c: f64 = raw
            .iter()
            .zip(&truth)
            .map(|(a, d)| (inv.distance(*a) - d).powi(2))
            .sum::<f64>()
            / n;
        r / c.max(1e-300)
    };
    Some(MseRatios {
        paper_noisy: ratio(&noisy, &paper),
        refined_noisy: ratio(&noisy, &refined),
        paper_mean: ratio(&mean, &paper),
        refined_mean: ratio(&mean, &refined),
    })
}

/// `runs` runs in parallel on rayon's pool, summarised.
#[must_use]
pub fn monte_carlo(setup: &Setup, runs: usize, seed: u64) -> Summary {
    let results: Vec<Option<RunResult>> = (0..runs as u64)
        .into_par_iter()
        .map(|i| run_one(setup, run_seed(seed, i)))
        .collect();
    summarise(setup, runs, &results)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_are_reproducible_and_noise_free_data_is_exact() {
        let setup = Setup::paper().noise(0.0, 0.0);
        let mut rng = Xoshiro256pp::seed_from_u64(3);
        let mut noiseless = setup.clone();
        noiseless.beta = vec![0.0];
        let t = simulate(&noiseless, &mut rng);
        let est = estimate(&t.set, &noiseless.estimator).unwrap();
        for (p, c) in est.paper.positions.iter().zip(&t.landmarks) {
            let p = p.unwrap();
            assert!((p[0] - c[0]).abs() < 1e-9 && (p[1] - c[1]).abs() < 1e-9);
        }
        assert_eq!(run_one(&setup, 42), run_one(&setup, 42));
    }
}
