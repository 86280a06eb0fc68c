//! The landmark calibrator's settings, with the defaults `hilsim calibrate --method landmarks`
//! uses. Every number is either from the paper, from the XV-11's geometry, or a tolerance whose
//! reason is given beside it.

use crate::CalibrationError;

/// Everything [`calibrate`](fn@super::calibrate) can be told.
///
/// ```
/// use hilsim_calibrator::landmarks::{Estimator, Options, OrderSelection};
/// let opts = Options {
///     estimator: Estimator::Paper,
///     order_selection: OrderSelection::CrossValidation,
///     ..Options::default()
/// };
/// assert!(opts.validate().is_ok());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// The landmarks' radius, metres; `None`: `meta.world.landmark_radius_m`, else estimated
    /// from the scans.
    pub landmark_radius_m: Option<f64>,
    /// The largest polynomial order tried, n_max of the paper's phase #1 (Sec. 3.2).
    pub max_order: usize,
    /// Which criterion picks the reported order; both are always computed and noted.
    pub order_selection: OrderSelection,
    /// The paper's estimator, or ours beyond it.
    pub estimator: Estimator,
    /// Standard deviation of the stops' positions about their nominal ones, metres (σs of the
    /// paper's eq. (8)); `None`: estimated from the residuals of eq. (24).
    pub sigma_s_m: Option<f64>,
    /// Iteration limit of the joint refinement.
    pub max_iterations: usize,
    /// The joint refinement stops when an iteration lowers the cost by less than this fraction.
    pub tolerance: f64,
    /// Finding the stops.
    pub stops: StopOptions,
    /// Finding the cylinders in the scans.
    pub detection: DetectionOptions,
    /// Matching detections across stops.
    pub association: AssociationOptions,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            landmark_radius_m: None,
            max_order: 3,
            order_selection: OrderSelection::Aic,
            estimator: Estimator::Refined,
            sigma_s_m: None,
            max_iterations: 50,
            tolerance: 1e-10,
            stops: StopOptions::default(),
            detection: DetectionOptions::default(),
            association: AssociationOptions::default(),
        }
    }
}

/// How the polynomial order is chosen (the paper's phase #2, Sec. 3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OrderSelection {
    /// Akaike's information criterion (as the seed papers, refs. 39 and 40 of the landmark
    /// paper, use).
    Aic,
    /// Leave-one-out cross-validation (PRESS).
    CrossValidation,
    /// A fixed order.
    Fixed(usize),
}

/// Which estimator turns the observations into a sensor model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Estimator {
    /// The paper as written: landmark positions by eq. (23) with the weights W_l of eq. (19),
    /// alpha by ordinary least squares, eq. (28).
    Paper,
    /// Beyond the paper: eq. (23) with the residual variances of eq. (24) as weights,
    /// heteroscedastic weighted least squares for alpha, then a joint refinement of the
    /// landmarks, the stops and alpha from bearings and ranges together.
    Refined,
}

/// Where the nominal stop positions come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Nominal {
    /// The commanded displacement integrated from `commands.csv` (the paper's eq. (7)).
    Commands,
    /// The odometry dead-reckoned from `odometry.csv`.
    Odometry,
}

/// Finding the stand-still stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopOptions {
    /// A stop holding fewer of the lidar's revolutions at rest is skipped: two revolutions give
    /// every beam two readings to average and gate (the median of two is their mean; a third
    /// helps the gate but is not needed).
    pub min_revolutions: f64,
    /// Time after the command goes to zero before the robot is taken to stand still; `None`:
    /// found from the odometry or the scans ([`super::rest`]).
    pub settle_s: Option<f64>,
    /// The odometry confirms a stop when both wheels' fitted speeds stay below this (m/s).
    pub still_speed_mps: f64,
    /// Nominal positions from the commands (the paper) or the odometry.
    pub nominal: Nominal,
}

impl Default for StopOptions {
    fn default() -> Self {
        Self {
            min_revolutions: 2.0,
            settle_s: None,
            still_speed_mps: 0.01,
            nominal: Nominal::Commands,
        }
    }
}

