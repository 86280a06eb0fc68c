//! From bearings and ranges to a sensor model: the paper's two steps (landmark positions by
//! eq. (23), then the Vandermonde regression with order selection and beta), and ours beyond
//! (residual-variance weights for eq. (23), heteroscedastic weighted least squares for alpha,
//! and the joint refinement). Shared by the recording calibrator and the pure-model Monte Carlo.

use super::joint::{JointObservation, JointProblem, JointSolution};
use super::options::{Options, OrderSelection};
use super::positions::{
    intersect, variance_components, BearingLine, Position, PositionError, Weights,
};
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

/// Rounds of re-weighting in the joint refinement: after each solution every group of residuals
/// (bearings, ranges, stop priors) whose mean square departs from its expectation by more than a
/// factor [`CONSISTENT`] has its standard deviation rescaled by the square root of the factor
/// (at most ×3, at least ×½ a round) and the problem is solved again: a variance-component
/// estimate (Förstner's, as in bundle adjustment) that keeps a poorly estimated σθ or σs from
/// pulling the solution into an over-trusted group.
const REWEIGHT_ROUNDS: usize = 3;

/// Mean squares within this factor of their expectation are consistent with their weights.
const CONSISTENT: f64 = 2.0;

/// The joint solution is set aside when the residuals' χ² per degree of freedom still exceeds
/// this after re-weighting: its weights contradict the data.
const MAX_CHI2_PER_DOF: f64 = 4.0;

/// A joint solution may move a landmark at most this many standard deviations of the WLS
/// estimate (Mahalanobis distance; 5σ is far beyond what one more look at the same data
/// justifies, yet never reached by a sound solution).
const MAX_SHIFT_SIGMAS: f64 = 5.0;

