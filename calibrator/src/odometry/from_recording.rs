//! A recording's drive as tuples: the lidar's revolutions matched scan to scan, the encoders'
//! travel over the same intervals, then the estimate of [`calibrate_intervals`].

use hilsim_recording::{Ends, LidarSample, OdometrySample, Place, Pose, Recording, TimedPath};
use rayon::prelude::*;

use super::estimate::calibrate_intervals;
use super::interval::Interval;
use super::kinematics::Geometry;
use crate::checks::Check;
use crate::landmarks::Inverse;
use crate::scan_match::{match_scans, MatchFailure, MatchOptions, Scan};
use crate::{Calibration, CalibrationError};

/// What a user sets of the calibration of a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingOptions {
    /// An interval's length, seconds: from each matched revolution to the first one at least
    /// this much later. About the paper's (its tuples span 0.8 s): long enough that the
    /// motion stands well above the scan matcher's millimetres, short enough for the odometry's
    /// guess to bring the matcher within reach.
    pub interval_s: f64,
    /// The wheels' nominal radius, metres, when `meta.toml` does not give it (or to override
    /// it): the radius the encoders' turns were multiplied by to report travel.
    pub nominal_wheel_radius_m: Option<f64>,
    /// How late the lidar's stamps are against the encoders', seconds (a scan stamped `t` was
    /// taken when the encoders' clock read `t − latency`); `None`: estimated from the drive.
    pub lidar_latency_s: Option<f64>,
    /// The lidar's range model, eq. (2)'s bias coefficients α₀.. (a calibration's): each range
    /// is turned back into a distance through it before the scans are matched. `None`: ranges
    /// as the lidar reports them.
    pub lidar_bias: Option<Vec<f64>>,
}

impl Default for RecordingOptions {
    fn default() -> Self {
        Self {
            interval_s: 1.0,
            nominal_wheel_radius_m: None,
            lidar_latency_s: None,
            lidar_bias: None,
        }
    }
}

/// Least readings for a revolution to be matched: 30. Below that a scan holds one or two
/// surfaces' worth of points, too few to fix three degrees of freedom with any margin.
pub const MIN_SCAN_POINTS: usize = 30;

/// Longest interval, seconds: 2. Longer ones are gaps in the data (a revolution lost), over
/// which the wheels' speeds cannot be taken as constant, the model's assumption.
pub const MAX_INTERVAL_S: f64 = 2.0;

/// An interval is standing still when each wheel moved less than this: 0.5 mm (half the
/// XV-11 robot encoders' millimetre). Its scan match measures only the matcher's noise.
const STILL_M: f64 = 0.0005;

/// Largest lidar latency searched for, seconds: 1. A driver's buffering or a host's clock puts
/// a log's stamps hundreds of milliseconds apart (the CoreSLAM rover's scans lag its encoders by
/// about 0.19 s); beyond a second, intervals of a second no longer overlap their own wheel
/// motion.
pub const MAX_LIDAR_LATENCY_S: f64 = 1.0;

/// The latency search's grid step, seconds: 10 ms, a tenth of a fast lidar's revolution.
const LATENCY_STEP_S: f64 = 0.01;

/// An estimated latency this far from the one the scans were first matched with has them
/// matched again from guesses at the right instants: 10 ms.
const REMATCH_LATENCY_S: f64 = 0.01;

/// Largest share of intervals whose scans could not be matched: 20 %. More means the room
/// does not fix the lidar's motion (a corridor, open space) for much of the drive, and the
/// rest may not be a random sample of it.
pub const MAX_FAILED_MATCH_SHARE: f64 = 0.20;