/// Finding cylinders in a stop's averaged scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectionOptions {
    /// A beam is used when at least this fraction of the stop's revolutions returned a valid
    /// reading in it.
    pub min_valid_fraction: f64,
    /// A landmark segment's interior beams must return a reading in at least this fraction of
    /// the revolutions: a cylinder within range always returns, a surface near the end of the
    /// range (6 m for the XV-11) drops out.
    pub min_return_fraction: f64,
    /// Segments nearer than this only, raw metres: the paper keeps its landmarks within 5 m
    /// (Sec. 4.3), and near the XV-11's 6 m limit readings drop out and surfaces break into
    /// fragments (5.5 m raw is ~4.8 m true under the paper's model).
    pub max_range_m: f64,
    /// Segments break where neighbouring beams' ranges differ by more than
    /// `jump_abs_m + jump_rel · range + jump_sigmas · σ`, σ the standard error of the difference.
    pub jump_abs_m: f64,
    /// See `jump_abs_m`.
    pub jump_rel: f64,
    /// See `jump_abs_m`.
    pub jump_sigmas: f64,
    /// Fewest beams a landmark segment may have.
    pub min_beams: usize,
    /// How far each edge of a segment may lie from where a cylinder of the known radius would
    /// put it, degrees: half a beam of quantisation plus the XV-11's beam jitter.
    pub edge_tolerance_deg: f64,
    /// A segment whose free circle fit (when it has enough beams to fit one) gives a radius more
    /// than this fraction away from the known one is not a landmark.
    pub radius_tolerance: f64,
    /// Beams within this fraction of the landmark's angular half-width of the bearing measure
    /// its range (the beam towards the centre and its nearest neighbours).
    pub central_fraction: f64,
    /// The largest radius a landmark may have when the radius is estimated, metres.
    pub max_radius_m: f64,
}

impl Default for DetectionOptions {
    fn default() -> Self {
        Self {
            min_valid_fraction: 0.5,
            min_return_fraction: 0.9,
            max_range_m: 5.5,
            jump_abs_m: 0.05,
            jump_rel: 0.03,
            jump_sigmas: 4.0,
            min_beams: 2,
            edge_tolerance_deg: 1.5,
            radius_tolerance: 0.5,
            central_fraction: 0.5,
            max_radius_m: 0.5,
        }
    }
}

/// Matching detections of the same cylinder across stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AssociationOptions {
    /// A detection joins a track when its position (nominal stop pose, raw range) lies within
    /// `gate_abs_m + gate_rel · range` of where the track was last seen: the raw range's bias
    /// (up to ~13 % at 4 m for the paper's XV-11 model) moves little between neighbouring stops.
    pub gate_abs_m: f64,
    /// See `gate_abs_m`.
    pub gate_rel: f64,
    /// Fewest stops a landmark must be seen from to be kept (two bearings intersect).
    pub min_stops: usize,
}

impl Default for AssociationOptions {
    fn default() -> Self {
        Self {
            gate_abs_m: 0.3,
            gate_rel: 0.1,
            min_stops: 2,
        }
    }
}

impl Options {
    /// Checks that every setting makes sense.
    ///
    /// # Errors
    /// [`CalibrationError::Invalid`] naming the first setting that does not.
    pub fn validate(&self) -> Result<(), CalibrationError> {
        let bad = |what: &str| Err(CalibrationError::Invalid(format!("landmarks: {what}")));
        let pos = |v: f64| v.is_finite() && v > 0.0;
        let nonneg = |v: f64| v.is_finite() && v >= 0.0;
        if let Some(r) = self.landmark_radius_m {
            if !nonneg(r) {
                return bad("the landmark radius must be a finite non-negative number");
            }
        }
        if let Some(s) = self.sigma_s_m {
            if !pos(s) {
                return bad("sigma_s must be positive");
            }
        }
        if let OrderSelection::Fixed(n) = self.order_selection {
            if n > self.max_order {
                return bad("the fixed order exceeds max_order");
            }
        }
        if self.max_order > 8 {
            return bad("max_order above 8 is numerically meaningless for a range polynomial");
        }
        if !pos(self.tolerance) || self.max_iterations == 0 {
            return bad("the refinement needs a positive tolerance and at least one iteration");
        }
        let s = &self.stops;
        if !(s.min_revolutions.is_finite() && s.min_revolutions >= 1.0) {
            return bad("a stop needs at least one revolution (--min-revolutions >= 1)");
        }
        if s.settle_s.is_some_and(|v| !nonneg(v)) || !pos(s.still_speed_mps) {
            return bad("the settling time must be >= 0 and the stand-still speed positive");
        }
        let d = &self.detection;
        let fraction = |v: f64| v > 0.0 && v <= 1.0;
        if !fraction(d.min_valid_fraction)
            || !fraction(d.central_fraction)
            || !fraction(d.min_return_fraction)
        {
            return bad("detection fractions must lie in (0, 1]");
        }
        if !nonneg(d.jump_abs_m)
            || !nonneg(d.jump_rel)
            || !nonneg(d.jump_sigmas)
            || !pos(d.edge_tolerance_deg)
            || !pos(d.radius_tolerance)
            || !pos(d.max_radius_m)
            || !pos(d.max_range_m)
            || d.min_beams < 2
        {
            return bad("detection thresholds must be positive and min_beams at least 2");
        }
        let a = &self.association;
        if !pos(a.gate_abs_m) || !nonneg(a.gate_rel) || a.min_stops < 2 {
            return bad("association gates must be positive and min_stops at least 2");
        }
        Ok(())
    }
}
