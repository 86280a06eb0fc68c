//! Estimating the real trajectory when the recording has no `truth.csv`: the commands replayed
//! through the nominal drive (or, without commands, dead reckoning from the encoders), corrected
//! revolution by revolution by matching the lidar's readings to the scenario's world.
//!
//! Each revolution's correction `(dx, dy, dθ)` is added to the dead-reckoned poses within it
//! (over 0.2 s the difference between adding and composing it is far below a millimetre) and
//! found by Gauss–Newton on the readings' normalised residuals against the nominal prediction,
//! with Huber weights (k = 2) so that readings the world does not explain (people, a mixed pixel)
//! do not pull it; the Jacobian by central differences (1 mm, 1 mrad) through the physics. It
//! starts from the previous revolution's correction. The revolutions' corrections are then
//! smoothed over time (a random walk whose steps grow with the motion, RTS smoother), and
//! interpolated linearly between revolutions.
//!
//! An effect that biases the lidar is partly absorbed into these corrections; effects with a
//! shape a rigid shift cannot take (incidence, reflectivity, mixed pixels, skew while turning)
//! still show. The estimate's own uncertainty is reported, and the drive's and the encoders'
//! residuals are widened by it.

use hilsim_calibrator::random_walk_smoother::{self, Step};
use hilsim_recording::{LidarSample, Recording, TruthSample};
use nalgebra::Matrix3;
use rayon::prelude::*;

use crate::error::MismatchError;
use crate::physics::{Hypothesis, LidarQuery, Physics};
use crate::trajectory::{wrap, Trajectory};

/// Gauss–Newton iterations per revolution.
const ITERATIONS: usize = 6;
/// Readings of a revolution used (evenly thinned).
const READINGS_PER_REV: usize = 90;
/// Huber's k, in normalised residuals.
const HUBER_K: f64 = 2.0;
/// Halvings of a Gauss–Newton step tried before the revolution's match stops.
const HALVINGS: usize = 4;

/// Huber's loss of a normalised residual `r` with [`HUBER_K`].
fn huber(r: f64) -> f64 {
    crate::stats::huber(r, HUBER_K)
}

/// What an estimated trajectory follows between the lidar's corrections.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeadReckoning {
    /// The commands replayed through the nominal drive: a smooth path, independent of the
    /// encoders (so the encoders can be judged against it).
    Commands,
    /// The encoders' travel integrated from the declared start: the robot's real motion at
    /// their rate, independent of the commands (so the drive can be judged against it).
    Encoders,
    /// The scenario's own path (a twin's, built by `hilsim world` from the encoders matched to
    /// the log's scans): the encoders' motion without a long run's drift.
    DeclaredPath,
    /// Each revolution's own match and nothing else, straight between revolutions: a log with
    /// encoders but no commands is matched along the encoders (or a twin's path), and its path
    /// is then taken from the matches alone, so that the encoders can be judged against the
    /// lidar (their radii, base and slip; a lidar delay or mount through them), as Censi et al.
    /// calibrate a robot's odometry against its scan matching (IEEE T-RO 29(2), 2013).
    Scans,
}

impl DeadReckoning {
    /// In words, for the diagnosis's `references`.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Self::Commands => "lidar-estimated path (commands between scans)",
            Self::Encoders => "lidar-estimated path (encoders between scans)",
            Self::DeclaredPath => "lidar-estimated path (the scenario's path between scans)",
            Self::Scans => "lidar-estimated path (each scan's own match, straight between scans)",
        }
    }

    /// Whether the path follows the encoders between scans (their travel, or a twin's path
    /// built from it): the encoders judged against it would be judged against themselves, and
    /// the drive judged against it is independent of the commands.
    #[must_use]
    pub fn follows_the_encoders(self) -> bool {
        matches!(self, Self::Encoders | Self::DeclaredPath)
    }
}

