//! The landmark calibrator on a recording: stops → averaged scans → cylinders → tracks →
//! observations → the estimator → a [`Calibration`].

use std::collections::BTreeMap;

use hilsim_recording::Recording;
use rayon::prelude::*;

use super::association::{associate, place, Track};
use super::detection::{candidate_radii, detect, Detection, Rejections};
use super::estimate::{
    estimate, Estimate, EstimateError, EstimatorConfig, JointRejection, Observation, ObservationSet,
};
use super::inversion::Inverse;
use super::options::{Estimator, Options, OrderSelection};
use super::pose::Pose2;
use super::positions::{intersect, BearingLine, PositionError, Weights, MIN_BEARING_SPREAD_RAD};
use super::scan::average_stop;
use super::stops::{find_stops, Stop};
use crate::stats::median;
use crate::{Calibration, CalibrationError, Method, Metrics, Sensor, SensorModel};

/// Standard deviation given to the stops before the robot first moved: they are at the start
/// pose by definition (0.1 mm: exact to the model, finite for the solver).
const AT_START_SD_M: f64 = 1e-4;

/// Calibrates the lidar's range model from a recording of stops among cylinders, the landmark
/// paper's method (Alhashimi, Magnusson, Knorn, Varagnolo, Sensors 2021), from the raw scans.
///
/// Requirements: `lidar.csv`; `commands.csv` rows (or `odometry.csv`) with at least two
/// stand-still stops; cylinders of one radius (`meta.world.landmark_radius_m`, the option, or
/// estimated) seen from at least two stops under bearings that are not parallel.
///
/// The result's `order` is the selected polynomial order, `landmarks` the estimated centres in
/// the start-pose frame, `metrics` (with `truth.csv` or the lidar's `true_range_m`) the MSE of
/// the landmark distances, raw and calibrated, and `notes` both order-selection verdicts, the
/// paper estimator's figures next to ours, the detection counts and every warning.
///
/// # Errors
/// [`CalibrationError::Missing`] without lidar data or stops to find; `TooFewSamples` with fewer
/// than two stops, no landmark detected, or every landmark seen from one stop only;
/// `Unidentifiable` when every landmark's bearings are colinear or the selected model is
/// constant; `Invalid` for bad options or lidar rows out of time order; `Diverged` when a
/// result is not finite.
pub fn calibrate(rec: &Recording, opts: &Options) -> Result<Calibration, CalibrationError> {
    analyse(rec, opts).map(|a| a.calibration)
}

/// Everything the calibrator found on the way, for tests, diagnostics and the reproduction.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// The stand-still stops.
    pub stops: Vec<Stop>,
    /// Each stop's nominal sensor (lidar) pose, start-pose frame.
    pub sensors: Vec<Pose2>,
    /// The landmark radius used, metres.
    pub radius_m: f64,
    /// Every detection, all stops.
    pub detections: Vec<Detection>,
    /// Segments rejected, by reason.
    pub rejected: Rejections,
    /// The tracks kept (indices into `detections`); landmark `l` of the results is `tracks[l]`.
    pub tracks: Vec<Track>,
    /// The estimator's input.
    pub observations: ObservationSet,
    /// The estimator's output.
    pub estimate: Estimate,
    /// The true distance of each used observation (order of `estimate.used`), when known.
    pub truth_distances: Option<Vec<f64>>,
    /// The result.
    pub calibration: Calibration,
}

