//! The Kalman filter and RTS smoother of the simplest state there is: a scalar random walk seen
//! directly at every step, `x_k = x_{k−1} + w_k`, `w_k ~ N(0, q_k)`, `y_k = x_k + v_k`,
//! `v_k ~ N(0, r_k)` (Shumway & Stoffer, §6.2).
//!
//! [`crate::kalman_smoother::RtsSmoother`] computes the same posterior for `D = 1`; this one
//! writes each update in scalar arithmetic (the gain as `p / (p + r)`, the variance as
//! `(1 − gain) p`), without matrix inverses or the symmetric form. The diagnosis smooths its
//! scan matches with it, and its outputs depend on these roundings.
//!
//! ```
//! use hilsim_calibrator::random_walk_smoother::{smooth, Step};
//! let steps = [1.0, 3.0].map(|y| Step { process_variance: 1.0, observed: y, observation_variance: 1.0 });
//! let smoothed = smooth((0.0, 1e6), &steps);
//! // The smoothed states lie between the two observations, drawn towards each other.
//! assert!(smoothed[0].0 > 1.0 && smoothed[1].0 < 3.0);
//! ```

/// One step of the walk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// The variance of the walk's step into this one from the one before (ignored at the first).
    pub process_variance: f64,
    /// What was observed of the state.
    pub observed: f64,
    /// The observation's variance (positive).
    pub observation_variance: f64,
}

/// The smoothed mean and variance of each step's state, from the prior `(mean, variance)` of
/// the first; empty for no steps.
#[must_use]
pub fn smooth(prior: (f64, f64), steps: &[Step]) -> Vec<(f64, f64)> {
    let n = steps.len();
    // Forward filter: predicted (m⁻, p⁻) and filtered (m, p) at each step.
    let mut pred = Vec::with_capacity(n);
    let mut filt: Vec<(f64, f64)> = Vec::with_capacity(n);
    for step in steps {
        let (mp, pp) = match filt.last() {
            Some(&(m, p)) => (m, p + step.process_variance),
            None => prior,
        };
        pred.push((mp, pp));
        let (y, r) = (step.observed, step.observation_variance);
        let gain = pp / (pp + r);
        filt.push((mp + gain * (y - mp), (1.0 - gain) * pp));
    }
    // Backward pass.
    let mut smooth = filt.clone();
    for k in (0..n.saturating_sub(1)).rev() {
        let g = filt[k].1 / pred[k + 1].1;
        smooth[k] = (
            filt[k].0 + g * (smooth[k + 1].0 - pred[k + 1].0),
            filt[k].1 + g * g * (smooth[k + 1].1 - pred[k + 1].1),
        );
    }
    smooth
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kalman_smoother::{
        Gaussian, Observation, Observations, RtsSmoother, StateSpaceModel, Transition,
    };
    use nalgebra::{Matrix1, Vector1};

    struct Walk<'a>(&'a [Step]);

    impl StateSpaceModel<1> for Walk<'_> {
        fn steps(&self) -> usize {
            self.0.len()
        }
        fn prior(&self) -> Gaussian<1> {
            Gaussian::new(Vector1::new(0.5), Matrix1::new(4.0))
        }
        fn transition(&self, k: usize) -> Transition<1> {
            Transition {
                a: Matrix1::new(1.0),
                b: Vector1::new(0.0),
                q: Matrix1::new(self.0[k + 1].process_variance),
            }
        }
        fn observations(&self, k: usize, out: &mut Observations<1>) {
            out.push(Observation {
                y: self.0[k].observed,
                offset: 0.0,
                h: Vector1::new(1.0),
                r: self.0[k].observation_variance,
            });
        }
    }

    /// The same posterior as the generic smoother's, to rounding.
    #[test]
    fn agrees_with_the_generic_smoother() {
        let steps: Vec<Step> = (0..20)
            .map(|k| Step {
                process_variance: 0.01 * (1 + k % 3) as f64,
                observed: (k as f64 * 0.7).sin(),
                observation_variance: 0.05 + 0.01 * (k % 4) as f64,
            })
            .collect();
        let scalar = smooth((0.5, 4.0), &steps);
        let mut generic = RtsSmoother::new();
        generic.run(&Walk(&steps)).unwrap();
        for (k, (m, p)) in scalar.iter().enumerate() {
            assert!((m - generic.smoothed_means()[k][0]).abs() < 1e-12, "{k}");
            assert!(
                (p - generic.smoothed_covs()[k][(0, 0)]).abs() < 1e-12,
                "{k}"
            );
        }
    }

    #[test]
    fn no_steps_smooth_to_nothing() {
        assert!(smooth((0.0, 1.0), &[]).is_empty());
    }
}