/// The trajectory to correct, following `preferred` when the recording has it (else the
/// other), and what it followed.
fn dead_reckoning(
    physics: &dyn Physics,
    recording: &Recording,
    end_s: f64,
    preferred: DeadReckoning,
    hypothesis: &Hypothesis,
) -> Result<(Trajectory, DeadReckoning), MismatchError> {
    let d = physics.declared();
    // The commands through the nominal drive give a smooth path; the encoders' readings carry
    // their noise into every pose (2 mm per reading is ~10 mrad of heading between readings),
    // but they follow what the robot did, lag and all.
    let replay = || {
        (!recording.commands.is_empty())
            .then(|| physics.drive(&recording.commands, end_s, hypothesis))
            .filter(|r| r.len() >= 2)
    };
    let odometry = recording.odometry.as_ref().filter(|o| o.len() >= 2);
    if preferred == DeadReckoning::Commands || odometry.is_none() {
        if let Some(replay) = replay() {
            return Ok((Trajectory::new(&replay)?, DeadReckoning::Commands));
        }
    }
    let Some(odometry) = odometry else {
        if let Some(path) = declared_path(physics) {
            return Ok((path, DeadReckoning::DeclaredPath));
        }
        return Err(MismatchError::Refused(
            "the recording has no truth.csv, no commands and no odometry to follow the robot by"
                .into(),
        ));
    };
    let mut pose = d.start;
    let mut out = vec![TruthSample {
        t_s: 0.0,
        x_m: pose.x,
        y_m: pose.y,
        yaw_rad: pose.yaw,
    }];
    let mut last = odometry[0];
    for o in &odometry[1..] {
        pose = pose.drive(
            o.left_m - last.left_m,
            o.right_m - last.right_m,
            d.wheel_base_m,
        );
        if o.t_s > out[out.len() - 1].t_s {
            out.push(TruthSample {
                t_s: o.t_s,
                x_m: pose.x,
                y_m: pose.y,
                yaw_rad: pose.yaw,
            });
        }
        last = *o;
    }
    Ok((Trajectory::new(&out)?, DeadReckoning::Encoders))
}

/// `base` between `t0` and `t1` (its samples there and the interpolated ends) with
/// `correction` added to every pose.
fn shifted(base: &Trajectory, t0: f64, t1: f64, correction: [f64; 3]) -> Trajectory {
    let inside = base
        .times()
        .iter()
        .zip(base.poses())
        .filter(|(&t, _)| t > t0 && t < t1)
        .map(|(&t, &p)| (t, p));
    let samples: Vec<TruthSample> = std::iter::once((t0, base.pose_at(t0)))
        .chain(inside)
        .chain(std::iter::once((t1, base.pose_at(t1))))
        .map(|(t, p)| TruthSample {
            t_s: t,
            x_m: p.x + correction[0],
            y_m: p.y + correction[1],
            yaw_rad: wrap(p.yaw + correction[2]),
        })
        .collect();
    // The base trajectory is valid, so is its shifted piece.
    Trajectory::new(&samples).unwrap_or_else(|_| base.clone())
}

/// The normalised residuals of `readings` under the nominal prediction from `trajectory`
/// (`None` where nothing valid is predicted).
fn residuals(
    physics: &dyn Physics,
    trajectory: &Trajectory,
    queries: &[LidarQuery],
    readings: &[f64],
    hypothesis: &Hypothesis,
) -> Vec<Option<f64>> {
    physics
        .lidar_distributions(trajectory, queries, hypothesis)
        .iter()
        .zip(readings)
        .map(|(p, &y)| {
            // The component nearest the reading, in its own standard deviations (the moments
            // of what is reported valid: near a range limit, of the truncated distribution).
            p.components
                .iter()
                .map(|g| {
                    let (mean, sd) = g.moments();
                    (y - mean) / sd
                })
                .min_by(|a, b| a.abs().total_cmp(&b.abs()))
        })
        .collect()
}

/// How uncertain an estimated trajectory is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Uncertainty {
    /// Standard deviation of a position, metres.
    pub position_m: f64,
    /// Standard deviation of a heading, radians.
    pub yaw_rad: f64,
}

