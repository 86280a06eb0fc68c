//! From bearings and ranges to a sensor model: the paper's two steps (landmark positions by
//! eq. (23), then the Vandermonde regression with order selection and beta), and ours beyond
//! (residual-variance weights for eq. (23), heteroscedastic weighted least squares for alpha,
//! and the joint refinement). Shared by the recording calibrator and the pure-model Monte Carlo.

mod refine;

use self::refine::refine;
use super::joint::JointSolution;
use super::options::{Options, OrderSelection};
use super::positions::{intersect, BearingLine, Position, PositionError, Weights};
use super::regression::{fit_beta, horner, scan_orders, OrderScan};

/// One landmark seen from one stop.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    /// Landmark index.
    pub landmark: usize,
    /// Stop index.
    pub stop: usize,
    /// Bearing of the landmark's centre, radians, start-pose frame.
    pub bearing_rad: f64,
    /// The raw range d̃ (towards the centre: to the nearest surface point), metres.
    pub range_m: f64,
    /// Readings averaged into `range_m` (1 for a single reading).
    pub count: usize,
    /// The averaged readings less their mean, when known (the stop's own noise sample); empty
    /// for a single reading.
    pub scatter: Vec<f64>,
}

/// Everything the estimator sees.
#[derive(Debug, Clone, PartialEq)]
pub struct ObservationSet {
    /// Nominal sensor positions of the stops, metres, start-pose frame.
    pub stops: Vec<[f64; 2]>,
    /// Prior standard deviation of each stop about its nominal position, when known better than
    /// σs (the stops before the first motion are at the start pose by definition).
    pub stop_sd_m: Vec<Option<f64>>,
    /// Number of landmarks.
    pub landmarks: usize,
    /// Landmark radius, metres.
    pub radius_m: f64,
    /// The observations.
    pub observations: Vec<Observation>,
}

/// The estimator's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorConfig {
    /// n_max.
    pub max_order: usize,
    /// How the reported order is picked.
    pub selection: OrderSelection,
    /// Run the stages beyond the paper.
    pub refine: bool,
    /// σs when known, metres.
    pub sigma_s_m: Option<f64>,
    /// Iteration limit of the joint refinement.
    pub max_iterations: usize,
    /// Relative cost decrease that ends the joint refinement.
    pub tolerance: f64,
}

impl From<&Options> for EstimatorConfig {
    fn from(o: &Options) -> Self {
        Self {
            max_order: o.max_order,
            selection: o.order_selection,
            refine: o.estimator == super::options::Estimator::Refined,
            sigma_s_m: o.sigma_s_m,
            max_iterations: o.max_iterations,
            tolerance: o.tolerance,
        }
    }
}

impl Default for EstimatorConfig {
    fn default() -> Self {
        Self::from(&Options::default())
    }
}

/// One stage's result: landmark positions, the order scan and the chosen model.
#[derive(Debug, Clone, PartialEq)]
pub struct Stage {
    /// Estimated centre of each landmark (`None`: dropped, see [`Estimate::dropped`]).
    pub positions: Vec<Option<[f64; 2]>>,
    /// d̂ of each used observation (same order as [`Estimate::used`]), metres.
    pub distances: Vec<f64>,
    /// The fits of every order and the orders AIC and cross-validation pick.
    pub scan: OrderScan,
    /// The order used.
    pub order: usize,
    /// α of that order.
    pub alpha: Vec<f64>,
    /// β of that order.
    pub beta: Vec<f64>,
}

