//! A truth sparser than the encoders, filled in by them. A logger that stores a pose only with
//! each scan (the CARMEN "corrected" logs: a scan-matched pose every metre or every few
//! seconds) gives a path whose straight chords between poses cut every curve the robot drove.
//! The encoders' own travel along those chords is then not what they measured, and the
//! shortfall accumulates. Between two poses the robot followed the encoders' shape; the shape
//! is dead-reckoned from each pose and bent so that it arrives at the next one: the heading's
//! error spread over the interval in proportion to the turning done, then the position's in
//! proportion to the distance driven (a robot standing still is not moved by the correction).
//! At each pose the path is the truth, so whatever the encoders get wrong between poses (a
//! radius, a base, a delay) is still measured against it.

use hilsim_calibrator::stats::median;
use hilsim_recording::{OdometrySample, Pose, TruthSample};
use nalgebra::{DMatrix, DVector};

use crate::trajectory::wrap;

/// How many encoder readings a truth interval must hold, at its median, before it is filled:
/// below it the straight chord is already within the encoders' own step.
const READINGS_PER_INTERVAL: f64 = 2.0;

/// The span the encoders' travel is judged over against a sparse truth, seconds. A logger's
/// poses depart from the path by about the same at every pose (a stamp a tenth of a second
/// off at speed, a scan matched a few centimetres off), so neighbouring intervals' departures
/// cancel in pairs; over spans of several poses the departure stays that of two poses while
/// an effect of the wheels grows with the travel.
const JUDGED_SPAN_S: f64 = 10.0;

/// The fewest spans a log is judged over when it is too short for spans of
/// [`JUDGED_SPAN_S`]: two rows each, enough for the residuals to be placed in bins of 30.
const MIN_SPANS: usize = 40;

/// How many of `truth`'s intervals make one span of at least [`JUDGED_SPAN_S`], at their
/// median step, but no more than leave [`MIN_SPANS`] spans (at least one).
#[must_use]
pub(crate) fn poses_per_span(truth: &[TruthSample]) -> usize {
    let for_span = median_step(truth.iter().map(|s| s.t_s))
        .map_or(1, |step| (JUDGED_SPAN_S / step).ceil() as usize);
    let for_count = truth.len().saturating_sub(1) / MIN_SPANS;
    for_span.min(for_count).max(1)
}

/// Whether `truth` is sparse beside `odometry`: its median step holds more than
/// [`READINGS_PER_INTERVAL`] of the encoders' median steps.
#[must_use]
pub(crate) fn is_sparse(truth: &[TruthSample], odometry: &[OdometrySample]) -> bool {
    let truth_step = median_step(truth.iter().map(|s| s.t_s));
    let odometry_step = median_step(odometry.iter().map(|s| s.t_s));
    match (truth_step, odometry_step) {
        (Some(t), Some(o)) => t > READINGS_PER_INTERVAL * o,
        _ => false,
    }
}

/// Whether `recording`'s encoders are judged against a sparse truth, whose spans between poses
/// read their delay or slip whatever the scatter of their stamps (`wheel_spans.rs`).
#[must_use]
pub(crate) fn reads_encoder_leads(recording: &hilsim_recording::Recording) -> bool {
    match (recording.truth.as_deref(), recording.odometry.as_deref()) {
        (Some(truth), Some(odometry)) => !truth.is_empty() && is_sparse(truth, odometry),
        _ => false,
    }
}

/// The median of the positive steps between consecutive `times`.
fn median_step(times: impl Iterator<Item = f64>) -> Option<f64> {
    let times: Vec<f64> = times.collect();
    let mut steps: Vec<f64> = times
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .collect();
    (!steps.is_empty()).then(|| median(&mut steps))
}

/// How far the encoders' travel over a span of a sparse truth departs from the truth's, beyond
/// any effect: a logger's poses (scan-matched, stamped with their scans, a stamp off by
/// a tenth of a second a metre apart at speed) are not a motion-capture system's. A departure
/// of standard deviation `sd_m` whatever the span, plus `share` of the span's travel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct IntervalNoise {
    pub sd_m: f64,
    pub share: f64,
}