/// [`calibrate`], keeping the intermediate results.
///
/// # Errors
/// As [`calibrate`].
pub fn analyse(rec: &Recording, opts: &Options) -> Result<Analysis, CalibrationError> {
    opts.validate()?;
    let lidar = rec
        .lidar
        .as_deref()
        .filter(|l| !l.is_empty())
        .ok_or_else(|| {
            CalibrationError::Missing("landmarks: the recording has no lidar.csv readings".into())
        })?;
    if lidar.windows(2).any(|w| w[1].t_s < w[0].t_s) {
        return Err(CalibrationError::Invalid(
            "landmarks: lidar.csv rows go back in time".into(),
        ));
    }
    let mut notes = Vec::new();
    let (stops, report) = find_stops(rec, &opts.stops)?;
    for (t, v) in &report.moving {
        notes.push(format!(
            "warning: stop at t = {t:.2} s dropped: the odometry shows motion ({v:.3} m/s)"
        ));
    }
    if report.too_short > 0 {
        notes.push(format!(
            "{} stand-still interval(s) shorter than {} s after the {} s settling time skipped",
            report.too_short, opts.stops.min_stop_s, opts.stops.settle_s
        ));
    }
    if stops.len() < 2 {
        return Err(CalibrationError::TooFewSamples(format!(
            "landmarks: found {} stand-still stop(s) of at least {} s; the bearings of two \
             stops at least are needed to place a landmark",
            stops.len(),
            opts.stops.min_stop_s
        )));
    }
    let scans: Vec<_> = stops
        .par_iter()
        .map(|s| average_stop(lidar, s, &opts.detection))
        .collect();
    let radius = match opts.landmark_radius_m.or(rec.meta.world.landmark_radius_m) {
        Some(r) => {
            notes.push(format!("landmark radius {r:.3} m (given)"));
            r
        }
        None => {
            let mut radii: Vec<f64> = scans
                .iter()
                .flat_map(|s| candidate_radii(s, &opts.detection))
                .collect();
            if radii.len() < 3 {
                return Err(CalibrationError::Missing(format!(
                    "landmarks: the landmark radius is not in meta.toml and only {} segment(s) \
                     could measure it; give [world] landmark_radius_m",
                    radii.len()
                )));
            }
            let r = median(&mut radii);
            notes.push(format!(
                "landmark radius {r:.3} m estimated (median of {} free circle fits, in raw \
                 reading space)",
                radii.len()
            ));
            r
        }
    };
    let mount = rec.meta.lidar.as_ref();
    let sensors: Vec<Pose2> = stops
        .iter()
        .map(|s| {
            s.pose.compose(
                mount.map_or(0.0, |m| m.x_m),
                mount.map_or(0.0, |m| m.y_m),
                mount.map_or(0.0, |m| m.yaw_deg.to_radians()),
            )
        })
        .collect();
    let mut rejected = Rejections::default();
    let mut dets: Vec<Detection> = Vec::new();
    for (k, scan) in scans.iter().enumerate() {
        let (d, r) = detect(scan, k, radius, &opts.detection);
        rejected.add(&r);
        dets.extend(d);
    }
    let reasons = [
        (rejected.occluded, "occluded"),
        (rejected.too_long, "too long (walls)"),
        (rejected.straight, "straight (walls)"),
        (rejected.short, "too short"),
        (rejected.edges, "edges misplaced for the radius"),
        (rejected.radius, "of another radius"),
        (rejected.intermittent, "intermittent"),
        (rejected.far, "too far"),
        (rejected.fit, "failed circle fits"),
    ];
    let reasons: Vec<String> = reasons
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, why)| format!("{n} {why}"))
        .collect();
    notes.push(format!(
        "{} stops, {} landmark detections; segments rejected: {}",
        stops.len(),
        dets.len(),
        if reasons.is_empty() {
            "none".to_string()
        } else {
            reasons.join(", ")
        }
    ));
    if dets.is_empty() {
        return Err(CalibrationError::TooFewSamples(format!(
            "landmarks: no landmark (cylinder of radius {radius:.3} m) detected in any of the {} \
             stops",
            stops.len()
        )));
    }
    let tracks = associate(&dets, &sensors, radius, &opts.association);
    let mut kept = Vec::new();
    for t in tracks {
        let seen_from = t.len();
        if seen_from >= opts.association.min_stops {
            kept.push(t);
        } else {
            let p = place(&dets[t[0]], &sensors[dets[t[0]].stop], radius);
            notes.push(format!(
                "warning: landmark near ({:.2}, {:.2}) m seen from {seen_from} stop(s) only \
                 (at least {} are needed): dropped",
                p[0], p[1], opts.association.min_stops
            ));
        }
    }
    if kept.is_empty() {
        return Err(CalibrationError::TooFewSamples(format!(
            "landmarks: every one of the {} landmark(s) detected was seen from fewer than {} \
             stops; bearings from two stops at least are needed to place a landmark",
            dets.len(),
            opts.association.min_stops
        )));
    }
    let set = ObservationSet {
        stops: sensors.iter().map(|p| [p.x, p.y]).collect(),
        stop_sd_m: stops
            .iter()
            .map(|s| (!s.moved_before).then_some(AT_START_SD_M))
            .collect(),
        landmarks: kept.len(),
        radius_m: radius,
        observations: kept
            .iter()
            .enumerate()
            .flat_map(|(l, t)| {
                let dets = &dets;
                let sensors = &sensors;
                t.iter().map(move |&i| {
                    let d = &dets[i];
                    Observation {
                        landmark: l,
                        stop: d.stop,
                        bearing_rad: sensors[d.stop].yaw + d.bearing_rad,
                        range_m: d.range_m,
                        count: d.count,
                        scatter: d.residuals.clone(),
                    }
                })
            })
            .collect(),
    };
    let obs_dets: Vec<&Detection> = kept
        .iter()
        .flat_map(|t| t.iter().map(|&i| &dets[i]))
        .collect();
    let cfg = EstimatorConfig::from(opts);
    let est = estimate(&set, &cfg).map_err(|e| match e {
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
    let (order, alpha, beta, positions, distances, iterations, converged) = match &est.refined {
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
            let (it, conv) = match &r.joint {
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
            (
                r.wls.order,
                r.alpha().to_vec(),
                r.beta.clone(),
                r.positions(),
                r.distances.clone(),
                it,
                conv,
            )
        }
        _ => (
            est.paper.order,
            est.paper.alpha.clone(),
            est.paper.beta.clone(),
            est.paper.positions.clone(),
            est.paper.distances.clone(),
            1,
            true,
        ),
    };
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
    let finite = alpha.iter().chain(&beta).all(|v| v.is_finite())
        && positions
            .iter()
            .flatten()
            .all(|p| p[0].is_finite() && p[1].is_finite());
    if !finite {
        return Err(CalibrationError::Diverged(
            "landmarks: the estimate is not finite".into(),
        ));
    }
    let dmax = distances.iter().copied().fold(0.0f64, f64::max).max(0.5);
    let inverse = Inverse::new(&alpha, [0.0, 1.5 * dmax])?;
    let used_dets: Vec<&Detection> = est.used.iter().map(|&i| obs_dets[i]).collect();
    let used_obs: Vec<&Observation> = est.used.iter().map(|&i| &set.observations[i]).collect();
    let truth = truth_distances(rec, &stops, &used_dets, &used_obs, &sensors, radius);
    let metrics = truth.as_ref().map(|(d, how)| {
        notes.push(format!("truth distances: {how}"));
        let raw: Vec<f64> = used_obs.iter().map(|o| o.range_m).collect();
        let m = metrics(
            &raw,
            &raw.iter().map(|r| inverse.distance(*r)).collect::<Vec<_>>(),
            d,
        );
        if let (Some(_), Estimator::Refined) = (&est.refined, opts.estimator) {
            if let Ok(p) = Inverse::new(&est.paper.alpha, [0.0, 1.5 * dmax]) {
                let mp = metrics(
                    &raw,
                    &raw.iter().map(|r| p.distance(*r)).collect::<Vec<_>>(),
                    d,
                );
                notes.push(format!(
                    "MSE ratio (eq. 31): paper estimator {:.2}, refined {:.2}",
                    mp.mse_ratio(),
                    m.mse_ratio()
                ));
            }
        }
        m
    });
    let mut sensors_out = BTreeMap::new();
    sensors_out.insert(Sensor::Lidar, SensorModel { alpha, beta });
    let calibration = Calibration {
        method: Method::Landmarks,
        sensors: sensors_out,
        iterations,
        converged,
        metrics,
        order: Some(order),
        landmarks: Some(positions.into_iter().flatten().collect()),
        notes,
    };
    Ok(Analysis {
        stops,
        sensors,
        radius_m: radius,
        detections: dets,
        rejected,
        tracks: kept,
        observations: set,
        estimate: est,
        truth_distances: truth.map(|(d, _)| d),
        calibration,
    })
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

/// MSE of raw and calibrated distances against the truth.
fn metrics(raw: &[f64], calibrated: &[f64], truth: &[f64]) -> Metrics {
    let n = truth.len().max(1) as f64;
    let mse = |x: &[f64]| {
        x.iter()
            .zip(truth)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / n
    };
    let norm = truth.iter().map(|d| d * d).sum::<f64>() / n;
    let (r, c) = (mse(raw), mse(calibrated));
    Metrics {
        mse_raw: r,
        mse_calibrated: c,
        nmse_raw: r / norm,
        nmse_calibrated: c / norm,
    }
}

/// The true distance of each used observation: the range estimator applied to the simulator's
/// true ranges when every reading has one; else, with `truth.csv`, the landmarks placed by the
/// paper's eq. (20) from the true stop positions (Aitken's estimator with the sensor positions
/// known) and d = |c − s| − R.
fn truth_distances(
    rec: &Recording,
    stops: &[Stop],
    dets: &[&Detection],
    obs: &[&Observation],
    nominal: &[Pose2],
    radius: f64,
) -> Option<(Vec<f64>, &'static str)> {
    let mount = rec.meta.lidar.as_ref();
    let landmarks = obs.iter().map(|o| o.landmark + 1).max().unwrap_or(0);
    if let Some(d) = dets
        .iter()
        .map(|d| d.true_range_m)
        .collect::<Option<Vec<f64>>>()
    {
        return Some((
            d,
            "the range estimator applied to lidar.csv's true_range_m of the same readings",
        ));
    }
    let truth = rec.truth.as_deref().filter(|t| !t.is_empty())?;
    let start = Pose2::new(truth[0].x_m, truth[0].y_m, truth[0].yaw_rad);
    let true_sensor: Vec<Option<Pose2>> = stops
        .iter()
        .map(|s| {
            let w: Vec<_> = truth
                .iter()
                .filter(|t| t.t_s >= s.t_start_s && t.t_s <= s.t_end_s)
                .collect();
            let t = w.get(w.len() / 2)?;
            let p = Pose2::new(t.x_m, t.y_m, t.yaw_rad).relative_to(&start);
            Some(p.compose(
                mount.map_or(0.0, |m| m.x_m),
                mount.map_or(0.0, |m| m.y_m),
                mount.map_or(0.0, |m| m.yaw_deg.to_radians()),
            ))
        })
        .collect();
    let mut centres = vec![None; landmarks];
    for (l, c) in centres.iter_mut().enumerate() {
        let lines: Vec<BearingLine> = obs
            .iter()
            .filter(|o| o.landmark == l)
            .filter_map(|o| {
                let s = true_sensor[o.stop]?;
                Some(BearingLine {
                    sensor: [s.x, s.y],
                    // The bearing measured in the lidar frame, turned by the true heading.
                    bearing_rad: o.bearing_rad - nominal[o.stop].yaw + s.yaw,
                    range_m: o.range_m,
                })
            })
            .collect();
        *c = intersect(&lines, Weights::Paper).ok().map(|p| p.centre);
    }
    let d: Option<Vec<f64>> = obs
        .iter()
        .map(|o| {
            let c = centres[o.landmark]?;
            let s = true_sensor[o.stop]?;
            Some((c[0] - s.x).hypot(c[1] - s.y) - radius)
        })
        .collect();
    d.map(|d| {
        (
            d,
            "landmarks placed by eq. (20) from the true stop poses of truth.csv",
        )
    })
}