/// The trajectory estimated from `recording` following `preferred` between the lidar's
/// corrections, its uncertainty and what it followed, with the lidar predicted and the
/// commands replayed under `hypothesis` (the nominal model first; fitted effects when
/// re-aligning). `matched_along` is the path an earlier estimate of the same recording chose to
/// match its revolutions along ([`Estimate::matched_along`]), followed again without choosing
/// anew; `None` to choose.
///
/// # Errors
/// [`MismatchError::Refused`] without lidar readings to match.
pub(crate) fn estimate_trajectory(
    physics: &dyn Physics,
    recording: &Recording,
    end_s: f64,
    hypothesis: &Hypothesis,
    preferred: DeadReckoning,
    matched_along: Option<DeadReckoning>,
) -> Result<Estimate, MismatchError> {
    let Some(lidar) = recording.lidar.as_ref().filter(|l| !l.is_empty()) else {
        return Err(MismatchError::Refused(
            "the recording has no truth.csv and no lidar readings to estimate its trajectory with"
                .into(),
        ));
    };
    // Without commands, a path that follows the encoders would leave them nothing to be judged
    // against: the matches alone are the path then (unless the encoders' own path is asked
    // for).
    let scans_only = preferred != DeadReckoning::Encoders
        && recording.commands.is_empty()
        && recording.odometry.as_ref().is_some_and(|o| o.len() >= 2);
    let finish = |m: Matched, reckoned: DeadReckoning| -> Estimate {
        match m.scans {
            Some((trajectory, uncertainty)) if scans_only && reckoned.follows_the_encoders() => {
                Estimate {
                    trajectory,
                    uncertainty,
                    reckoned: DeadReckoning::Scans,
                    smoothed: Some(m.trajectory),
                    matched_along: reckoned,
                }
            }
            _ => Estimate {
                trajectory: m.trajectory,
                uncertainty: m.uncertainty,
                reckoned,
                smoothed: None,
                matched_along: reckoned,
            },
        }
    };
    let path = declared_path(physics);
    if let (Some(DeadReckoning::DeclaredPath), Some(path)) = (matched_along, &path) {
        let along_path = matched(physics, lidar, path, hypothesis)?;
        return Ok(finish(along_path, DeadReckoning::DeclaredPath));
    }
    let (base, reckoned) = dead_reckoning(physics, recording, end_s, preferred, hypothesis)?;
    let estimate = matched(physics, lidar, &base, hypothesis)?;
    // A twin's path is the encoders already matched to these scans by `hilsim world`: the same
    // motion without the drift that the encoders' bare integration gathers over a long run, or
    // that commands replayed on wheels of another size turn away by, faster than a revolution's
    // match follows (measured on a 75 s rover log: from the bare integration the matches lost
    // the path by metres). It is taken when it matches at least as many of the readings as the
    // encoders, and clearly more than the commands (along which the encoders stay
    // diagnosable). A twin of another run matches few of this one's. The choice is made once,
    // under the nominal model: an estimate again under fitted effects follows what it chose
    // (each choice matches every revolution, and on a log without commands the encoders'
    // integration, which loses the path, would be matched in every estimate only to be
    // dropped).
    if reckoned != DeadReckoning::DeclaredPath && matched_along.is_none() {
        if let Some(path) = &path {
            let along_path = matched(physics, lidar, path, hypothesis)?;
            let margin = match reckoned {
                DeadReckoning::Commands => LOST_TRACK_SHARE,
                _ => 0.0,
            };
            if along_path.matched_share >= estimate.matched_share + margin {
                return Ok(finish(along_path, DeadReckoning::DeclaredPath));
            }
        }
    }
    Ok(finish(estimate, reckoned))
}

/// An estimated trajectory, its uncertainty and what it followed between the lidar's matches.
#[derive(Debug, Clone)]
pub(crate) struct Estimate {
    pub trajectory: Trajectory,
    pub uncertainty: Uncertainty,
    pub reckoned: DeadReckoning,
    /// With [`DeadReckoning::Scans`], the same matches smoothed along the encoders between
    /// them (a random walk of corrections): less of each match's own noise, for what reads the
    /// path's shape over short steps (`crab.rs`).
    pub smoothed: Option<Trajectory>,
    /// What the revolutions were matched along: the commands' replay, the encoders' travel or
    /// the scenario's path.
    pub matched_along: DeadReckoning,
}

