//! Statistics over a Monte Carlo's runs.

use super::result::{MseRatios, RunResult};
use super::setup::Setup;
use crate::stats::median;

/// Statistics of a landmark position estimator over a Monte Carlo.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PositionStats {
    /// Mean radial error, metres.
    pub bias_radial: f64,
    /// Mean tangential error, metres.
    pub bias_tangential: f64,
    /// Standard errors of the two means, metres.
    pub bias_se: [f64; 2],
    /// Variance: mean squared deviation from the mean error (both components), m².
    pub variance: f64,
    /// Estimates counted.
    pub count: usize,
}

impl PositionStats {
    /// |bias|, metres.
    #[must_use]
    pub fn bias(&self) -> f64 {
        self.bias_radial.hypot(self.bias_tangential)
    }

    fn of(errors: impl Iterator<Item = [f64; 2]>) -> Self {
        let e: Vec<[f64; 2]> = errors.collect();
        let n = e.len() as f64;
        if e.is_empty() {
            return Self::default();
        }
        let m = [
            e.iter().map(|x| x[0]).sum::<f64>() / n,
            e.iter().map(|x| x[1]).sum::<f64>() / n,
        ];
        let v = [
            e.iter().map(|x| (x[0] - m[0]).powi(2)).sum::<f64>() / (n - 1.0).max(1.0),
            e.iter().map(|x| (x[1] - m[1]).powi(2)).sum::<f64>() / (n - 1.0).max(1.0),
        ];
        Self {
            bias_radial: m[0],
            bias_tangential: m[1],
            bias_se: [(v[0] / n).sqrt(), (v[1] / n).sqrt()],
            variance: v[0] + v[1],
            count: e.len(),
        }
    }
}

/// Summary of a Monte Carlo.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Runs asked for.
    pub runs: usize,
    /// Runs whose estimate or inversion failed.
    pub failed: usize,
    /// The paper's landmark position estimator.
    pub paper_positions: PositionStats,
    /// The refined positions.
    pub refined_positions: PositionStats,
    /// Mean over runs of the MSE ratios (as the paper averages its points).
    pub mean_ratio: MseRatios,
    /// Median over runs of the MSE ratios.
    pub median_ratio: MseRatios,
    /// How often each order was picked: `[method][order]` for paper AIC, paper CV, refined AIC,
    /// refined CV.
    pub order_counts: [Vec<usize>; 4],
}

impl Summary {
    /// Fraction of successful runs in which `which` (0 paper AIC, 1 paper CV, 2 refined AIC,
    /// 3 refined CV) picked `order`.
    #[must_use]
    pub fn order_rate(&self, which: usize, order: usize) -> f64 {
        let c = &self.order_counts[which];
        let total: usize = c.iter().sum();
        c.get(order).copied().unwrap_or(0) as f64 / total.max(1) as f64
    }
}

/// Summarises run results.
#[must_use]
pub fn summarise(setup: &Setup, runs: usize, results: &[Option<RunResult>]) -> Summary {
    let ok: Vec<&RunResult> = results.iter().flatten().collect();
    let paper_positions = PositionStats::of(
        ok.iter()
            .flat_map(|r| r.paper_errors.iter().flatten().copied()),
    );
    let refined_positions = PositionStats::of(
        ok.iter()
            .flat_map(|r| r.refined_errors.iter().flatten().copied()),
    );
    let ratios: Vec<MseRatios> = ok.iter().filter_map(|r| r.mse).collect();
    let stat = |f: fn(&MseRatios) -> f64, mean: bool| -> f64 {
        let mut v: Vec<f64> = ratios.iter().map(f).filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return f64::NAN;
        }
        if mean {
            v.iter().sum::<f64>() / v.len() as f64
        } else {
            median(&mut v)
        }
    };
    let summary_of = |mean: bool| MseRatios {
        paper_noisy: stat(|r| r.paper_noisy, mean),
        refined_noisy: stat(|r| r.refined_noisy, mean),
        paper_mean: stat(|r| r.paper_mean, mean),
        refined_mean: stat(|r| r.refined_mean, mean),
    };
    let n = setup.estimator.max_order + 1;
    let mut order_counts = [vec![0; n], vec![0; n], vec![0; n], vec![0; n]];
    for r in &ok {
        for (w, o) in [
            r.paper_orders.0,
            r.paper_orders.1,
            r.refined_orders.0,
            r.refined_orders.1,
        ]
        .into_iter()
        .enumerate()
        {
            if o < n {
                order_counts[w][o] += 1;
            }
        }
    }
    Summary {
        runs,
        failed: runs - ratios.len(),
        paper_positions,
        refined_positions,
        mean_ratio: summary_of(true),
        median_ratio: summary_of(false),
        order_counts,
    }
}
