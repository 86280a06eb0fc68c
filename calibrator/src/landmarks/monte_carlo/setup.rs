//! The study's settings: the paper's model and geometry, and variations on them.

use crate::landmarks::estimate::EstimatorConfig;

/// The paper's range bias, Sec. 4.1: alpha = [0.0525, 0.8838, 0.0584].
pub const PAPER_ALPHA: [f64; 3] = [0.0525, 0.8838, 0.0584];

/// The paper's noise, Sec. 4.1: beta = 0.05 alpha.
#[must_use]
pub fn paper_beta() -> [f64; 3] {
    PAPER_ALPHA.map(|a| 0.05 * a)
}

/// One simulation study's settings.
///
/// ```
/// use hilsim_calibrator::landmarks::monte_carlo::Setup;
/// let setup = Setup::paper().noise(0.01, 1.0).landmarks(2);
/// assert_eq!((setup.landmarks, setup.positions), (2, 20));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// True alpha.
    pub alpha: Vec<f64>,
    /// True beta.
    pub beta: Vec<f64>,
    /// Number of landmarks L.
    pub landmarks: usize,
    /// Number of sensor positions K.
    pub positions: usize,
    /// Spacing of the nominal positions along x, metres.
    pub step_m: f64,
    /// Landmark radius, metres (the distance is to the surface, the bearing to the centre).
    pub radius_m: f64,
    /// σs of eq. (8), metres.
    pub sigma_s_m: f64,
    /// σθ of eq. (5), radians.
    pub sigma_theta_rad: f64,
    /// Landmarks at fixed positions instead of random ones.
    pub fixed_landmarks: Option<Vec<[f64; 2]>>,
    /// The estimator.
    pub estimator: EstimatorConfig,
}

impl Setup {
    /// The paper's Sec. 4.1: alpha, beta = 0.05 alpha, five landmarks, twenty positions. The
    /// paper does not give the geometry; ours follows its field experiment (Sec. 4.3): a 3 m
    /// straight path (20 positions 0.15 m apart), cylinders of radius 0.12 m placed at random
    /// 0.5–2.5 m either side of it, every one 0.2–5 m from every position. Noise: σs = 1 cm,
    /// σθ = 1°.
    #[must_use]
    pub fn paper() -> Self {
        Self {
            alpha: PAPER_ALPHA.to_vec(),
            beta: paper_beta().to_vec(),
            landmarks: 5,
            positions: 20,
            step_m: 0.15,
            radius_m: 0.12,
            sigma_s_m: 0.01,
            sigma_theta_rad: 1f64.to_radians(),
            fixed_landmarks: None,
            estimator: EstimatorConfig::default(),
        }
    }

    /// With σs (metres) and σθ (degrees).
    #[must_use]
    pub fn noise(mut self, sigma_s_m: f64, sigma_theta_deg: f64) -> Self {
        self.sigma_s_m = sigma_s_m;
        self.sigma_theta_rad = sigma_theta_deg.to_radians();
        self
    }

    /// With L random landmarks.
    #[must_use]
    pub fn landmarks(mut self, n: usize) -> Self {
        self.landmarks = n;
        self.fixed_landmarks = None;
        self
    }

    /// The nominal positions.
    #[must_use]
    pub fn nominal(&self) -> Vec<[f64; 2]> {
        (0..self.positions)
            .map(|k| [self.step_m * k as f64, 0.0])
            .collect()
    }
}