/// A recording's drive cut into intervals, with what could not be used and why.
#[derive(Debug, Clone)]
pub struct DriveIntervals {
    /// The matched intervals, in time order.
    pub intervals: Vec<Interval>,
    /// Each matched interval's start and end, seconds.
    pub spans_s: Vec<[f64; 2]>,
    /// The geometry the recording declares (`meta.toml`'s wheel base and lidar mount, the
    /// nominal wheel radius): the scan matcher's guesses and the de-skewing use it.
    pub nominal: Geometry,
    /// The lidar's revolutions.
    pub revolutions: usize,
    /// Intervals whose scans could not be matched, with why.
    pub failed: Vec<MatchFailure>,
    /// Intervals standing still.
    pub still: usize,
    /// Intervals longer than [`MAX_INTERVAL_S`] or outside the odometry's span.
    pub gaps: usize,
    /// Intervals with a revolution of fewer than [`MIN_SCAN_POINTS`] readings.
    pub sparse: usize,
    /// How late the lidar's stamps are taken to be against the encoders', seconds: the
    /// options', else the estimate's, else 0.
    pub lidar_latency_s: f64,
    /// The latency estimated from the drive, when it was not given.
    pub latency_estimate: Option<LatencyEstimate>,
    /// What was assumed, for people.
    pub notes: Vec<String>,
}

/// The lidar's latency against the encoders, estimated from the drive: the one at which the
/// scan-matched turns and the wheels' turns over each interval agree best (the paper's first
/// step, the turn gains by least squares, at each candidate latency), within
/// ±[`MAX_LIDAR_LATENCY_S`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatencyEstimate {
    /// Seconds.
    pub latency_s: f64,
    /// Its standard deviation from the curvature of the turns' profile likelihood, seconds
    /// (`None` when the profile is flat there).
    pub sd_s: Option<f64>,
    /// Whether the best latency is at the edge of the search: the true one may lie beyond it.
    pub at_bound: bool,
}

