//! The calibrator's last stage: score the calibration against the truth, when the recording
//! has it.

use hilsim_recording::Recording;

use super::model::Model;
use crate::landmarks::association::Track;
use crate::landmarks::detection::Detection;
use crate::landmarks::estimate::{Estimate, Observation, ObservationSet};
use crate::landmarks::inversion::Inverse;
use crate::landmarks::options::{Estimator, Options};
use crate::landmarks::positions::{intersect, BearingLine, Weights};
use crate::landmarks::stops::Stop;
use crate::{CalibrationError, LidarModelMetrics, Metrics};
use hilsim_recording::Pose;

/// What the stages before the estimator found, as the scoring needs it.
pub(super) struct Seen<'a> {
    /// The stand-still stops.
    pub stops: &'a [Stop],
    /// Each stop's nominal sensor pose.
    pub sensors: &'a [Pose],
    /// The landmark radius, metres.
    pub radius: f64,
    /// Every detection.
    pub dets: &'a [Detection],
    /// The tracks kept.
    pub tracks: &'a [Track],
    /// The estimator's input.
    pub set: &'a ObservationSet,
}

/// Score against truth: the true distances of the used observations and the MSE of the raw and
/// calibrated distances against them (with the paper estimator's MSE ratio next to ours), when
/// the truth is known.
pub(super) fn score_against_truth(
    rec: &Recording,
    opts: &Options,
    seen: &Seen<'_>,
    est: &Estimate,
    model: &Model,
    notes: &mut Vec<String>,
) -> Result<(Option<Metrics>, Option<Vec<f64>>), CalibrationError> {
    let obs_dets: Vec<&Detection> = seen
        .tracks
        .iter()
        .flat_map(|t| t.iter().map(|&i| &seen.dets[i]))
        .collect();
    let dmax = model
        .distances
        .iter()
        .copied()
        .fold(0.0f64, f64::max)
        .max(0.5);
    let inverse = Inverse::new(&model.alpha, [0.0, 1.5 * dmax])?;
    let used_dets: Vec<&Detection> = est.used.iter().map(|&i| obs_dets[i]).collect();
    let used_obs: Vec<&Observation> = est
        .used
        .iter()
        .map(|&i| &seen.set.observations[i])
        .collect();
    let truth = truth_distances(
        rec,
        seen.stops,
        &used_dets,
        &used_obs,
        seen.sensors,
        seen.radius,
    );
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
    Ok((metrics, truth.map(|(d, _)| d)))
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
        // The estimates are the raw readings inverted through the fitted model (eq. 30).
        lidar_model: LidarModelMetrics::score(
            raw.iter()
                .zip(calibrated)
                .zip(truth)
                .map(|((&r, &c), &d)| (r, c, d)),
        ),
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
    nominal: &[Pose],
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
    let start = Pose::new(truth[0].x_m, truth[0].y_m, truth[0].yaw_rad);
    let true_sensor: Vec<Option<Pose>> = stops
        .iter()
        .map(|s| {
            let w: Vec<_> = truth
                .iter()
                .filter(|t| t.t_s >= s.t_start_s && t.t_s <= s.t_end_s)
                .collect();
            let t = w.get(w.len() / 2)?;
            let p = Pose::new(t.x_m, t.y_m, t.yaw_rad).relative_to(&start);
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