/// The regressors of a span's travel [`IntervalNoise::measure`] takes out.
pub(crate) const REGRESSORS: usize = 3;

/// The weight of gross departures (a pose stamped seconds off, a pose the scan matching got
/// wrong) in an interval's travel, against which the noise is measured and readings judged.
pub(crate) const GROSS_SHARE: f64 = 0.02;
/// The span gross departures are spread over, metres (the intervals' travel is about a metre).
pub(crate) const GROSS_SPAN_M: f64 = 2.0;

impl IntervalNoise {
    /// The variance of one span's departure whose travel is `travel_m`.
    #[must_use]
    pub(crate) fn variance(&self, travel_m: f64) -> f64 {
        self.sd_m * self.sd_m + (self.share * travel_m).powi(2)
    }

    /// Measured from `spans`, each span's regressors (what the path predicts of its travel
    /// and what the wheels' linear effects would add to it: the path's mean travel, its turn,
    /// its change of speed) and the encoders' travel: the best weighted least-squares
    /// combination is taken out first (a wrong radius, base or delay is an effect, not noise),
    /// weighted by the noise found and refound once; the noise is the maximum-likelihood pair
    /// on a grid, against gross departures of weight [`GROSS_SHARE`]. `travel` picks the
    /// regressor the departure grows with.
    #[must_use]
    pub(crate) fn measure(spans: &[([f64; REGRESSORS], f64)], travel: usize) -> Option<Self> {
        if spans.len() < 4 * REGRESSORS {
            return None;
        }
        let mut noise = Self {
            sd_m: 1.0,
            share: 0.0,
        };
        for _ in 0..2 {
            let rows = spans.len();
            let weights: Vec<f64> = spans
                .iter()
                .map(|(x, _)| 1.0 / noise.variance(x[travel]).sqrt())
                .collect();
            let design = DMatrix::from_fn(rows, REGRESSORS, |i, j| weights[i] * spans[i].0[j]);
            let counted = DVector::from_fn(rows, |i, _| weights[i] * spans[i].1);
            let coefficients = design.svd(true, true).solve(&counted, 1e-12).ok()?;
            let departures: Vec<(f64, f64)> = spans
                .iter()
                .map(|(x, counted)| {
                    let fitted: f64 = x.iter().zip(coefficients.iter()).map(|(a, b)| a * b).sum();
                    (counted - fitted, x[travel])
                })
                .collect();
            noise = Self::most_likely(&departures);
        }
        Some(noise)
    }

    /// The grid's (sd from 1 mm to 0.5 m geometrically; share 0 to 30 %) most likely noise of
    /// `departures` (departure, travel).
    fn most_likely(departures: &[(f64, f64)]) -> Self {
        let density = GROSS_SHARE / GROSS_SPAN_M;
        let log_likelihood = |noise: &Self| -> f64 {
            departures
                .iter()
                .map(|(r, travel)| {
                    let var = noise.variance(*travel);
                    let normal =
                        (-0.5 * r * r / var).exp() / (2.0 * std::f64::consts::PI * var).sqrt();
                    ((1.0 - GROSS_SHARE) * normal + density).ln()
                })
                .sum()
        };
        let mut best = (
            f64::NEG_INFINITY,
            Self {
                sd_m: 0.001,
                share: 0.0,
            },
        );
        for i in 0..=40 {
            for j in 0..=30 {
                let noise = Self {
                    sd_m: 0.001 * 500f64.powf(f64::from(i) / 40.0),
                    share: 0.01 * f64::from(j),
                };
                let ll = log_likelihood(&noise);
                if ll > best.0 {
                    best = (ll, noise);
                }
            }
        }
        best.1
    }
}

