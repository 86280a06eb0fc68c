//! The landmark calibrator on a recording: stops → averaged scans → cylinders → tracks →
//! observations → the estimator → a [`Calibration`].

mod model;
mod truth;

use std::collections::BTreeMap;

use hilsim_recording::{LidarSample, Recording};
use rayon::prelude::*;

use self::model::{check_model, choose_model, run_estimator};
use self::truth::{score_against_truth, Seen};
use super::association::{associate, place, Track};
use super::detection::{candidate_radii, detect, Detection, Rejections};
use super::estimate::{Estimate, Observation, ObservationSet};
use super::options::Options;
use super::scan::{average_stop, StopScan};
use super::stops::{find_stops, Stop};
use crate::landmarks::regression::beta_sd;
use crate::stats::median;
use crate::{Calibration, CalibrationError, Method, Sensor, SensorModel};
use hilsim_recording::Pose;

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
    pub sensors: Vec<Pose>,
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
    let lidar = check_lidar(rec)?;
    let mut notes = Vec::new();
    let stops = stand_still_stops(rec, opts, &mut notes)?;
    let scans = average_scans(lidar, &stops, opts);
    let radius = landmark_radius(rec, opts, &scans, &mut notes)?;
    let sensors = sensor_poses(rec, &stops);
    let (dets, rejected) = detect_landmarks(&scans, radius, opts, &mut notes)?;
    let kept = keep_tracks(&dets, &sensors, radius, opts, &mut notes)?;
    let set = build_observations(&stops, &sensors, &dets, &kept, radius);
    let est = run_estimator(&set, opts, &mut notes)?;
    let model = choose_model(&est, opts, &mut notes);
    check_model(&model, opts, &mut notes)?;
    let seen = Seen {
        stops: &stops,
        sensors: &sensors,
        radius,
        dets: &dets,
        tracks: &kept,
        set: &set,
    };
    let (metrics, truth) = score_against_truth(rec, opts, &seen, &est, &model, &mut notes)?;
    let mut sensors_out = BTreeMap::new();
    sensors_out.insert(
        Sensor::Lidar,
        SensorModel {
            beta_sd: beta_sd(
                &reading_distances(&set, &est.used, &model.distances),
                &model.beta,
            ),
            alpha: model.alpha,
            beta: model.beta,
            alpha_sd: model.alpha_sd,
        },
    );
    let mut checks = super::checks::landmark_checks(&set, &est.used, &model.positions, model.order);
    if let Some(lidar) = sensors_out.get(&Sensor::Lidar) {
        checks.extend(crate::checks::bias_plausible("lidar", lidar));
    }
    let calibration = Calibration {
        method: Method::Landmarks,
        sensors: sensors_out,
        iterations: model.iterations,
        converged: model.converged,
        metrics,
        order: Some(model.order),
        odometry: None,
        landmarks: Some(model.positions.into_iter().flatten().collect()),
        checks,
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
        truth_distances: truth,
        calibration,
    })
}

/// One distance per reading behind the used observations (an averaged range stands for its
/// `count` readings), as the noise polynomial was fitted.
fn reading_distances(set: &ObservationSet, used: &[usize], distances: &[f64]) -> Vec<f64> {
    used.iter()
        .zip(distances)
        .flat_map(|(&i, &d)| {
            let count = set.observations.get(i).map_or(1, |o| o.count.max(1));
            std::iter::repeat_n(d, count)
        })
        .collect()
}

/// Check the lidar: readings present and in time order.
fn check_lidar(rec: &Recording) -> Result<&[LidarSample], CalibrationError> {
    let lidar = rec
        .lidar
        .as_deref()
        .filter(|l| !l.is_empty())
        .ok_or_else(|| {
            CalibrationError::Missing("the recording has no lidar.csv readings".into())
        })?;
    if lidar.windows(2).any(|w| w[1].t_s < w[0].t_s) {
        return Err(CalibrationError::Invalid(
            "landmarks: lidar.csv rows go back in time".into(),
        ));
    }
    Ok(lidar)
}