fn solve_consistently(
    problem: &mut JointProblem,
    set: &ObservationSet,
    cfg: &EstimatorConfig,
) -> (Option<JointSolution>, Option<JointRejection>) {
    let m = 2 * problem.observations.len() + 2 * problem.stops.len();
    let dof = m.saturating_sub(problem.parameters()).max(1) as f64;
    let share = dof / m as f64;
    let mut iterations = 0;
    let mut last = None;
    for round in 0..=REWEIGHT_ROUNDS {
        let Some(mut sol) = problem.solve(cfg.max_iterations, cfg.tolerance) else {
            return (None, None);
        };
        iterations += sol.iterations;
        sol.iterations = iterations;
        let g = problem.chi2_by_group(&sol);
        let factor: Vec<f64> = g
            .iter()
            .map(|(sum, n)| sum / (*n as f64 * share).max(1e-9))
            .collect();
        let total: f64 = g.iter().map(|(s, _)| s).sum::<f64>() / dof;
        let consistent = factor
            .iter()
            .zip(&g)
            .all(|(f, (_, n))| *n == 0 || (1.0 / CONSISTENT..=CONSISTENT).contains(f));
        last = Some((sol, total));
        if consistent || round == REWEIGHT_ROUNDS {
            break;
        }
        let scale = |f: f64| f.sqrt().clamp(0.5, 3.0);
        problem.bearing_sd_rad *= scale(factor[0]);
        for o in &mut problem.observations {
            o.range_sd_m *= scale(factor[1]);
        }
        if cfg.sigma_s_m.is_none() {
            for (sd, given) in problem.stop_sd_m.iter_mut().zip(&set.stop_sd_m) {
                if given.is_none() {
                    *sd *= scale(factor[2]);
                }
            }
        }
    }
    match last {
        Some((_, total)) if total > MAX_CHI2_PER_DOF => (None, Some(JointRejection::Chi2(total))),
        Some((sol, _)) => (Some(sol), None),
        None => (None, None),
    }
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

fn refine(
    set: &ObservationSet,
    used: &[usize],
    per_landmark: &[(Vec<usize>, Vec<BearingLine>)],
    paper_fits: &[Option<Position>],
    paper: &Stage,
    cfg: &EstimatorConfig,
) -> Result<Refinement, EstimateError> {
    // σs² and σθ² of eq. (24) from the paper stage's residuals, against the centre distances of
    // the paper stage's estimate (the raw reading is biased, by up to 13 % at 4 m).
    let centre_lines: Vec<Vec<BearingLine>> = (0..set.landmarks)
        .map(|l| {
            let c = paper_fits[l].as_ref().map_or([f64::NAN; 2], |p| p.centre);
            per_landmark[l]
                .1
                .iter()
                .map(|b| BearingLine {
                    range_m: (c[0] - b.sensor[0]).hypot(c[1] - b.sensor[1]),
                    ..*b
                })
                .collect()
        })
        .collect();
    let kept: Vec<usize> = (0..set.landmarks)
        .filter(|&l| paper_fits[l].is_some())
        .collect();
    let lines: Vec<&[BearingLine]> = kept.iter().map(|&l| centre_lines[l].as_slice()).collect();
    let fits: Vec<&Position> = kept
        .iter()
        .filter_map(|&l| paper_fits[l].as_ref())
        .collect();
    let (s2, t2) = variance_components(&lines, &fits, cfg.sigma_s_m.map(|s| s * s));
    let weights = Weights::Residual {
        sigma_s2: s2,
        sigma_theta2: t2,
    };
    let wls_fits: Vec<Option<Position>> = (0..set.landmarks)
        .map(|l| {
            paper_fits[l].as_ref()?;
            intersect(&centre_lines[l], weights).ok()
        })
        .collect();
    let positions: Vec<Option<[f64; 2]>> = (0..set.landmarks)
        .map(|l| {
            wls_fits[l]
                .as_ref()
                .map(|p| p.centre)
                .or(paper_fits[l].as_ref().map(|p| p.centre))
        })
        .collect();
    // Heteroscedastic WLS: each averaged range's variance σ(d)²/n from the paper stage's β,
    // plus τ², what the OLS residuals show beyond it (the landmark positions' error).
    let pilot = &paper.scan.fits[paper.order];
    let n = used.len() as f64;
    let p = pilot.coeffs.len() as f64;
    let noise_part: f64 = used
        .iter()
        .zip(&paper.distances)
        .map(|(&i, d)| variance(&paper.beta, *d, set.observations[i].count, 0.0))
        .sum::<f64>()
        / n;
    let tau2 = (pilot.rss / (n - p).max(1.0) - noise_part).max(0.0);
    let wls = stage(set, used, positions, Some((&paper.beta, tau2)), cfg)?;
    // The joint refinement, started from the WLS stage.
    let sigma_s = s2.sqrt();
    let obs: Vec<JointObservation> = used
        .iter()
        .zip(&wls.distances)
        .map(|(&i, d)| {
            let o = &set.observations[i];
            JointObservation {
                landmark: o.landmark,
                stop: o.stop,
                bearing_rad: o.bearing_rad,
                range_m: o.range_m,
                // A millimetre floor: the ranges' own estimation errors (Sec. detection).
                range_sd_m: variance(&wls.beta, *d, o.count, 1e-6).sqrt(),
            }
        })
        .collect();
    // Landmarks without a position are dropped from the problem by remapping their indices.
    let remap: Vec<Option<usize>> = {
        let mut next = 0;
        wls.positions
            .iter()
            .map(|p| {
                p.map(|_| {
                    next += 1;
                    next - 1
                })
            })
            .collect()
    };
    let mut problem = JointProblem {
        observations: obs
            .into_iter()
            .filter_map(|mut o| {
                o.landmark = remap[o.landmark]?;
                Some(o)
            })
            .collect(),
        landmarks: wls.positions.iter().flatten().copied().collect(),
        stops: set.stops.clone(),
        stop_sd_m: set.stop_sd_m.iter().map(|s| s.unwrap_or(sigma_s)).collect(),
        alpha: wls.alpha.clone(),
        bearing_sd_rad: t2.sqrt(),
        radius_m: set.radius_m,
    };
    let (joint, mut rejected) = solve_consistently(&mut problem, set, cfg);
    let joint = joint.map(|mut j| {
        // Back to the original landmark indices.
        let mut full = vec![[f64::NAN; 2]; set.landmarks];
        for (l, r) in remap.iter().enumerate() {
            if let Some(r) = r {
                full[l] = j.landmarks[*r];
            }
        }
        let mut cov = vec![[[f64::INFINITY, 0.0], [0.0, f64::INFINITY]]; set.landmarks];
        for (l, r) in remap.iter().enumerate() {
            if let Some(r) = r {
                cov[l] = j.landmark_cov[*r];
            }
        }
        j.landmarks = full;
        j.landmark_cov = cov;
        j
    });
    // A joint solution that moved a landmark far beyond the WLS estimate's uncertainty went into
    // another basin (with two landmarks the stops and alpha can trade scale for shape): set aside.
    let joint = joint.filter(|j| {
        let worst = wls_fits
            .iter()
            .zip(&j.landmarks)
            .filter_map(|(f, q)| {
                let f = f.as_ref()?;
                let (dx, dy) = (q[0] - f.centre[0], q[1] - f.centre[1]);
                let c = f.cov;
                let det = c[0][0] * c[1][1] - c[0][1] * c[1][0];
                (det > 0.0).then(|| {
                    (c[1][1] * dx * dx - 2.0 * c[0][1] * dx * dy + c[0][0] * dy * dy) / det
                })
            })
            .fold(0.0f64, f64::max)
            .sqrt();
        if worst > MAX_SHIFT_SIGMAS {
            rejected = Some(JointRejection::Moved(worst));
            false
        } else {
            true
        }
    });
    let (distances, beta) = match &joint {
        Some(j) => {
            let pos: Vec<Option<[f64; 2]>> = wls
                .positions
                .iter()
                .zip(&j.landmarks)
                .map(|(p, q)| p.map(|_| *q))
                .collect();
            let d = distances(set, used, &pos, Some(&j.stops));
            let res: Vec<f64> = used
                .iter()
                .zip(&d)
                .map(|(&i, d)| set.observations[i].range_m - horner(&j.alpha, *d))
                .collect();
            let lev = vec![j.alpha.len() as f64 / used.len().max(1) as f64; used.len()];
            let beta = beta_of(set, used, &d, &res, &lev, j.alpha.len() - 1);
            (d, beta)
        }
        None => (wls.distances.clone(), wls.beta.clone()),
    };
    Ok(Refinement {
        sigma_s_m: sigma_s,
        sigma_theta_rad: t2.sqrt(),
        rejected,
        wls,
        joint,
        beta,
        distances,
    })
}
