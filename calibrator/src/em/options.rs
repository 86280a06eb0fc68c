//! What EM does: its options, the E-step variants, and the least data it accepts.

use super::model::Free;
use super::prior::Priors;
use crate::target_samples::SampleOptions;
use crate::CalibrationError;

/// Fewest valid lidar readings EM accepts: the lidar alone has four parameters (α0..α2, β2);
/// ten readings leave six degrees of freedom for the noise level, the least for which its
/// estimate's relative sd, `1/√(2·6) ≈ 0.29`, is below a third.
pub const MIN_LIDAR_READINGS: usize = 10;

/// Fewest readings for the odometer or sonar to take part (same reasoning, three parameters).
pub const MIN_AUX_READINGS: usize = 10;

/// Least span of commanded distance EM accepts, metres: below it the robot has not really
/// moved (5 cm is 2.5 revolutions at the paper's slowest 0.1 m/s). Separating α1 from α2 needs
/// the bias's curvature to show: over a span Δ the quadratic term departs from a straight line
/// by `α2 Δ²/4`, 0.04 mm here for the paper's α2 ≈ 0.06 /m, far below the XV-11's 1 mm
/// resolution, and the normal equations are numerically singular.
pub const MIN_SPAN_M: f64 = 0.05;

/// How the E-step treats the state-dependent (heteroscedastic) noise.
///
/// The refinements beyond the paper do not lower the error in the paper's setting (measured in
/// `docs/reproduce-em.md`: the paper's variant is as good or marginally better, and cheapest),
/// because the smoothed sd of `d` (millimetres) is tiny against `d` (≥ 0.5 m): `E[d⁴]` differs
/// from `d̂⁴` by `6 Var(d)/d̂² ≈ 1e-5` relative. So the paper's is the default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EStep {
    /// As the paper (Sec. IV-B/C): `R_k = (β · x̂_k^(t−1))²` at the previous iteration's
    /// smoothed redundant state, the same frozen weights in the M-step, and the M-step's
    /// `E[x xᵀ] = x̂ x̂ᵀ + P` from the redundant state (whose `d²` entry is its own variable).
    /// The default.
    #[default]
    Paper,
    /// Second-order moments: `R_k = E[(β·[1, d, d²])²]` (bringing in `E[d⁴]`) under the
    /// smoothed Gaussian of `d`, and the M-step's expectations `E[d^(−2p) φ φᵀ]` taken under
    /// that Gaussian too (weights included), instead of the redundant state's `d²` entry.
    SecondOrder,
    /// [`EStep::SecondOrder`], and the E-step re-evaluates `R_k` and `Q_k` at the *current*
    /// parameters' smoothed state (a second smoother pass) before the M-step, instead of
    /// keeping the previous iteration's.
    Relinearized,
}

impl EStep {
    /// A short name for notes and tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            EStep::Paper => "paper",
            EStep::SecondOrder => "second-order",
            EStep::Relinearized => "relinearized",
        }
    }

    pub(super) fn second_order(self) -> bool {
        self != EStep::Paper
    }
}

/// What EM does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmOptions {
    /// Beam angle in the lidar's frame, degrees (0: the lidar's forward axis).
    pub beam_deg: f64,
    /// Lidar-to-target distance at t = 0, metres; overrides `meta.world.target_start_distance_m`.
    pub start_distance_m: Option<f64>,
    /// Use the odometer when the recording has one.
    pub use_odometer: bool,
    /// Use the sonar when the recording has one.
    pub use_sonar: bool,
    /// Iteration cap, in E-steps (default 5000: plain EM with all three sensors needs up to
    /// ~3,400 to reach the default tolerance; SQUAREM a few hundred at most).
    pub max_iterations: usize,
    /// Convergence: every parameter's relative change (scale floor 1e-4) and the
    /// log-likelihood's relative change below this.
    pub tolerance: f64,
    /// The E-step variant.
    pub e_step: EStep,
    /// The paper's `σ_d` (eq. 3), assumed known, expressed per metre commanded: the sd of the
    /// distance's deviation from the commanded motion over one step is `q |u_k|`. It models a
    /// speed-scale actuation error; the paper gives no value, so the default 0.02 is the
    /// reproduction's simulated drive error (`scale_sd = 0.02`); with such an error the result
    /// hardly depends on it from 0.005 to 0.05 (`docs/reproduce-em.md`, "Process-noise scale").
    pub process_noise_rel: f64,
    /// Estimate `q` in the M-step (Shumway–Stoffer, with the lag-one covariances) from
    /// `process_noise_rel`, instead of keeping it fixed as the paper does (its σ_d is "assumed
    /// known"). On by default: a real drive's error is not known, and with q fixed too small
    /// the innovations of a wandering drive are correlated (the foreign em-reverse run: Ljung–Box
    /// Q(10) 33 fixed, 8 estimated) while the lidar model hardly changes.
    pub estimate_process_noise: bool,
    /// Accelerate EM with SQUAREM extrapolation (beyond the paper); the fixed point is the
    /// same, reached in fewer iterations. Plain EM when false.
    pub accelerate: bool,
    /// Gaussian priors on bias coefficients (MAP-EM, docs/em-calibration.md Sec. 12); with one
    /// on a scale (`alpha1`), the commands' speed scale is estimated too.
    pub priors: Priors,
}

impl Default for EmOptions {
    fn default() -> Self {
        Self {
            beam_deg: 0.0,
            start_distance_m: None,
            use_odometer: true,
            use_sonar: true,
            max_iterations: 5000,
            tolerance: 1e-6,
            e_step: EStep::default(),
            process_noise_rel: 0.02,
            estimate_process_noise: true,
            accelerate: true,
            priors: Priors::default(),
        }
    }
}

impl EmOptions {
    pub(super) fn validate(&self) -> Result<(), CalibrationError> {
        if self.max_iterations == 0 {
            return Err(CalibrationError::Invalid(
                "max_iterations must be at least 1".into(),
            ));
        }
        if !(self.tolerance > 0.0 && self.tolerance.is_finite()) {
            return Err(CalibrationError::Invalid(format!(
                "tolerance must be positive, got {}",
                self.tolerance
            )));
        }
        if !(self.process_noise_rel >= 0.0 && self.process_noise_rel.is_finite()) {
            return Err(CalibrationError::Invalid(format!(
                "process_noise_rel must be non-negative, got {}",
                self.process_noise_rel
            )));
        }
        Ok(())
    }

    /// The parameters beside the sensors' that the M-step estimates.
    pub(crate) fn free(&self) -> Free {
        Free {
            q: self.estimate_process_noise,
            speed_scale: self.estimates_speed_scale(),
        }
    }

    /// Whether the commands' speed scale is a parameter: when a prior pins a sensor's scale.
    #[must_use]
    pub fn estimates_speed_scale(&self) -> bool {
        self.priors.pins_a_scale()
    }

    /// The target these options name.
    #[must_use]
    pub fn sample_options(&self) -> SampleOptions {
        SampleOptions {
            beam_deg: self.beam_deg,
            start_distance_m: self.start_distance_m,
        }
    }
}