/// Find the stops: the stand-still intervals, at least two of them.
fn stand_still_stops(
    rec: &Recording,
    opts: &Options,
    notes: &mut Vec<String>,
) -> Result<Vec<Stop>, CalibrationError> {
    let (stops, report) = find_stops(rec, &opts.stops)?;
    for (t, v) in &report.moving {
        notes.push(format!(
            "warning: stop at t = {t:.2} s skipped: the odometry shows motion ({v:.3} m/s)"
        ));
    }
    for (t, revolutions) in &report.too_short {
        notes.push(format!(
            "stop at t = {t:.2} s skipped: {revolutions:.1} revolution(s) at rest, {} needed",
            opts.stops.min_revolutions
        ));
    }
    let mut sources: Vec<&str> = stops.iter().map(|s| s.rest_from.describe()).collect();
    sources.sort_unstable();
    sources.dedup();
    if !stops.is_empty() {
        notes.push(format!(
            "{} stop(s) used, each from the moment of rest found by {}; lidar revolution {:.3} s",
            stops.len(),
            sources.join(" or "),
            report.revolution_s
        ));
    }
    if stops.len() < 2 {
        return Err(CalibrationError::TooFewSamples(format!(
            "landmarks: found {} stand-still stop(s) holding at least {} lidar revolutions at \
             rest; the bearings of two stops at least are needed to place a landmark",
            stops.len(),
            opts.stops.min_revolutions
        )));
    }
    Ok(stops)
}

/// Average each stop's revolutions beam by beam.
fn average_scans(lidar: &[LidarSample], stops: &[Stop], opts: &Options) -> Vec<StopScan> {
    stops
        .par_iter()
        .map(|s| average_stop(lidar, s, &opts.detection))
        .collect()
}

/// The landmark radius: given (option or `meta.toml`), else the median of free circle fits.
fn landmark_radius(
    rec: &Recording,
    opts: &Options,
    scans: &[StopScan],
    notes: &mut Vec<String>,
) -> Result<f64, CalibrationError> {
    match opts.landmark_radius_m.or(rec.meta.world.landmark_radius_m) {
        Some(r) => {
            notes.push(format!("landmark radius {r:.3} m (given)"));
            Ok(r)
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
            Ok(r)
        }
    }
}

/// Each stop's nominal sensor (lidar) pose: the stop's pose composed with the lidar mount.
fn sensor_poses(rec: &Recording, stops: &[Stop]) -> Vec<Pose> {
    let mount = rec.meta.lidar.as_ref();
    stops
        .iter()
        .map(|s| {
            s.pose.compose(
                mount.map_or(0.0, |m| m.x_m),
                mount.map_or(0.0, |m| m.y_m),
                mount.map_or(0.0, |m| m.yaw_deg.to_radians()),
            )
        })
        .collect()
}

/// Detect the cylinders in every stop's scan, counting the segments rejected.
fn detect_landmarks(
    scans: &[StopScan],
    radius: f64,
    opts: &Options,
    notes: &mut Vec<String>,
) -> Result<(Vec<Detection>, Rejections), CalibrationError> {
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
        scans.len(),
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
            scans.len()
        )));
    }
    Ok((dets, rejected))
}

/// Keep the tracks: associate the detections across stops and keep the landmarks seen from
/// enough stops.
fn keep_tracks(
    dets: &[Detection],
    sensors: &[Pose],
    radius: f64,
    opts: &Options,
    notes: &mut Vec<String>,
) -> Result<Vec<Track>, CalibrationError> {
    let tracks = associate(dets, sensors, radius, &opts.association);
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
    Ok(kept)
}

/// Build the observations: the estimator's input, one per detection of a kept track.
fn build_observations(
    stops: &[Stop],
    sensors: &[Pose],
    dets: &[Detection],
    kept: &[Track],
    radius: f64,
) -> ObservationSet {
    ObservationSet {
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
    }
}