/// How many more of the readings (within Huber's k of their prediction at the match) a twin's
/// path must match than the commands' replay for the estimate to follow the path: a tenth.
/// Measured on a room run without truth: on wheels 2 % long and 1 % short the replay matched
/// 97 % and the path 99 % (the replay kept, the wheels named within 0.3 %); on wheels 6 % long
/// and 4 % short the replay matched 76 % and the path 99 %, and along the replay a lidar mount
/// at its search's bound was named.
const LOST_TRACK_SHARE: f64 = 0.1;

/// A trajectory estimated by matching the lidar's revolutions along `base`.
struct Matched {
    trajectory: Trajectory,
    uncertainty: Uncertainty,
    /// The share of the matched readings within Huber's k of their prediction at the match.
    matched_share: f64,
    /// The revolutions' own matches, unsmoothed, straight between revolutions, with their
    /// uncertainty ([`DeadReckoning::Scans`]); `None` with fewer than two.
    scans: Option<(Trajectory, Uncertainty)>,
}

/// `base` corrected revolution by revolution by matching `lidar` to the world.
fn matched(
    physics: &dyn Physics,
    lidar: &[LidarSample],
    base: &Trajectory,
    hypothesis: &Hypothesis,
) -> Result<Matched, MismatchError> {
    let declared = physics.declared().lidar;
    let matcher = Matcher {
        physics,
        base,
        hypothesis,
        period: declared.map_or(1.0 / 1800.0, |l| 60.0 / (l.rpm * 360.0)),
        snapshot: declared.is_some_and(|l| l.snapshot),
        ranges: declared.map_or(0.0..=f64::INFINITY, |l| l.min_range_m..=l.max_range_m),
    };
    let revs = revolutions(lidar);
    let mut knots: Vec<Knot> = Vec::with_capacity(revs.len());
    let mut variances = Vec::new();
    let mut correction = [0.0; 3];
    let (mut near, mut used) = (0_usize, 0_usize);
    // The stamps each knot's readings span: its geometry is theirs throughout (a lidar that
    // takes it at one instant, that instant).
    let mut extents = Vec::with_capacity(revs.len());
    for rows in &revs {
        if let Some((knot, variance, fit)) = matcher.revolution(rows, &mut correction) {
            extents.push(match (matcher.snapshot, rows.first(), rows.last()) {
                (false, Some(a), Some(b)) => (a.t_s, b.t_s),
                _ => (knot.0, knot.0),
            });
            knots.push(knot);
            variances.push(variance);
            near += fit.near;
            used += fit.used;
        }
    }
    let scans = scans_only(base, &knots, &extents, &variances);
    let (knots, variances) = smooth_corrections(base, &knots, &variances);
    if knots.is_empty() {
        return Err(MismatchError::Refused(
            "the recording has no truth.csv and too few valid lidar readings to estimate its \
             trajectory"
                .into(),
        ));
    }
    let samples = corrected(base, &knots);
    Ok(Matched {
        trajectory: Trajectory::new(&samples)?,
        uncertainty: uncertainty(&variances),
        matched_share: near as f64 / used.max(1) as f64,
        scans,
    })
}

/// Poses of `base` averaged over a revolution's readings: this many, evenly through its stamps.
const REVOLUTION_SAMPLES: usize = 9;