/// The encoders' (left, right) travel at `t_s`, interpolated between their readings (held
/// beyond them); zero before their first reading.
#[must_use]
pub(crate) fn counted_at(samples: &[OdometrySample], t_s: f64) -> [f64; 2] {
    let k = samples.partition_point(|s| s.t_s <= t_s);
    if k == 0 {
        return [0.0; 2];
    }
    let p = samples[k - 1];
    let Some(q) = samples.get(k).filter(|q| q.t_s > p.t_s) else {
        return [p.left_m, p.right_m];
    };
    let u = (t_s - p.t_s) / (q.t_s - p.t_s);
    [
        p.left_m + u * (q.left_m - p.left_m),
        p.right_m + u * (q.right_m - p.right_m),
    ]
}

/// `truth` with the encoders' readings between each two of its poses added as poses: each
/// interval's dead-reckoned shape, bent to meet the poses at both ends (module docs). Readings
/// outside the truth's span add nothing; the truth's own poses are kept as they are.
#[must_use]
pub(crate) fn filled_by_encoders(
    truth: &[TruthSample],
    odometry: &[OdometrySample],
    wheel_base_m: f64,
) -> Vec<TruthSample> {
    let mut out = Vec::with_capacity(truth.len() + odometry.len());
    for pair in truth.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        out.push(a);
        if b.t_s > a.t_s {
            out.extend(interval(a, b, odometry, wheel_base_m));
        }
    }
    out.extend(truth.last().copied());
    out
}