/// `rec`'s drive as intervals: each one's lidar motion from scan-to-scan matching
/// (point-to-line ICP, [`crate::scan_match`]) of revolutions de-skewed along the dead-reckoned
/// path, its wheel turns from the encoders' travel over the nominal radius.
///
/// # Errors
/// A table or a `meta.toml` key the method needs is missing, or the options are out of range.
pub fn drive_intervals(
    rec: &Recording,
    options: &RecordingOptions,
) -> Result<DriveIntervals, CalibrationError> {
    let lidar = rec
        .lidar
        .as_deref()
        .filter(|l| !l.is_empty())
        .ok_or_else(|| {
            CalibrationError::Missing("odometry: the recording has no lidar.csv".into())
        })?;
    let odometry = rec
        .odometry
        .as_deref()
        .filter(|o| o.len() >= 2)
        .ok_or_else(|| {
            CalibrationError::Missing(
                "odometry: the recording has no odometry.csv (wheel travel) of two rows or more"
                    .into(),
            )
        })?;
    let nominal_radius = options
        .nominal_wheel_radius_m
        .or(rec.meta.robot.wheel_radius_m)
        .filter(|r| r.is_finite() && *r > 0.0)
        .ok_or_else(|| {
            CalibrationError::Missing(
                "odometry: meta.toml gives no nominal wheel radius ([robot] wheel_radius_m), \
                 which the encoders' travel was reported with; give it (calibrate \
                 --wheel-radius-m R)"
                    .into(),
            )
        })?;
    if !(options.interval_s > 0.0 && options.interval_s <= MAX_INTERVAL_S) {
        return Err(CalibrationError::Invalid(format!(
            "odometry: an interval must last more than 0 s and at most {MAX_INTERVAL_S} s"
        )));
    }
    let mut notes = Vec::new();
    let mount = rec.meta.lidar.unwrap_or_else(|| {
        notes.push(
            "meta.toml gives no lidar mount: the scans are de-skewed and matched from guesses \
             as if the lidar sat on the axle's centre"
                .into(),
        );
        hilsim_recording::Mount::default()
    });
    let nominal = Geometry {
        left_radius_m: nominal_radius,
        right_radius_m: nominal_radius,
        wheel_base_m: rec.meta.robot.wheel_base_m,
        lidar: [mount.x_m, mount.y_m, mount.yaw_rad()],
    };
    let path = Path::new(odometry, nominal.wheel_base_m);
    let given = options.lidar_latency_s;
    if given.is_some_and(|l| !(l.is_finite() && l.abs() <= MAX_LIDAR_LATENCY_S)) {
        return Err(CalibrationError::Invalid(format!(
            "odometry: the lidar's latency must be within ±{MAX_LIDAR_LATENCY_S} s"
        )));
    }
    let inverse = match &options.lidar_bias {
        Some(alpha) => {
            let farthest = lidar
                .iter()
                .filter(|s| s.range_m.is_finite())
                .fold(1.0f64, |m, s| m.max(s.range_m));
            // Search up to past the farthest reading: a range model is fitted below 100 m.
            let inverse = Inverse::new(alpha, [0.0, 2.0 * farthest + 100.0]).map_err(|e| {
                CalibrationError::Invalid(format!("odometry: the lidar's range model: {e}"))
            })?;
            notes.push(format!(
                "ranges turned into distances through the lidar's range model (alpha {alpha:?}) \
                 before matching"
            ));
            Some(inverse)
        }
        None => None,
    };
    let mut latency = given.unwrap_or(0.0);
    let read = Readings {
        lidar,
        inverse: inverse.as_ref(),
    };
    let mut deskew = true;
    let mut scans = revolutions(&read, &path, &nominal, latency, deskew);
    // A chain of intervals: each interval's last revolution is the next one's first, so no
    // two intervals share a stretch of the drive (their errors would be counted twice).
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    let mut a = 0;
    while a < scans.len() {
        let until = scans[a].t_s + options.interval_s;
        let Some(b) = (a + 1..scans.len()).find(|&b| scans[b].t_s >= until) else {
            break;
        };
        pairs.push((a, b));
        a = b;
    }
    let matching = MatchOptions::default();
    let match_all = |scans: &[Revolution], latency: f64| -> Vec<Outcome> {
        pairs
            .par_iter()
            .map(|&(a, b)| interval(&scans[a], &scans[b], &path, &nominal, &matching, latency))
            .collect()
    };
    // A lidar that takes a revolution at once (a simulator's snapshot) keeps per-reading stamps
    // all the same; de-skewing its scans would bend them. Its scans match better as they are.
    if takes_revolution_at_once(&read, &pairs, &scans, &path, &nominal, &matching, latency) {
        deskew = false;
        scans = revolutions(&read, &path, &nominal, latency, deskew);
        notes.push(
            "the scans match better as they are than de-skewed while turning: the lidar takes \
             each revolution at one instant (a simulator's snapshot); they are not de-skewed"
                .into(),
        );
    }
    let mut outcomes = match_all(&scans, latency);
    let mut latency_estimate = None;
    if given.is_none() {
        let turns: Vec<([f64; 2], f64)> = outcomes
            .iter()
            .zip(&pairs)
            .filter_map(|(o, &(a, b))| match o {
                Outcome::Matched(i) => Some(([scans[a].t_s, scans[b].t_s], i.lidar_motion[2])),
                _ => None,
            })
            .collect();
        latency_estimate = estimate_latency(&turns, &path, &nominal);
        if let Some(e) = latency_estimate {
            if (e.latency_s - latency).abs() > REMATCH_LATENCY_S {
                latency = e.latency_s;
                scans = revolutions(&read, &path, &nominal, latency, deskew);
                outcomes = match_all(&scans, latency);
            }
        }
    }
    let mut drive = DriveIntervals {
        intervals: Vec::new(),
        spans_s: Vec::new(),
        nominal,
        revolutions: scans.len(),
        failed: Vec::new(),
        still: 0,
        gaps: 0,
        sparse: 0,
        lidar_latency_s: latency,
        latency_estimate,
        notes,
    };
    for (outcome, (a, b)) in outcomes.into_iter().zip(pairs) {
        match outcome {
            Outcome::Matched(t) => {
                drive.intervals.push(t);
                drive.spans_s.push([scans[a].t_s, scans[b].t_s]);
            }
            Outcome::Still => drive.still += 1,
            Outcome::Gap => drive.gaps += 1,
            Outcome::Sparse => drive.sparse += 1,
            Outcome::Failed(f) => drive.failed.push(f),
        }
    }
    Ok(drive)
}