/// The path of the revolutions' own matches: at each knot, `base` averaged over the stamps its
/// readings span (`extents`) with the knot's correction, straight between knots, and its
/// uncertainty from the matches' own variances. The correction is the one that fits the whole
/// revolution, so it is added to the revolution's mean pose of `base`, not to `base` at its
/// middle: where `base` (the encoders) changes its turn within a revolution, its pose at the
/// middle departs from that mean at the encoders' own time, which a lidar stamped later than
/// the encoders would not share.
fn scans_only(
    base: &Trajectory,
    knots: &[Knot],
    extents: &[(f64, f64)],
    variances: &[[f64; 3]],
) -> Option<(Trajectory, Uncertainty)> {
    let mean_pose = |(from, to): (f64, f64), t: f64| {
        let middle = base.pose_at(t);
        let n = REVOLUTION_SAMPLES as f64;
        let (mut x, mut y, mut turn) = (0.0, 0.0, 0.0);
        for i in 0..REVOLUTION_SAMPLES {
            let p = base.pose_at(from + (to - from) * i as f64 / (n - 1.0));
            x += p.x / n;
            y += p.y / n;
            turn += wrap(p.yaw - middle.yaw) / n;
        }
        (x, y, middle.yaw + turn)
    };
    // A knot no later than the one before (a revolution's readings stamped out of order) is
    // left out rather than the whole path.
    let mut last = f64::NEG_INFINITY;
    let samples: Vec<TruthSample> = knots
        .iter()
        .zip(extents)
        .filter(|(&(t, _), _)| {
            let later = t > last;
            last = last.max(t);
            later
        })
        .map(|(&(t, c), &extent)| {
            let (x, y, yaw) = mean_pose(extent, t);
            TruthSample {
                t_s: t,
                x_m: x + c[0],
                y_m: y + c[1],
                yaw_rad: wrap(yaw + c[2]),
            }
        })
        .collect();
    if samples.len() < 2 {
        return None;
    }
    let trajectory = Trajectory::new(&samples).ok()?;
    Some((trajectory, uncertainty(variances)))
}

/// The scenario's declared path, when it has one of two poses or more.
fn declared_path(physics: &dyn Physics) -> Option<Trajectory> {
    physics
        .declared()
        .path
        .clone()
        .filter(|p| p.times().len() >= 2)
}

/// The lidar's readings grouped by revolution, in order.
fn revolutions(lidar: &[LidarSample]) -> Vec<Vec<&LidarSample>> {
    let mut revs: Vec<(u64, Vec<&LidarSample>)> = Vec::new();
    for s in lidar {
        match revs.last_mut() {
            Some((rev, rows)) if *rev == s.rev => rows.push(s),
            _ => revs.push((s.rev, vec![s])),
        }
    }
    revs.into_iter().map(|(_, rows)| rows).collect()
}

/// A revolution whose readings sweep this far, degrees, is a full circle (the last reading of
/// a 360-reading revolution is 359° after its first).
const FULL_CIRCLE_DEG: f64 = 358.0;

/// Matches revolutions' readings to the world along the dead reckoning.
struct Matcher<'a> {
    physics: &'a dyn Physics,
    base: &'a Trajectory,
    hypothesis: &'a Hypothesis,
    /// Seconds per degree of the lidar's rotation.
    period: f64,
    /// Whether the lidar takes a revolution's geometry at one instant.
    snapshot: bool,
    /// The declared range limits, metres.
    ranges: std::ops::RangeInclusive<f64>,
}

/// How a revolution's match fits: of its readings used, how many are within Huber's k of their
/// prediction there.
struct MatchFit {
    near: usize,
    used: usize,
}

/// One revolution's readings to match: their queries, ranges and the piece of trajectory
/// (`t0`, `t1`) they need.
struct Scan {
    queries: Vec<LidarQuery>,
    y: Vec<f64>,
    t0: f64,
    t1: f64,
}