/// The poses strictly between `a` and `b` at the encoders' readings there.
fn interval(
    a: TruthSample,
    b: TruthSample,
    odometry: &[OdometrySample],
    wheel_base_m: f64,
) -> Vec<TruthSample> {
    let first = odometry.partition_point(|o| o.t_s <= a.t_s);
    let last = odometry.partition_point(|o| o.t_s < b.t_s);
    if first >= last || first == 0 || last >= odometry.len() {
        return Vec::new();
    }
    // The readings at both ends, then those inside: (time, left, right).
    let at = |t: f64| {
        let k = odometry
            .partition_point(|o| o.t_s <= t)
            .clamp(1, odometry.len() - 1);
        let (p, q) = (odometry[k - 1], odometry[k]);
        let u = ((t - p.t_s) / (q.t_s - p.t_s)).clamp(0.0, 1.0);
        (
            t,
            p.left_m + u * (q.left_m - p.left_m),
            p.right_m + u * (q.right_m - p.right_m),
        )
    };
    let mut readings = vec![at(a.t_s)];
    readings.extend(
        odometry[first..last]
            .iter()
            .map(|o| (o.t_s, o.left_m, o.right_m)),
    );
    readings.push(at(b.t_s));
    // Each step's forward travel and turn, and how much of the interval's driving and turning
    // is done by the end of each step.
    let steps: Vec<(f64, f64)> = readings
        .windows(2)
        .map(|w| {
            let (l, r) = (w[1].1 - w[0].1, w[1].2 - w[0].2);
            ((l + r) / 2.0, (r - l) / wheel_base_m)
        })
        .collect();
    let shares = |amount: &dyn Fn(&(f64, f64)) -> f64| -> Vec<f64> {
        let total: f64 = steps.iter().map(|s| amount(s).abs()).sum();
        let span = b.t_s - a.t_s;
        let mut done = 0.0;
        steps
            .iter()
            .zip(readings.windows(2))
            .map(|(s, w)| {
                done += amount(s).abs();
                if total > 1e-9 {
                    done / total
                } else {
                    (w[1].0 - a.t_s) / span
                }
            })
            .collect()
    };
    let driven = shares(&|s| s.0);
    let turned = shares(&|s| s.1);
    // The heading, corrected so that it ends at b's.
    let mut headings = Vec::with_capacity(steps.len());
    let mut yaw = a.yaw_rad;
    for s in &steps {
        yaw += s.1;
        headings.push(yaw);
    }
    let heading_error = wrap(b.yaw_rad - yaw);
    let mut before = a.yaw_rad;
    let mut poses = Vec::with_capacity(steps.len());
    let mut pose = Pose::new(a.x_m, a.y_m, a.yaw_rad);
    for ((s, h), share) in steps.iter().zip(&headings).zip(&turned) {
        let corrected = h + heading_error * share;
        let mid = (before + corrected) / 2.0;
        pose = Pose::new(
            pose.x + s.0 * mid.cos(),
            pose.y + s.0 * mid.sin(),
            corrected,
        );
        before = corrected;
        poses.push(pose);
    }
    // The position, corrected so that it ends at b's.
    let end = poses[poses.len() - 1];
    let (ex, ey) = (b.x_m - end.x, b.y_m - end.y);
    readings[1..readings.len() - 1]
        .iter()
        .zip(&poses)
        .zip(&driven)
        .map(|((r, p), share)| TruthSample {
            t_s: r.0,
            x_m: p.x + ex * share,
            y_m: p.y + ey * share,
            yaw_rad: wrap(p.yaw),
        })
        .filter(|s| s.t_s > a.t_s && s.t_s < b.t_s)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t_s: f64, x_m: f64, y_m: f64, yaw_rad: f64) -> TruthSample {
        TruthSample {
            t_s,
            x_m,
            y_m,
            yaw_rad,
        }
    }

    /// Encoders of a robot driving a circle of radius 1 m at 0.5 m/s, read at 10 Hz, each
    /// wheel's count scaled by `scale`.
    fn circle(scale: f64, base: f64, end_s: f64) -> Vec<OdometrySample> {
        let (v, w) = (0.5, 0.5);
        (0..=(end_s * 10.0) as usize)
            .map(|k| {
                let t = k as f64 / 10.0;
                OdometrySample {
                    t_s: t,
                    left_m: scale * (v - w * base / 2.0) * t,
                    right_m: scale * (v + w * base / 2.0) * t,
                }
            })
            .collect()
    }

    fn on_circle(t: f64) -> TruthSample {
        let a = 0.5 * t;
        sample(t, a.sin(), 1.0 - a.cos(), a)
    }

    /// Truth every 3 s on a circle: the chords are short of the arc; filled by the encoders,
    /// the path runs along the circle between the poses, so its wheels travel the arc.
    #[test]
    fn a_sparse_circle_is_filled_along_the_arc() {
        let truth: Vec<_> = (0..=4).map(|k| on_circle(3.0 * f64::from(k))).collect();
        let odometry = circle(1.0, 0.3, 12.0);
        assert!(is_sparse(&truth, &odometry));
        let filled = filled_by_encoders(&truth, &odometry, 0.3);
        assert!(filled.len() > 100);
        for s in &filled {
            let on = on_circle(s.t_s);
            assert!((s.x_m - on.x_m).hypot(s.y_m - on.y_m) < 1e-3, "{s:?}");
            assert!(wrap(s.yaw_rad - on.yaw_rad).abs() < 1e-3, "{s:?}");
        }
    }

    /// Encoders counting 3 % long: the shape is bent back onto the truth, so the filled path
    /// is still the circle (within 1 cm: between poses the shape keeps 3 % of its own turn,
    /// a few millimetres sideways over a 1.5 m chord), and the encoders' excess is left for
    /// the diagnosis to see.
    #[test]
    fn encoders_counting_long_do_not_bend_the_path_away_from_the_truth() {
        let truth: Vec<_> = (0..=4).map(|k| on_circle(3.0 * f64::from(k))).collect();
        let filled = filled_by_encoders(&truth, &circle(1.03, 0.3, 12.0), 0.3);
        for s in &filled {
            let on = on_circle(s.t_s);
            assert!((s.x_m - on.x_m).hypot(s.y_m - on.y_m) < 1e-2, "{s:?}");
        }
    }

    /// A truth as dense as the encoders is not sparse; a truth beyond the encoders' span is
    /// kept as it is.
    #[test]
    fn dense_or_uncovered_truth_is_kept() {
        let odometry = circle(1.0, 0.3, 2.0);
        let dense: Vec<_> = (0..=20).map(|k| on_circle(0.1 * f64::from(k))).collect();
        assert!(!is_sparse(&dense, &odometry));
        let beyond = vec![on_circle(5.0), on_circle(8.0)];
        assert_eq!(filled_by_encoders(&beyond, &odometry, 0.3), beyond);
    }
}