/// The refinement beyond the paper.
#[derive(Debug, Clone, PartialEq)]
pub struct Refinement {
    /// σs used (estimated from the residuals of eq. (24) unless given), metres.
    pub sigma_s_m: f64,
    /// σθ estimated from the residuals of eq. (24), radians.
    pub sigma_theta_rad: f64,
    /// Eq. (23) with residual-variance weights, then heteroscedastic WLS for α.
    pub wls: Stage,
    /// The joint refinement (`None` when it failed to start or its residuals contradicted its
    /// weights; the WLS stage stands).
    pub joint: Option<JointSolution>,
    /// Why the joint refinement was set aside, if it was.
    pub rejected: Option<JointRejection>,
    /// β re-estimated at the joint solution's distances.
    pub beta: Vec<f64>,
    /// d̂ at the joint solution (same order as [`Estimate::used`]).
    pub distances: Vec<f64>,
}

impl Refinement {
    /// The final α: the joint solution's, else the WLS stage's.
    #[must_use]
    pub fn alpha(&self) -> &[f64] {
        self.joint.as_ref().map_or(&self.wls.alpha, |j| &j.alpha)
    }

    /// The final landmark positions.
    #[must_use]
    pub fn positions(&self) -> Vec<Option<[f64; 2]>> {
        match &self.joint {
            Some(j) => self
                .wls
                .positions
                .iter()
                .zip(&j.landmarks)
                .map(|(p, q)| p.map(|_| *q))
                .collect(),
            None => self.wls.positions.clone(),
        }
    }
}

/// Why a joint solution was set aside (the WLS stage then stands).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointRejection {
    /// Its χ² per degree of freedom (the value) still contradicted its weights after
    /// re-weighting.
    Chi2(f64),
    /// It moved a landmark this many standard deviations of the WLS estimate.
    Moved(f64),
}

/// What the estimator found.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Indices of the observations used (those of landmarks whose position could be estimated).
    pub used: Vec<usize>,
    /// Landmarks dropped, and why.
    pub dropped: Vec<(usize, PositionError)>,
    /// The paper's estimator.
    pub paper: Stage,
    /// Ours beyond it, when asked for.
    pub refined: Option<Refinement>,
}

/// Why no estimate could be made.
#[derive(Debug, Clone, PartialEq)]
pub enum EstimateError {
    /// No landmark's position could be estimated.
    NoLandmarks(Vec<(usize, PositionError)>),
    /// Too few observations to fit even a constant.
    TooFewObservations(usize),
}

/// Runs the estimator.
///
/// # Errors
/// No landmark position could be estimated, or too few observations remain to fit a model.
pub fn estimate(set: &ObservationSet, cfg: &EstimatorConfig) -> Result<Estimate, EstimateError> {
    let lines_of = |l: usize| -> (Vec<usize>, Vec<BearingLine>) {
        set.observations
            .iter()
            .enumerate()
            .filter(|(_, o)| o.landmark == l)
            .map(|(i, o)| {
                (
                    i,
                    BearingLine {
                        sensor: set.stops[o.stop],
                        bearing_rad: o.bearing_rad,
                        range_m: o.range_m,
                    },
                )
            })
            .unzip()
    };
    let per_landmark: Vec<(Vec<usize>, Vec<BearingLine>)> =
        (0..set.landmarks).map(lines_of).collect();
    // Eq. (23) with the paper's weights.
    let mut dropped = Vec::new();
    let mut paper_fits: Vec<Option<Position>> = Vec::with_capacity(set.landmarks);
    for (l, (_, lines)) in per_landmark.iter().enumerate() {
        match intersect(lines, Weights::Paper) {
            Ok(p) => paper_fits.push(Some(p)),
            Err(e) => {
                dropped.push((l, e));
                paper_fits.push(None);
            }
        }
    }
    if paper_fits.iter().all(Option::is_none) {
        return Err(EstimateError::NoLandmarks(dropped));
    }
    let used: Vec<usize> = (0..set.observations.len())
        .filter(|&i| paper_fits[set.observations[i].landmark].is_some())
        .collect();
    let positions: Vec<Option<[f64; 2]>> = paper_fits
        .iter()
        .map(|p| p.as_ref().map(|p| p.centre))
        .collect();
    let paper = stage(set, &used, positions, None, cfg)?;
    let refined = if cfg.refine {
        Some(refine(set, &used, &per_landmark, &paper_fits, &paper, cfg)?)
    } else {
        None
    };
    Ok(Estimate {
        used,
        dropped,
        paper,
        refined,
    })
}