impl Matcher<'_> {
    /// One revolution's correction, refined from `correction` (which it updates), as a knot with
    /// the variances of its coordinates; `None` when it has too few valid readings or its
    /// geometry pins no coordinate (a corridor's length: it is left to the others).
    fn revolution(
        &self,
        rows: &[&LidarSample],
        correction: &mut [f64; 3],
    ) -> Option<(Knot, [f64; 3], MatchFit)> {
        let start = rows[0].t_s - rows[0].angle_deg * self.period;
        // A reading outside the declared range limits is one the model cannot predict (its
        // predictive distribution there is the sliver truncated at the limit, whose tiny spread
        // would let one such reading outweigh the rest): another lidar may report farther
        // than the scenario says (the other simulator's boards: 7.5 m against a declared 6 m).
        let valid: Vec<&&LidarSample> = rows
            .iter()
            .filter(|s| !s.invalid && s.range_m > 0.0 && self.ranges.contains(&s.range_m))
            .collect();
        if valid.len() < 12 {
            return None;
        }
        let stride = valid.len().div_ceil(READINGS_PER_REV).max(1);
        let used: Vec<&&LidarSample> = valid.into_iter().step_by(stride).collect();
        let queries: Vec<LidarQuery> = used
            .iter()
            .map(|s| LidarQuery {
                t_s: s.t_s,
                rev_start_s: start,
                angle_deg: s.angle_deg,
            })
            .collect();
        let y: Vec<f64> = used.iter().map(|s| s.range_m).collect();
        // The piece of trajectory the revolution's readings need (timestamps or its start).
        let (t0, t1) = (
            start.min(used[0].t_s) - 0.01,
            used[used.len() - 1].t_s + 0.01,
        );
        let scan = Scan { queries, y, t0, t1 };
        let mut info = [[0.0; 3]; 3];
        // The residuals at `correction`, once the last step's descent has found them.
        let mut known = None;
        for _ in 0..ITERATIONS {
            let here = known
                .take()
                .unwrap_or_else(|| self.scan_residuals(&scan, *correction));
            let (a, g) = self.normal_equations(&scan, *correction, &here);
            info = a;
            let Some(delta) = solve3(a, g) else {
                break;
            };
            // Trust region: at most 5 cm and 3° per step.
            let scale = (delta[0].hypot(delta[1]) / 0.05)
                .max(delta[2].abs() / 0.05)
                .max(1.0);
            let step = delta.map(|d| d / scale);
            let Some((next, there)) = self.descent(&scan, *correction, &here, step) else {
                break;
            };
            *correction = next;
            known = Some(there);
            if delta[0].hypot(delta[1]) < 1e-5 && delta[2].abs() < 1e-5 {
                break;
            }
        }
        // The correction holds where the readings' geometry was taken: at the revolution's
        // start for a lidar that takes it at one instant, else halfway through it: half a turn
        // after the start of a full circle, and halfway through the readings of a sweep that
        // covers less (a 240° sweep, which starts two-thirds of a turn after the angle it
        // counts from; the part of a revolution a log starts or ends in).
        let (first_s, last_s) = (rows[0].t_s, rows[rows.len() - 1].t_s);
        let knot = if self.snapshot {
            start
        } else if last_s - first_s >= FULL_CIRCLE_DEG * self.period {
            start + 0.5 * 360.0 * self.period
        } else {
            0.5 * (first_s + last_s)
        };
        let inv = invert3(info)?;
        let last = known.unwrap_or_else(|| self.scan_residuals(&scan, *correction));
        let fit = MatchFit {
            near: last.iter().flatten().filter(|r| r.abs() <= HUBER_K).count(),
            used: last.len(),
        };
        Some((
            (knot, *correction),
            [inv[(0, 0)], inv[(1, 1)], inv[(2, 2)]],
            fit,
        ))
    }

    /// The normalised residuals of `scan`'s readings with `correction` added to its piece of
    /// the dead reckoning.
    fn scan_residuals(&self, scan: &Scan, correction: [f64; 3]) -> Vec<Option<f64>> {
        residuals(
            self.physics,
            &shifted(self.base, scan.t0, scan.t1, correction),
            &scan.queries,
            &scan.y,
            self.hypothesis,
        )
    }

    /// `correction` (where the residuals are `here`) moved along `step`, halved until the move
    /// lowers the Huber loss of the readings predicted at both ends (at most [`HALVINGS`]
    /// times), with the residuals there; `None` when no such move lowers it. The nearest component of a reading's prediction switches as the pose moves
    /// (a board's edge, the wall behind it), so the loss is rugged and a Gauss–Newton step on
    /// differences taken at one point can climb it: measured on the other simulator's
    /// `board-d` run, unchecked steps slid the path 0.69 m sideways within 3 s.
    fn descent(
        &self,
        scan: &Scan,
        correction: [f64; 3],
        here: &[Option<f64>],
        step: [f64; 3],
    ) -> Option<([f64; 3], Vec<Option<f64>>)> {
        let mut size = 1.0;
        for _ in 0..=HALVINGS {
            let next = [0, 1, 2].map(|k| correction[k] + size * step[k]);
            let there = self.scan_residuals(scan, next);
            let (before, after) = here
                .iter()
                .zip(&there)
                .filter_map(|(a, b)| a.zip(*b))
                .fold((0.0, 0.0), |(sa, sb), (a, b)| {
                    (sa + huber(a), sb + huber(b))
                });
            if after < before {
                return Some((next, there));
            }
            size /= 2.0;
        }
        None
    }

    /// The Huber-weighted normal equations `J'WJ δ = −J'W r` of `scan` at `correction`, where
    /// the residuals are `r0`: the matrix `J'WJ` and the right-hand side, the Jacobian by
    /// central differences.
    fn normal_equations(
        &self,
        scan: &Scan,
        correction: [f64; 3],
        r0: &[Option<f64>],
    ) -> ([[f64; 3]; 3], [f64; 3]) {
        let residuals_at = |c: [f64; 3]| self.scan_residuals(scan, c);
        let n = scan.y.len();
        let steps = [0.001, 0.001, 0.001];
        // Central differences of the residuals along each coordinate: the six predictions
        // side by side (a revolution's few dozen readings are too few to share among the
        // threads one prediction at a time without most of the time going to handing over).
        let moved: Vec<Vec<Option<f64>>> = (0..6)
            .into_par_iter()
            .map(|j| {
                let mut c = correction;
                c[j / 2] += if j % 2 == 0 {
                    steps[j / 2]
                } else {
                    -steps[j / 2]
                };
                residuals_at(c)
            })
            .collect();
        let mut jac: Vec<[f64; 3]> = vec![[0.0; 3]; n];
        let mut usable = vec![true; n];
        for k in 0..3 {
            let (ru, rd) = (&moved[2 * k], &moved[2 * k + 1]);
            for i in 0..n {
                match (ru[i], rd[i]) {
                    (Some(a), Some(b)) => jac[i][k] = (a - b) / (2.0 * steps[k]),
                    _ => usable[i] = false,
                }
            }
        }
        // Weighted normal equations J'WJ δ = −J'W r.
        let mut a = [[0.0; 3]; 3];
        let mut g = [0.0; 3];
        for i in 0..n {
            let Some(r) = r0[i].filter(|_| usable[i]) else {
                continue;
            };
            let w = if r.abs() <= HUBER_K {
                1.0
            } else {
                HUBER_K / r.abs()
            };
            for p in 0..3 {
                g[p] -= w * jac[i][p] * r;
                for q in 0..3 {
                    a[p][q] += w * jac[i][p] * jac[i][q];
                }
            }
        }
        (a, g)
    }
}

