//! The Kalman/RTS smoother under the EM calibrator, checked against brute force. On a
//! small linear-Gaussian model every state and observation is jointly Gaussian, so the smoothed
//! means, covariances and lag-one covariances are the Gaussian conditioning of the states on all
//! observations, and the log-likelihood is the observations' joint Gaussian density.

use hilsim_calibrator::kalman_smoother::{
    Gaussian, Observation, Observations, RtsSmoother, StateSpaceModel, Transition,
};
use nalgebra::{DMatrix, DVector, SMatrix, SVector};
use proptest::prelude::*;

/// A time-varying model with explicit matrices, possibly missing or multiple observations.
#[derive(Debug, Clone)]
struct Explicit<const D: usize> {
    prior: Gaussian<D>,
    transitions: Vec<Transition<D>>,
    observations: Vec<Vec<Observation<D>>>,
}

impl<const D: usize> StateSpaceModel<D> for Explicit<D> {
    fn steps(&self) -> usize {
        self.observations.len()
    }
    fn prior(&self) -> Gaussian<D> {
        self.prior
    }
    fn transition(&self, k: usize) -> Transition<D> {
        self.transitions[k]
    }
    fn observations(&self, k: usize, out: &mut Observations<D>) {
        for o in &self.observations[k] {
            out.push(*o);
        }
    }
}

/// The posterior of all states by Gaussian conditioning, and log p(y).
struct Batch {
    mean: DVector<f64>,
    cov: DMatrix<f64>,
    log_likelihood: f64,
}

fn batch<const D: usize>(m: &Explicit<D>) -> Batch {
    let n = m.observations.len();
    let dim = n * D;
    // Prior mean and covariance of the stacked states: x_{k+1} = A x_k + b + w.
    let mut mu = DVector::zeros(dim);
    let mut sigma = DMatrix::zeros(dim, dim);
    mu.rows_mut(0, D).copy_from(&m.prior.mean);
    sigma.view_mut((0, 0), (D, D)).copy_from(&m.prior.cov);
    for k in 0..n - 1 {
        let t = &m.transitions[k];
        let a = DMatrix::from_fn(D, D, |i, j| t.a[(i, j)]);
        let next = &a * mu.rows(k * D, D) + DVector::from_fn(D, |i, _| t.b[i]);
        mu.rows_mut((k + 1) * D, D).copy_from(&next);
        // Cov(x_{k+1}, x_j) = A Cov(x_k, x_j) for j ≤ k.
        for j in 0..=k {
            let c = &a * sigma.view((k * D, j * D), (D, D));
            sigma.view_mut(((k + 1) * D, j * D), (D, D)).copy_from(&c);
            sigma
                .view_mut((j * D, (k + 1) * D), (D, D))
                .copy_from(&c.transpose());
        }
        let q = DMatrix::from_fn(D, D, |i, j| t.q[(i, j)]);
        let c = &a * sigma.view((k * D, k * D), (D, D)) * a.transpose() + q;
        sigma
            .view_mut(((k + 1) * D, (k + 1) * D), (D, D))
            .copy_from(&c);
    }
    // Observations y = c + H x + v.
    let rows: Vec<(usize, &Observation<D>)> = m
        .observations
        .iter()
        .enumerate()
        .flat_map(|(k, os)| os.iter().map(move |o| (k, o)))
        .collect();
    let p = rows.len();
    let mut h = DMatrix::zeros(p, dim);
    let mut y = DVector::zeros(p);
    let mut c = DVector::zeros(p);
    let mut r = DMatrix::zeros(p, p);
    for (i, (k, o)) in rows.iter().enumerate() {
        for j in 0..D {
            h[(i, k * D + j)] = o.h[j];
        }
        y[i] = o.y;
        c[i] = o.offset;
        r[(i, i)] = o.r;
    }
    let s = &h * &sigma * h.transpose() + r;
    let s_inv = s
        .clone()
        .try_inverse()
        .expect("observation covariance is regular");
    let innovation = &y - (&c + &h * &mu);
    let gain = &sigma * h.transpose() * &s_inv;
    let mean = &mu + &gain * &innovation;
    let cov = &sigma - &gain * &h * &sigma;
    let log_det = s
        .clone()
        .cholesky()
        .expect("positive definite")
        .l()
        .diagonal()
        .map(f64::ln)
        .sum()
        * 2.0;
    let log_likelihood = -0.5
        * (p as f64 * (2.0 * std::f64::consts::PI).ln()
            + log_det
            + (innovation.transpose() * &s_inv * &innovation)[(0, 0)]);
    Batch {
        mean,
        cov,
        log_likelihood,
    }
}

