//! The estimator beyond the paper: eq. (23) with residual-variance weights, heteroscedastic WLS
//! for α, then the joint refinement of the landmarks, stops and α, re-weighted until its
//! residuals agree with its weights.

use super::{
    beta_of, distances, stage, variance, EstimateError, EstimatorConfig, JointRejection,
    ObservationSet, Refinement, Stage,
};
use crate::landmarks::joint::{JointObservation, JointProblem, JointSolution};
use crate::landmarks::positions::{intersect, variance_components, BearingLine, Position, Weights};
use crate::landmarks::regression::horner;

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

/// The refinement, from the paper stage's fits: residual-variance weights, the WLS stage, the
/// joint refinement (set aside when it contradicts its weights or moves a landmark too far),
/// and β at the final distances.
pub(super) fn refine(
    set: &ObservationSet,
    used: &[usize],
    per_landmark: &[(Vec<usize>, Vec<BearingLine>)],
    paper_fits: &[Option<Position>],
    paper: &Stage,
    cfg: &EstimatorConfig,
) -> Result<Refinement, EstimateError> {
    let (centre_lines, s2, t2) = residual_variances(set, per_landmark, paper_fits, cfg);
    let weights = Weights::Residual {
        sigma_s2: s2,
        sigma_theta2: t2,
    };
    let (wls_fits, positions) = reweighted_positions(set, paper_fits, &centre_lines, weights);
    let wls = wls_stage(set, used, positions, paper, cfg)?;
    // The joint refinement, started from the WLS stage.
    let sigma_s = s2.sqrt();
    let (mut problem, remap) = joint_problem(set, used, &wls, sigma_s, t2);
    let (joint, mut rejected) = solve_consistently(&mut problem, set, cfg);
    let joint = joint.map(|j| original_indices(j, &remap, set.landmarks));
    // A joint solution that moved a landmark far beyond the WLS estimate's uncertainty went into
    // another basin (with two landmarks the stops and alpha can trade scale for shape): set aside.
    let joint = joint.filter(|j| {
        let worst = largest_shift(&wls_fits, j);
        if worst > MAX_SHIFT_SIGMAS {
            rejected = Some(JointRejection::Moved(worst));
            false
        } else {
            true
        }
    });
    let (distances, beta) = final_distances_and_beta(set, used, &wls, joint.as_ref());
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

/// σs² and σθ² of eq. (24) from the paper stage's residuals, against the centre distances of
/// the paper stage's estimate (the raw reading is biased, by up to 13 % at 4 m); with each
/// landmark's bearing lines at those centre distances.
fn residual_variances(
    set: &ObservationSet,
    per_landmark: &[(Vec<usize>, Vec<BearingLine>)],
    paper_fits: &[Option<Position>],
    cfg: &EstimatorConfig,
) -> (Vec<Vec<BearingLine>>, f64, f64) {
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
    (centre_lines, s2, t2)
}

/// Eq. (23) again with the residual-variance weights: each landmark's fit, and its position
/// (the paper stage's where the re-weighted fit fails).
fn reweighted_positions(
    set: &ObservationSet,
    paper_fits: &[Option<Position>],
    centre_lines: &[Vec<BearingLine>],
    weights: Weights,
) -> (Vec<Option<Position>>, Vec<Option<[f64; 2]>>) {
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
    (wls_fits, positions)
}

/// Heteroscedastic WLS: each averaged range's variance σ(d)²/n from the paper stage's β, plus
/// τ², what the OLS residuals show beyond it (the landmark positions' error).
fn wls_stage(
    set: &ObservationSet,
    used: &[usize],
    positions: Vec<Option<[f64; 2]>>,
    paper: &Stage,
    cfg: &EstimatorConfig,
) -> Result<Stage, EstimateError> {
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
    stage(set, used, positions, Some((&paper.beta, tau2)), cfg)
}

/// The joint problem started from the WLS stage, and the map from the landmark indices to the
/// problem's (landmarks without a position are dropped from the problem).
fn joint_problem(
    set: &ObservationSet,
    used: &[usize],
    wls: &Stage,
    sigma_s: f64,
    t2: f64,
) -> (JointProblem, Vec<Option<usize>>) {
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
    let problem = JointProblem {
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
    (problem, remap)
}

/// Solves the joint problem, re-weighting the groups of residuals that contradict their weights
/// ([`REWEIGHT_ROUNDS`]); the solution is set aside when its χ² per degree of freedom stays
/// above [`MAX_CHI2_PER_DOF`].
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

/// The joint solution back in the original landmark indices (NaN centres and infinite
/// covariances for the landmarks it left out).
fn original_indices(
    mut j: JointSolution,
    remap: &[Option<usize>],
    landmarks: usize,
) -> JointSolution {
    let mut full = vec![[f64::NAN; 2]; landmarks];
    for (l, r) in remap.iter().enumerate() {
        if let Some(r) = r {
            full[l] = j.landmarks[*r];
        }
    }
    let mut cov = vec![[[f64::INFINITY, 0.0], [0.0, f64::INFINITY]]; landmarks];
    for (l, r) in remap.iter().enumerate() {
        if let Some(r) = r {
            cov[l] = j.landmark_cov[*r];
        }
    }
    j.landmarks = full;
    j.landmark_cov = cov;
    j
}

/// The largest shift of a landmark from its WLS fit, in that fit's standard deviations
/// (Mahalanobis distance).
fn largest_shift(wls_fits: &[Option<Position>], j: &JointSolution) -> f64 {
    wls_fits
        .iter()
        .zip(&j.landmarks)
        .filter_map(|(f, q)| {
            let f = f.as_ref()?;
            let (dx, dy) = (q[0] - f.centre[0], q[1] - f.centre[1]);
            let c = f.cov;
            let det = c[0][0] * c[1][1] - c[0][1] * c[1][0];
            (det > 0.0)
                .then(|| (c[1][1] * dx * dx - 2.0 * c[0][1] * dx * dy + c[0][0] * dy * dy) / det)
        })
        .fold(0.0f64, f64::max)
        .sqrt()
}

/// d̂ and β at the joint solution (β re-estimated from its residuals), else the WLS stage's.
fn final_distances_and_beta(
    set: &ObservationSet,
    used: &[usize],
    wls: &Stage,
    joint: Option<&JointSolution>,
) -> (Vec<f64>, Vec<f64>) {
    match joint {
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
    }
}