/// Dead reckoning plus the smoothed corrections `knots`, interpolated linearly between
/// revolutions.
fn corrected(base: &Trajectory, knots: &[Knot]) -> Vec<TruthSample> {
    let at = |t: f64| -> [f64; 3] {
        let i = knots.partition_point(|k| k.0 <= t);
        match (i.checked_sub(1).map(|j| knots[j]), knots.get(i)) {
            (Some(a), Some(b)) => {
                let u = (t - a.0) / (b.0 - a.0);
                [0, 1, 2].map(|k| a.1[k] + (b.1[k] - a.1[k]) * u)
            }
            (Some(a), None) => a.1,
            (None, Some(b)) => b.1,
            (None, None) => [0.0; 3],
        }
    };
    base.times()
        .iter()
        .zip(base.poses())
        .map(|(&t, p)| {
            let c = at(t);
            TruthSample {
                t_s: t,
                x_m: p.x + c[0],
                y_m: p.y + c[1],
                yaw_rad: wrap(p.yaw + c[2]),
            }
        })
        .collect()
}

/// The estimate's uncertainty from the revolutions' smoothed variances: the median
/// revolution's standard errors, doubled (and floored at 3 mm and 1 mrad): the curvature of
/// the fits leaves out the interpolation between revolutions.
fn uncertainty(variances: &[[f64; 3]]) -> Uncertainty {
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let pos = median(variances.iter().map(|v| (v[0] + v[1]) / 2.0).collect());
    let yaw = median(variances.iter().map(|v| v[2]).collect());
    Uncertainty {
        position_m: (2.0 * pos.max(0.0).sqrt()).max(0.003),
        yaw_rad: (2.0 * yaw.max(0.0).sqrt()).max(0.001),
    }
}