/// Compares the smoother with the batch posterior; returns the largest absolute difference.
fn compare<const D: usize>(m: &Explicit<D>) -> f64 {
    let mut smoother = RtsSmoother::<D>::new();
    let ll = smoother.run(m).expect("smoother runs");
    let b = batch(m);
    let n = m.observations.len();
    let mut worst = (ll - b.log_likelihood).abs();
    for k in 0..n {
        for i in 0..D {
            worst = worst.max((smoother.smoothed_means()[k][i] - b.mean[k * D + i]).abs());
            for j in 0..D {
                worst = worst.max(
                    (smoother.smoothed_covs()[k][(i, j)] - b.cov[(k * D + i, k * D + j)]).abs(),
                );
                if k + 1 < n {
                    // Cov(x_{k+1}, x_k | Y).
                    let batch_lag = b.cov[((k + 1) * D + i, k * D + j)];
                    worst = worst.max((smoother.lag_one_covs()[k][(i, j)] - batch_lag).abs());
                }
            }
        }
    }
    worst
}

/// A random model from the proptest values: transitions near the identity (as the EM model's
/// `[[1, 0], [2u, 1]]`), positive definite Q, P0 and R, and per step 0–2 observations.
fn model<const D: usize>(vals: &[f64], counts: &[usize]) -> Explicit<D> {
    let mut it = vals.iter().copied().cycle();
    let mut next = move || it.next().unwrap();
    fn spd<const D: usize>(next: &mut impl FnMut() -> f64, scale: f64) -> SMatrix<f64, D, D> {
        let l = SMatrix::<f64, D, D>::from_fn(|_, _| next());
        l * l.transpose() * scale + SMatrix::identity() * (0.05 * scale)
    }
    let prior = Gaussian::new(SVector::from_fn(|_, _| next()), spd(&mut next, 1.0));
    let n = counts.len();
    let transitions = (0..n)
        .map(|_| Transition {
            a: SMatrix::identity() + SMatrix::from_fn(|_, _| 0.3 * next()),
            b: SVector::from_fn(|_, _| next()),
            q: spd(&mut next, 0.2),
        })
        .collect();
    let observations = counts
        .iter()
        .map(|&c| {
            (0..c)
                .map(|_| Observation {
                    y: 2.0 * next(),
                    offset: next(),
                    h: SVector::from_fn(|_, _| next()),
                    r: 0.1 + next().abs(),
                })
                .collect()
        })
        .collect();
    Explicit {
        prior,
        transitions,
        observations,
    }
}

// Tolerance 1e-9: the values are O(1) and the matrices well conditioned (every covariance has
// at least 0.05 × identity added), so both computations agree to a few hundred ulps times the
// ~10² operations each value passes through: ~1e-12; 1e-9 leaves three orders of margin.
const TOLERANCE: f64 = 1e-9;

#[test]
fn the_smoother_is_gaussian_conditioning() {
    // A fixed case with a step observed twice, one observed never, and an EM-like transition.
    let mut m = model::<2>(
        &[
            0.3, -0.7, 0.2, 0.9, -0.4, 0.5, 0.1, -0.2, 0.8, -0.6, 0.35, 0.05,
        ],
        &[1, 2, 0, 1, 1, 0, 2],
    );
    m.transitions[2].a = SMatrix::<f64, 2, 2>::new(1.0, 0.0, 0.04, 1.0);
    assert!(compare(&m) < TOLERANCE);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn random_two_state_models_match(
        vals in prop::collection::vec(-1.0f64..1.0, 40),
        counts in prop::collection::vec(0usize..3, 1..9),
    ) {
        let m = model::<2>(&vals, &counts);
        let worst = compare(&m);
        prop_assert!(worst < TOLERANCE, "worst difference {worst}");
    }

    #[test]
    fn random_three_state_models_match(
        vals in prop::collection::vec(-1.0f64..1.0, 60),
        counts in prop::collection::vec(0usize..3, 1..7),
    ) {
        let m = model::<3>(&vals, &counts);
        let worst = compare(&m);
        prop_assert!(worst < TOLERANCE, "worst difference {worst}");
    }
}
