//! The calibrator's stages from the observations to the reported model: run the estimator,
//! choose the model (the paper's or ours), check it.

use super::ObservationSet;
use crate::landmarks::estimate::{
    estimate, Estimate, EstimateError, EstimatorConfig, JointRejection,
};
use crate::landmarks::options::{Estimator, Options, OrderSelection};
use crate::landmarks::positions::{PositionError, MIN_BEARING_SPREAD_RAD};
use crate::CalibrationError;

/// The model the calibration reports, with the figures that go with it.
pub(super) struct Model {
    /// The selected polynomial order.
    pub order: usize,
    /// α of that order.
    pub alpha: Vec<f64>,
    /// β of that order.
    pub beta: Vec<f64>,
    /// The landmark centres (`None`: dropped).
    pub positions: Vec<Option<[f64; 2]>>,
    /// d̂ of each used observation.
    pub distances: Vec<f64>,
    /// Iterations of the joint refinement (1 without it).
    pub iterations: usize,
    /// Whether the joint refinement converged (true without it).
    pub converged: bool,
    /// Standard errors of α: the joint refinement's (landmark and stop positions' uncertainty
    /// included), else the regression's at the estimated distances (a lower bound).
    pub alpha_sd: Vec<f64>,
}

/// Estimate: run the estimator on the observations, noting the landmarks dropped and the paper
/// estimator's figures.
pub(super) fn run_estimator(
    set: &ObservationSet,
    opts: &Options,
    notes: &mut Vec<String>,
) -> Result<Estimate, CalibrationError> {
    let cfg = EstimatorConfig::from(opts);
    let est = estimate(set, &cfg).map_err(|e| match e {
        EstimateError::NoLandmarks(d) => CalibrationError::Unidentifiable(format!(
            "landmarks: no landmark's position can be estimated: {}",
            describe_drops(&d)
        )),
        EstimateError::TooFewObservations(n) => CalibrationError::TooFewSamples(format!(
            "landmarks: {n} landmark observation(s) are too few to fit a range model"
        )),
    })?;
    for (l, e) in &est.dropped {
        notes.push(format!(
            "warning: landmark {} dropped: {}",
            l + 1,
            describe_drop(*e)
        ));
    }
    let scan = &est.paper.scan;
    notes.push(format!(
        "paper estimator (eq. 23, OLS eq. 28): AIC picks order {}, cross-validation picks {}; \
         alpha {:?}; AIC by order {:?}; PRESS by order {:?}",
        scan.aic_order,
        scan.cv_order,
        round(&est.paper.alpha),
        round(&scan.fits.iter().map(|f| f.aic).collect::<Vec<_>>()),
        round(&scan.fits.iter().map(|f| f.press).collect::<Vec<_>>()),
    ));
    Ok(est)
}

/// Choose the model: the refined estimator's when asked for and available, else the paper's.
pub(super) fn choose_model(est: &Estimate, opts: &Options, notes: &mut Vec<String>) -> Model {
    match &est.refined {
        Some(r) if opts.estimator == Estimator::Refined => {
            notes.push(format!(
                "refined (eq. 23 with residual-variance weights, WLS): AIC picks order {}, \
                 cross-validation picks {}; sigma_s {:.4} m, sigma_theta {:.3} deg from the \
                 residuals of eq. 24",
                r.wls.scan.aic_order,
                r.wls.scan.cv_order,
                r.sigma_s_m,
                r.sigma_theta_rad.to_degrees()
            ));
            let (iterations, converged) = match &r.joint {
                Some(j) => {
                    notes.push(format!(
                        "joint refinement: {} iterations, cost {:.1} -> {:.1}, converged {}",
                        j.iterations, j.cost.0, j.cost.1, j.converged
                    ));
                    (j.iterations, j.converged)
                }
                None => {
                    notes.push(match r.rejected {
                        Some(JointRejection::Chi2(c)) => format!(
                            "warning: joint refinement set aside: its residuals contradict its \
                             weights (chi2/dof {c:.1}); the WLS stage stands"
                        ),
                        Some(JointRejection::Moved(k)) => format!(
                            "warning: joint refinement set aside: it moved a landmark {k:.1} \
                             standard deviations from the WLS estimate; the WLS stage stands"
                        ),
                        None => "warning: the joint refinement could not start; the WLS stage \
                                 stands"
                            .into(),
                    });
                    (1, false)
                }
            };
            let alpha_sd = match &r.joint {
                Some(j) => j.alpha_sd.clone(),
                None => stage_alpha_sd(&r.wls),
            };
            Model {
                order: r.wls.order,
                alpha: r.alpha().to_vec(),
                beta: r.beta.clone(),
                positions: r.positions(),
                distances: r.distances.clone(),
                iterations,
                converged,
                alpha_sd,
            }
        }
        _ => Model {
            order: est.paper.order,
            alpha: est.paper.alpha.clone(),
            beta: est.paper.beta.clone(),
            positions: est.paper.positions.clone(),
            distances: est.paper.distances.clone(),
            iterations: 1,
            converged: true,
            alpha_sd: stage_alpha_sd(&est.paper),
        },
    }
}

/// A stage's α standard errors: its regression's, at its estimated distances (a lower bound).
fn stage_alpha_sd(stage: &crate::landmarks::estimate::Stage) -> Vec<f64> {
    match stage.scan.fits.get(stage.order) {
        Some(fit) => fit.coeff_sd.clone(),
        None => vec![f64::INFINITY; stage.alpha.len()],
    }
}

/// Check the model: note how its order was selected; a constant or non-finite model is an
/// error.
pub(super) fn check_model(
    model: &Model,
    opts: &Options,
    notes: &mut Vec<String>,
) -> Result<(), CalibrationError> {
    let order = model.order;
    let selection = match opts.order_selection {
        OrderSelection::Aic => "AIC".to_string(),
        OrderSelection::CrossValidation => "cross-validation".to_string(),
        OrderSelection::Fixed(n) => format!("fixed at {n}"),
    };
    notes.push(format!("reported order {order} ({selection})"));
    if order == 0 {
        return Err(CalibrationError::Unidentifiable(
            "landmarks: the selected range model is constant (order 0): the readings do not \
             follow the distances; check the landmark detections"
                .into(),
        ));
    }
    let finite = model.alpha.iter().chain(&model.beta).all(|v| v.is_finite())
        && model
            .positions
            .iter()
            .flatten()
            .all(|p| p[0].is_finite() && p[1].is_finite());
    if !finite {
        return Err(CalibrationError::Diverged(
            "landmarks: the estimate is not finite".into(),
        ));
    }
    Ok(())
}

fn describe_drop(e: PositionError) -> String {
    match e {
        PositionError::TooFewBearings => "seen from fewer than two stops".into(),
        PositionError::Colinear(s) => format!(
            "its bearings are colinear (spread {:.2} deg, at least {:.2} deg is needed)",
            s.to_degrees(),
            MIN_BEARING_SPREAD_RAD.to_degrees()
        ),
        PositionError::Behind => "its bearings meet behind the sensor".into(),
    }
}

fn describe_drops(d: &[(usize, PositionError)]) -> String {
    d.iter()
        .map(|(l, e)| format!("landmark {}: {}", l + 1, describe_drop(*e)))
        .collect::<Vec<_>>()
        .join("; ")
}

fn round(v: &[f64]) -> Vec<f64> {
    v.iter().map(|x| (x * 1e5).round() / 1e5).collect()
}