/// A revolution's time and its correction `(dx, dy, dθ)`.
type Knot = (f64, [f64; 3]);

/// Drift of the dead reckoning the corrections follow, per metre travelled and per radian
/// turned: generous (5 % of the travel, 0.02 rad per metre and 5 % of the turn) so that a
/// drive that departs from its commands (a concealed motor lag, slip) is followed, not
/// smoothed over. Standing still, the correction may wander by 1 mm and 0.5 mrad per
/// revolution.
const DRIFT_PER_M: f64 = 0.05;
const YAW_DRIFT_PER_M: f64 = 0.02;
const YAW_DRIFT_PER_RAD: f64 = 0.05;
const STILL_DRIFT_M: f64 = 0.001;
const STILL_DRIFT_RAD: f64 = 0.0005;

/// The revolutions' corrections smoothed over time, with their variances: each coordinate a
/// random walk whose steps grow with the distance and the turn the dead reckoning covers
/// between two revolutions, observed by each revolution's scan match with the variance its fit
/// gives (Rauch–Tung–Striebel smoother; Shumway & Stoffer, §6.2). One revolution's match uses
/// a few dozen readings and errs by centimetres in a sparse world; while the robot stands, the
/// smoother averages every revolution of the stop.
fn smooth_corrections(
    base: &Trajectory,
    knots: &[Knot],
    variances: &[[f64; 3]],
) -> (Vec<Knot>, Vec<[f64; 3]>) {
    let n = knots.len();
    if n < 2 {
        return (knots.to_vec(), variances.to_vec());
    }
    // Process variance between knot k − 1 and k, per coordinate.
    let q: Vec<[f64; 3]> = (0..n)
        .map(|k| {
            if k == 0 {
                return [0.0; 3];
            }
            let (a, b) = (base.pose_at(knots[k - 1].0), base.pose_at(knots[k].0));
            let (dist, turn) = ((b.x - a.x).hypot(b.y - a.y), wrap(b.yaw - a.yaw).abs());
            let pos = STILL_DRIFT_M.powi(2) + (DRIFT_PER_M * dist).powi(2);
            let yaw = STILL_DRIFT_RAD.powi(2)
                + (YAW_DRIFT_PER_M * dist + YAW_DRIFT_PER_RAD * turn).powi(2);
            [pos, pos, yaw]
        })
        .collect();
    let mut out = knots.to_vec();
    let mut out_var = variances.to_vec();
    for c in 0..3 {
        let steps: Vec<Step> = (0..n)
            .map(|k| Step {
                process_variance: q[k][c],
                observed: knots[k].1[c],
                observation_variance: variances[k][c].max(1e-12),
            })
            .collect();
        // The first revolution: a diffuse prior.
        let smooth = random_walk_smoother::smooth((0.0, 1e6), &steps);
        for k in 0..n {
            out[k].1[c] = smooth[k].0;
            out_var[k][c] = smooth[k].1.max(0.0);
        }
    }
    (out, out_var)
}

/// Solves the 3×3 system `a x = b` by its inverse; `None` when singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let inv = invert3(a)?;
    Some([0, 1, 2].map(|i| (0..3).map(|j| inv[(i, j)] * b[j]).sum()))
}

/// The inverse of a 3×3 matrix; `None` when singular: its determinant not finite or at most
/// 1e-12 of its largest element cubed.
fn invert3(m: [[f64; 3]; 3]) -> Option<Matrix3<f64>> {
    let m = Matrix3::from_fn(|r, c| m[r][c]);
    let det = m.determinant();
    let scale = m.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    if !det.is_finite() || det.abs() <= 1e-12 * scale.powi(3) {
        return None;
    }
    m.try_inverse()
}
