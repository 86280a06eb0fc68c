//! What one run of the Monte Carlo measured.

/// What one run measured.
#[derive(Debug, Clone, PartialEq)]
pub struct RunResult {
    /// Each landmark's position error (radial, tangential) with respect to the path's middle,
    /// the paper's estimator (eq. (23)), metres; `None` for a landmark it dropped.
    pub paper_errors: Vec<Option<[f64; 2]>>,
    /// The same for the refined estimate.
    pub refined_errors: Vec<Option<[f64; 2]>>,
    /// MSE ratios, when both calibrations could invert.
    pub mse: Option<MseRatios>,
    /// Orders picked by AIC and by cross-validation, OLS (the paper).
    pub paper_orders: (usize, usize),
    /// Orders picked by AIC and by cross-validation, WLS (refined).
    pub refined_orders: (usize, usize),
}

/// MSE ratios (31) of one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MseRatios {
    /// Fresh noisy readings at the true distances, the paper's calibration.
    pub paper_noisy: f64,
    /// Same, the refined calibration.
    pub refined_noisy: f64,
    /// Noise-free readings f(d) at the true distances (the bias alone), the paper's.
    pub paper_mean: f64,
    /// Same, refined.
    pub refined_mean: f64,
}