/// Calibrates the wheels and the lidar's mount from `rec`'s encoders and lidar: the intervals
/// of [`drive_intervals`], then the estimate of [`calibrate_intervals`], its wheel scales
/// against the nominal radius, and a check of how many matches failed.
///
/// # Errors
/// A table or a `meta.toml` key the method needs is missing, too few intervals could be
/// matched, or the estimate's errors.
pub fn calibrate(
    rec: &Recording,
    options: &RecordingOptions,
) -> Result<Calibration, CalibrationError> {
    let drive = drive_intervals(rec, options)?;
    let DriveIntervals {
        intervals,
        nominal,
        revolutions,
        failed,
        still,
        gaps,
        sparse,
        lidar_latency_s,
        latency_estimate,
        mut notes,
        ..
    } = drive;
    let attempted = intervals.len() + failed.len();
    if intervals.len() < 12 {
        return Err(CalibrationError::TooFewSamples(format!(
            "odometry: {} interval(s) of the drive could be matched ({revolutions} \
             revolutions; {} failed to match, {still} standing still, {gaps} gaps, {sparse} \
             with fewer than {MIN_SCAN_POINTS} readings); at least 12 are needed",
            intervals.len(),
            failed.len()
        )));
    }
    let mut calibration = calibrate_intervals(&intervals)?;
    let nominal_radius = nominal.left_radius_m;
    if let Some(model) = calibration.odometry.as_mut() {
        model.wheel_scale = Some([
            model.left_wheel_radius_m / nominal_radius,
            model.right_wheel_radius_m / nominal_radius,
        ]);
        model.lidar_latency_s = Some(lidar_latency_s);
        model.lidar_latency_sd_s = latency_estimate.and_then(|e| e.sd_s);
    }
    match latency_estimate {
        Some(e) => {
            calibration.checks.push(Check::at_most(
                "odometry.lidar_latency_s",
                e.latency_s.abs(),
                MAX_LIDAR_LATENCY_S - LATENCY_STEP_S,
                format!(
                    "the lidar's stamps are {:+.3} s{} against the encoders' (estimated from the \
                     turns); at the edge of the ±{MAX_LIDAR_LATENCY_S} s search the true offset \
                     may lie beyond it: fix the stamps, or give it (--lidar-latency-s)",
                    e.latency_s,
                    e.sd_s.map_or(String::new(), |sd| format!(" ± {sd:.3}"))
                ),
            ));
            notes.push(format!(
                "the lidar's stamps taken as {:+.3} s late against the encoders' (estimated{}); \
                 each interval's wheel turns are the encoders' over its scans' instants",
                lidar_latency_s,
                e.sd_s.map_or(String::new(), |sd| format!(", sd {sd:.3} s"))
            ));
        }
        None if options.lidar_latency_s.is_some() => notes.push(format!(
            "the lidar's stamps taken as {lidar_latency_s:+.3} s late against the encoders' (given)"
        )),
        None => notes.push(
            "the lidar's latency against the encoders could not be estimated (too few turning \
             intervals): taken as 0"
                .into(),
        ),
    }
    let share = failed.len() as f64 / attempted.max(1) as f64;
    let mut kinds: Vec<(String, usize)> = Vec::new();
    for f in &failed {
        let kind = match f {
            MatchFailure::TooFewPoints { .. } => "too few points",
            MatchFailure::NotConverged { .. } => "did not settle",
            MatchFailure::Degenerate { .. } => "geometry did not fix the motion",
            _ => "other",
        };
        match kinds.iter_mut().find(|(k, _)| k == kind) {
            Some((_, n)) => *n += 1,
            None => kinds.push((kind.to_string(), 1)),
        }
    }
    calibration.checks.push(Check::at_most(
        "odometry.failed_match_share",
        share,
        MAX_FAILED_MATCH_SHARE,
        format!(
            "{} of {attempted} intervals' scans could not be matched{}; they are left out, and \
             many mean the room does not fix the lidar's motion for much of the drive",
            failed.len(),
            if kinds.is_empty() {
                String::new()
            } else {
                format!(
                    " ({})",
                    kinds
                        .iter()
                        .map(|(k, n)| format!("{n} {k}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        ),
    ));
    notes.push(format!(
        "{revolutions} lidar revolutions, intervals of {} s: {} matched, {} failed to match, \
         {still} standing still, {gaps} longer than {MAX_INTERVAL_S} s or outside the \
         odometry, {sparse} with fewer than {MIN_SCAN_POINTS} readings",
        options.interval_s,
        intervals.len(),
        failed.len()
    ));
    notes.push(format!(
        "wheel speeds from the encoders' travel over the nominal radius {nominal_radius:.4} m; \
         the radii are that radius times each wheel's scale"
    ));
    calibration.notes.splice(0..0, notes);
    Ok(calibration)
}

/// One interval's outcome.
enum Outcome {
    Matched(Interval),
    Still,
    Gap,
    Sparse,
    Failed(MatchFailure),
}

/// One revolution, de-skewed to its middle instant.
struct Revolution {
    t_s: f64,
    scan: Scan,
}

/// The robot's dead-reckoned path with the nominal geometry: each odometry row's pose, for the
/// scan matcher's guesses and the de-skewing within a revolution.
struct Path<'a> {
    odometry: &'a [OdometrySample],
    poses: TimedPath,
}

impl<'a> Path<'a> {
    fn new(odometry: &'a [OdometrySample], wheel_base_m: f64) -> Self {
        let mut poses = TimedPath::with_capacity(odometry.len());
        let mut pose = Pose::default();
        let mut last = (odometry[0].left_m, odometry[0].right_m);
        for o in odometry {
            pose = pose.drive(o.left_m - last.0, o.right_m - last.1, wheel_base_m);
            last = (o.left_m, o.right_m);
            poses.push(o.t_s, pose);
        }
        Self { odometry, poses }
    }

    fn pose_at(&self, t: f64) -> Option<Pose> {
        self.poses.pose_with(t, Ends::Within)
    }

    /// The wheels' turns from `from` to `to`, step by step between the encoders' readings,
    /// each travel over its nominal radius.
    fn wheel_turns(&self, from: f64, to: f64, nominal: &Geometry) -> Option<Vec<[f64; 2]>> {
        let mut last = self.travel_at(from)?;
        let end = self.travel_at(to)?;
        let o = self.odometry;
        let inside = o.partition_point(|s| s.t_s <= from)..o.partition_point(|s| s.t_s < to);
        // Rows out of time order make no interval (the reader refuses them; a caller's may not).
        if inside.start > inside.end {
            return None;
        }
        let mut turns = Vec::with_capacity(inside.len() + 1);
        for s in &o[inside] {
            let here = (s.left_m, s.right_m);
            turns.push([
                (here.0 - last.0) / nominal.left_radius_m,
                (here.1 - last.1) / nominal.right_radius_m,
            ]);
            last = here;
        }
        turns.push([
            (end.0 - last.0) / nominal.left_radius_m,
            (end.1 - last.1) / nominal.right_radius_m,
        ]);
        Some(turns)
    }

    /// The wheels' travel at `t`, interpolated as the pose is; `None` outside the odometry's
    /// span.
    fn travel_at(&self, t: f64) -> Option<(f64, f64)> {
        let o = self.odometry;
        Some(match self.poses.locate(t, Ends::Within)? {
            Place::Between(i, u) => (
                o[i].left_m + (o[i + 1].left_m - o[i].left_m) * u,
                o[i].right_m + (o[i + 1].right_m - o[i].right_m) * u,
            ),
            Place::At(i) => (o[i].left_m, o[i].right_m),
        })
    }
}

/// The lidar's motion from `from` to `to` on the dead-reckoned path, in its own frame at `from`.
fn lidar_motion(path: &Path, nominal: &Geometry, from: f64, to: f64) -> Option<[f64; 3]> {
    let robot = path.pose_at(to)?.relative_to(&path.pose_at(from)?);
    Some(nominal.lidar_motion([robot.x, robot.y, robot.yaw]))
}

/// The recording's revolutions, each de-skewed to its middle instant along the dead-reckoned
/// path: a revolution of the XV-11 takes 0.2 s, over which a robot at 0.3 m/s moves 6 cm.
fn revolutions(
    read: &Readings,
    path: &Path,
    nominal: &Geometry,
    latency_s: f64,
    deskew: bool,
) -> Vec<Revolution> {
    let lidar = read.lidar;
    let mut out = Vec::new();
    let mut start = 0;
    while start < lidar.len() {
        let rev = lidar[start].rev;
        let end = start + lidar[start..].iter().take_while(|s| s.rev == rev).count();
        let readings: Vec<&LidarSample> = lidar[start..end]
            .iter()
            .filter(|s| !s.invalid && s.range_m > 0.0 && s.range_m.is_finite() && s.t_s.is_finite())
            .collect();
        start = end;
        if readings.is_empty() {
            continue;
        }
        let (first, last) = (readings[0].t_s, readings[readings.len() - 1].t_s);
        let t_s = (first + last) / 2.0;
        let skewed = deskew && last > first;
        let points = readings
            .iter()
            .map(|s| {
                let (sin, cos) = s.angle_deg.to_radians().sin_cos();
                let range = read.inverse.map_or(s.range_m, |i| i.distance(s.range_m));
                let p = [range * cos, range * sin];
                if !skewed {
                    return p;
                }
                match lidar_motion(path, nominal, t_s - latency_s, s.t_s - latency_s) {
                    Some([x, y, yaw]) => Pose::new(x, y, yaw).transform(p),
                    None => p,
                }
            })
            .collect();
        out.push(Revolution {
            t_s,
            scan: Scan { points },
        });
    }
    out
}

/// The lidar's readings and the inverse of its range model, when one is given.
struct Readings<'a> {
    lidar: &'a [LidarSample],
    inverse: Option<&'a Inverse>,
}

/// Most turning intervals the revolution-at-once test matches both ways: 30.
const TIMING_TEST_INTERVALS: usize = 30;

/// Whether the scans of turning intervals match better undistorted than de-skewed: the median
/// point-to-line residual of up to 30 of them, matched both ways. A turn at 60°/s bends a scan
/// by 12° over an XV-11's revolution; de-skewing the scans of a unit that takes a revolution at
/// once bends them by that much, and leaving a real unit's undistorted leaves them bent: on the
/// simulator's drives the wrong way's median residual is 10–30 % larger.
fn takes_revolution_at_once(
    read: &Readings,
    pairs: &[(usize, usize)],
    deskewed: &[Revolution],
    path: &Path,
    nominal: &Geometry,
    matching: &MatchOptions,
    latency_s: f64,
) -> bool {
    // Intervals whose revolutions turn by more than 10° each by the encoders.
    let turning: Vec<(usize, usize)> = pairs
        .iter()
        .copied()
        .filter(|&(a, b)| {
            let span = (deskewed[b].t_s - deskewed[a].t_s).max(1e-9);
            lidar_motion(
                path,
                nominal,
                deskewed[a].t_s - latency_s,
                deskewed[b].t_s - latency_s,
            )
            .is_some_and(|m| m[2].abs() / span > 10f64.to_radians() / 0.2)
        })
        .take(TIMING_TEST_INTERVALS)
        .collect();
    if turning.len() < 5 {
        return false;
    }
    let raw = revolutions(read, path, nominal, latency_s, false);
    if raw.len() != deskewed.len() {
        return false;
    }
    let residual = |scans: &[Revolution], a: usize, b: usize| -> Option<f64> {
        let (from, to) = (scans[a].t_s - latency_s, scans[b].t_s - latency_s);
        let guess = lidar_motion(path, nominal, from, to)?;
        match_scans(&scans[a].scan, &scans[b].scan, guess, matching)
            .ok()
            .map(|m| m.rms_residual_m)
    };
    // Each interval matched both ways: the same scans, so their residuals differ by the
    // distortion alone. A paired t-test of the log-ratios: undistorted must be better beyond
    // chance, for the physics of a real unit (each reading at its own instant) is the default.
    let log_ratios: Vec<f64> = turning
        .par_iter()
        .filter_map(|&(a, b)| {
            let (r, d) = (residual(&raw, a, b)?, residual(deskewed, a, b)?);
            (r > 0.0 && d > 0.0).then(|| (r / d).ln())
        })
        .collect();
    let n = log_ratios.len();
    if n < 8 {
        return false;
    }
    let mean = log_ratios.iter().sum::<f64>() / n as f64;
    let var = log_ratios.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    let t = mean / (var / n as f64).sqrt();
    t < -AT_ONCE_T
}

/// The paired t statistic below which the undistorted scans win: −1.5. On the simulator's
/// drives a unit that takes each revolution at once gives −2 to −5 and one that reads as it
/// turns +2 to +6; the margin keeps a real unit from being taken for a snapshot by chance.
const AT_ONCE_T: f64 = 1.5;

/// The interval from revolution `a` to `b`, the lidar's stamps `latency_s` late.
fn interval(
    a: &Revolution,
    b: &Revolution,
    path: &Path,
    nominal: &Geometry,
    matching: &MatchOptions,
    latency_s: f64,
) -> Outcome {
    let (from, to) = (a.t_s - latency_s, b.t_s - latency_s);
    let duration_s = b.t_s - a.t_s;
    if !(duration_s > 0.0 && duration_s <= MAX_INTERVAL_S) {
        return Outcome::Gap;
    }
    let Some(wheel_turns_rad) = path.wheel_turns(from, to, nominal) else {
        return Outcome::Gap;
    };
    let [left, right] = wheel_turns_rad
        .iter()
        .fold([0.0, 0.0], |[l, r], [x, y]| [l + x, r + y]);
    if (left * nominal.left_radius_m).abs() < STILL_M
        && (right * nominal.right_radius_m).abs() < STILL_M
    {
        return Outcome::Still;
    }
    if a.scan.points.len() < MIN_SCAN_POINTS || b.scan.points.len() < MIN_SCAN_POINTS {
        return Outcome::Sparse;
    }
    let Some(guess) = lidar_motion(path, nominal, from, to) else {
        return Outcome::Gap;
    };
    match match_scans(&a.scan, &b.scan, guess, matching) {
        Ok(m) => Outcome::Matched(Interval {
            wheel_turns_rad,
            lidar_motion: m.motion,
        }),
        Err(f) => Outcome::Failed(f),
    }
}

/// The latency at which the wheels' turns over each interval best explain its scan-matched
/// turn `θ = J₂₁ Δφ_L + J₂₂ Δφ_R` (the closed form's first step, refitted at each candidate):
/// the least trimmed mean square on a 10 ms grid over ±[`MAX_LIDAR_LATENCY_S`], refined by a
/// parabola. `turns` holds each matched interval's stamps and scan-matched turn. `None` with
/// fewer than 12 intervals or a drive that never turns.
fn estimate_latency(
    turns: &[([f64; 2], f64)],
    path: &Path,
    nominal: &Geometry,
) -> Option<LatencyEstimate> {
    if turns.len() < 12 {
        return None;
    }
    let steps = (MAX_LIDAR_LATENCY_S / LATENCY_STEP_S).round() as i64;
    // Each candidate's trimmed mean square and the number of intervals it kept.
    let profile: Vec<(f64, f64, usize)> = (-steps..=steps)
        .into_par_iter()
        .filter_map(|k| {
            let latency = k as f64 * LATENCY_STEP_S;
            let rows: Vec<([f64; 2], f64)> = turns
                .iter()
                .filter_map(|&([a, b], theta)| {
                    let w = path.wheel_turns(a - latency, b - latency, nominal)?;
                    let total = w.iter().fold([0.0, 0.0], |[l, r], [x, y]| [l + x, r + y]);
                    Some((total, theta))
                })
                .collect();
            // The ends of the log fall outside the odometry at large latencies: a candidate
            // that loses more than a tenth of the intervals is not compared.
            if rows.len() * 10 < turns.len() * 9 {
                return None;
            }
            trimmed_turn_misfit(&rows).map(|mse| (latency, mse, rows.len()))
        })
        .collect();
    let best = (0..profile.len()).min_by(|&i, &j| profile[i].1.total_cmp(&profile[j].1))?;
    let (latency, mse, n) = profile[best];
    let edge = best == 0 || best + 1 == profile.len();
    if edge {
        return Some(LatencyEstimate {
            latency_s: latency,
            sd_s: None,
            at_bound: latency.abs() >= MAX_LIDAR_LATENCY_S - LATENCY_STEP_S / 2.0,
        });
    }
    // The profile log-likelihood of the turns, −(n/2) ln(mse), as a parabola fitted by least
    // squares to the candidates within 40 ms of the best (the trimmed profile is bumpy at the
    // grid's scale): its vertex is the estimate, its curvature the information.
    let ell = |m: f64| -(n as f64) / 2.0 * m.ln();
    let window: Vec<(f64, f64)> = profile[best.saturating_sub(PARABOLA_HALF_WIDTH)
        ..(best + PARABOLA_HALF_WIDTH + 1).min(profile.len())]
        .iter()
        .map(|&(l, m, _)| (l - latency, ell(m)))
        .collect();
    let (latency_s, sd_s) = match parabola(&window) {
        Some([_, b, c]) if c < 0.0 => {
            let half = PARABOLA_HALF_WIDTH as f64 * LATENCY_STEP_S;
            let vertex = (-b / (2.0 * c)).clamp(-half, half);
            (latency + vertex, Some((-1.0 / (2.0 * c)).sqrt()))
        }
        _ => (latency, None),
    };
    let _ = mse;
    Some(LatencyEstimate {
        latency_s,
        sd_s,
        at_bound: false,
    })
}

/// Candidates each side of the best one the profile's parabola is fitted to: 4 (40 ms).
const PARABOLA_HALF_WIDTH: usize = 4;

/// The least-squares parabola `a + b x + c x²` through `points` (x, y); `None` with fewer than
/// three or a singular system.
fn parabola(points: &[(f64, f64)]) -> Option<[f64; 3]> {
    if points.len() < 3 {
        return None;
    }
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut aty = nalgebra::Vector3::<f64>::zeros();
    for &(x, y) in points {
        let row = nalgebra::Vector3::new(1.0, x, x * x);
        ata += row * row.transpose();
        aty += row * y;
    }
    let c = ata.try_inverse()? * aty;
    c.iter().all(|v| v.is_finite()).then(|| [c[0], c[1], c[2]])
}

/// The mean square of the turn residuals of `rows` (each interval's wheel turns and its
/// scan-matched turn) after the least-squares turn gains, its worst tenth left out (a match
/// gone wrong must not choose the latency).
fn trimmed_turn_misfit(rows: &[([f64; 2], f64)]) -> Option<f64> {
    let (mut ata, mut aty) = ([[0.0f64; 2]; 2], [0.0f64; 2]);
    for &([l, r], theta) in rows {
        ata[0][0] += l * l;
        ata[0][1] += l * r;
        ata[1][1] += r * r;
        aty[0] += l * theta;
        aty[1] += r * theta;
    }
    let det = ata[0][0] * ata[1][1] - ata[0][1] * ata[0][1];
    if !(det.is_finite() && det.abs() > 1e-12 * (ata[0][0] * ata[1][1]).max(1e-300)) {
        return None;
    }
    let j21 = (aty[0] * ata[1][1] - aty[1] * ata[0][1]) / det;
    let j22 = (aty[1] * ata[0][0] - aty[0] * ata[0][1]) / det;
    let mut squares: Vec<f64> = rows
        .iter()
        .map(|&([l, r], theta)| (theta - j21 * l - j22 * r).powi(2))
        .collect();
    squares.sort_by(f64::total_cmp);
    let kept = squares.len() - squares.len() / 10;
    (kept > 0).then(|| squares[..kept].iter().sum::<f64>() / kept as f64)
}