/// Distances, the order scan, α and β for given positions; weighted least squares when
/// `wls` carries the per-observation variances' model (β and the extra variance τ²).
fn stage(
    set: &ObservationSet,
    used: &[usize],
    positions: Vec<Option<[f64; 2]>>,
    wls: Option<(&[f64], f64)>,
    cfg: &EstimatorConfig,
) -> Result<Stage, EstimateError> {
    let distances = distances(set, used, &positions, None);
    let y: Vec<f64> = used.iter().map(|&i| set.observations[i].range_m).collect();
    let weights: Option<Vec<f64>> = wls.map(|(beta, tau2)| {
        used.iter()
            .zip(&distances)
            .map(|(&i, d)| 1.0 / variance(beta, *d, set.observations[i].count, tau2))
            .collect()
    });
    let scan = scan_orders(&distances, &y, weights.as_deref(), cfg.max_order)
        .ok_or(EstimateError::TooFewObservations(used.len()))?;
    let order = match cfg.selection {
        OrderSelection::Aic => scan.aic_order,
        OrderSelection::CrossValidation => scan.cv_order,
        OrderSelection::Fixed(n) => n.min(scan.fits.len() - 1),
    };
    let alpha = scan.fits[order].coeffs.clone();
    let beta = beta_of(
        set,
        used,
        &distances,
        &scan.fits[order].residuals,
        &scan.fits[order].leverages,
        order,
    );
    Ok(Stage {
        positions,
        distances,
        scan,
        order,
        alpha,
        beta,
    })
}

/// d̂ = |ĉ − s| − R for each used observation, at the nominal stops or at `stops`.
fn distances(
    set: &ObservationSet,
    used: &[usize],
    positions: &[Option<[f64; 2]>],
    stops: Option<&[[f64; 2]]>,
) -> Vec<f64> {
    used.iter()
        .map(|&i| {
            let o = &set.observations[i];
            let c = positions[o.landmark].unwrap_or([f64::NAN; 2]);
            let s = stops.map_or(set.stops[o.stop], |s| s[o.stop]);
            (c[0] - s[0]).hypot(c[1] - s[1]) - set.radius_m
        })
        .collect()
}

/// The variance of an averaged range: σ(d)²/n plus an extra τ².
fn variance(beta: &[f64], d: f64, count: usize, tau2: f64) -> f64 {
    let s = horner(beta, d).max(1e-4);
    s * s / count.max(1) as f64 + tau2
}

/// β of eq. (3) from the residuals: the stops' own scatter when the observations carry it (free
/// of the landmark positions' errors), else the regression's residuals (leverage-corrected).
fn beta_of(
    set: &ObservationSet,
    used: &[usize],
    distances: &[f64],
    residuals: &[f64],
    leverages: &[f64],
    order: usize,
) -> Vec<f64> {
    let (mut d, mut e, mut dof) = (Vec::new(), Vec::new(), Vec::new());
    let scatter = used
        .iter()
        .any(|&i| !set.observations[i].scatter.is_empty());
    for (j, &i) in used.iter().enumerate() {
        let o = &set.observations[i];
        if scatter {
            let n = o.scatter.len() as f64;
            if n < 2.0 {
                continue;
            }
            for v in &o.scatter {
                d.push(distances[j]);
                e.push(*v);
                dof.push((n / (n - 1.0)).sqrt());
            }
        } else {
            d.push(distances[j]);
            // An averaged range's residual scaled back to one reading's.
            e.push(residuals[j] * (o.count.max(1) as f64).sqrt());
            dof.push(1.0 / (1.0 - leverages[j]).max(0.05).sqrt());
        }
    }
    fit_beta(&d, &e, &dof, order).unwrap_or_else(|| vec![0.0; order + 1])
}
