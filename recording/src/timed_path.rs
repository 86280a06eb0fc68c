//! A robot's path as poses at times (a recording's truth, a dead-reckoned or estimated path),
//! and the pose at any instant: between two samples position linearly, heading along the shorter
//! arc ([`Pose::lerp`]).
//!
//! Its users differ in what they want at and beyond the span's ends, so that is a choice,
//! [`Ends`], made at each lookup; [`TimedPath::pose_at`] is the common one.

use crate::pose::Pose;
use crate::samples::TruthSample;

/// Poses at times that never decrease (two samples may share a time).
///
/// ```
/// use hilsim_recording::{Ends, Pose, TimedPath};
/// let path: TimedPath = [(0.0, Pose::new(0.0, 0.0, 3.1)), (1.0, Pose::new(1.0, 0.0, -3.1))]
///     .into_iter()
///     .collect();
/// let mid = path.pose_at(0.5).unwrap();
/// assert!((mid.x - 0.5).abs() < 1e-12);
/// assert!((mid.yaw.abs() - std::f64::consts::PI).abs() < 1e-9); // through ±π, not through 0
/// assert_eq!(path.pose_at(9.0), Some(Pose::new(1.0, 0.0, -3.1))); // held at the end
/// assert_eq!(path.pose_with(9.0, Ends::Within), None);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TimedPath {
    times_s: Vec<f64>,
    poses: Vec<Pose>,
}

/// What a lookup gives at the ends of a path's span and beyond them. The users of a path
/// differ here, and their outputs depend on the difference: interpolating at a sample's own
/// instant (u = 0) wraps its heading and can turn a −0 into a 0, which a recorded pose is not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ends {
    /// The nearest end's pose as recorded beyond the span and at its last instant; at its first
    /// instant interpolated (from the first sample, as at every later sample's instant). An
    /// instant that is not a number: the first pose. (tf2's lookup between stamped transforms;
    /// the report's paths, a scenario's recorded path.)
    Held,
    /// The nearest end's pose as recorded beyond the span and at both its ends. An instant that
    /// is not a number: a pose of NaN. (The diagnosis's trajectory.)
    HeldAtBothEnds,
    /// Nothing beyond the span (nor at an instant that is not a number); within it, the ends
    /// included, always interpolated between two samples (of two at one time, from the later;
    /// two at the span's end, the earlier at its instant). (The odometry calibration's dead
    /// reckoning, which must not guess beyond its encoders' readings.)
    Within,
}

/// Where an instant falls on a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Place {
    /// At sample `k` itself: its pose as recorded.
    At(usize),
    /// Between samples `k` and `k + 1`, the fraction `u` of the way (in [0, 1], by time).
    Between(usize, f64),
}

impl TimedPath {
    /// An empty path.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty path with room for `n` samples.
    #[must_use]
    pub fn with_capacity(n: usize) -> Self {
        Self {
            times_s: Vec::with_capacity(n),
            poses: Vec::with_capacity(n),
        }
    }

    /// The path of a recording's `truth.csv` rows (each heading wrapped by [`Pose::new`]).
    #[must_use]
    pub fn from_truth(samples: &[TruthSample]) -> Self {
        samples
            .iter()
            .map(|s| (s.t_s, Pose::new(s.x_m, s.y_m, s.yaw_rad)))
            .collect()
    }

    /// Adds a sample at the end; `t_s` must not be before the last sample's time (the lookups
    /// assume time order; out of order they give a pose of a wrong time, never a panic).
    pub fn push(&mut self, t_s: f64, pose: Pose) {
        self.times_s.push(t_s);
        self.poses.push(pose);
    }

    /// The number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        self.poses.len()
    }

    /// Whether the path has no sample.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.poses.is_empty()
    }

    /// The sample times.
    #[must_use]
    pub fn times(&self) -> &[f64] {
        &self.times_s
    }

    /// The sample poses.
    #[must_use]
    pub fn poses(&self) -> &[Pose] {
        &self.poses
    }

    /// The first sample.
    #[must_use]
    pub fn first(&self) -> Option<(f64, Pose)> {
        Some((*self.times_s.first()?, *self.poses.first()?))
    }

    /// The samples, `(t_s, pose)`, in time order.
    pub fn iter(&self) -> impl Iterator<Item = (f64, Pose)> + '_ {
        self.times_s.iter().copied().zip(self.poses.iter().copied())
    }

    /// The index `k` of the samples `k` and `k + 1` that bracket `t`: the last sample at or
    /// before `t`, kept within `0..=len − 2` (so beyond the span, the first or last pair; 0 for
    /// a path of fewer than two samples).
    #[must_use]
    pub fn interval(&self, t: f64) -> usize {
        let n = self.times_s.len();
        if n < 2 {
            return 0;
        }
        self.times_s.partition_point(|&s| s <= t).clamp(1, n - 1) - 1
    }

    /// Where `t` falls on the path under `ends`; `None` for an empty path, or beyond the span
    /// under [`Ends::Within`].
    #[must_use]
    pub fn locate(&self, t: f64, ends: Ends) -> Option<Place> {
        let t_ = &self.times_s;
        let n = t_.len();
        if n == 0 {
            return None;
        }
        match ends {
            Ends::Held => {
                let after = t_.partition_point(|&s| s <= t);
                match (after.checked_sub(1), t_.get(after)) {
                    (Some(k), Some(&t1)) if t1 > t_[k] => {
                        Some(Place::Between(k, (t - t_[k]) / (t1 - t_[k])))
                    }
                    (Some(k), _) => Some(Place::At(k)),
                    (None, _) => Some(Place::At(0)),
                }
            }
            Ends::HeldAtBothEnds => {
                if n == 1 || t <= t_[0] {
                    return Some(Place::At(0));
                }
                if t >= t_[n - 1] {
                    return Some(Place::At(n - 1));
                }
                let k = self.interval(t);
                Some(Place::Between(k, (t - t_[k]) / (t_[k + 1] - t_[k])))
            }
            Ends::Within => {
                if !(t >= t_[0] && t <= t_[n - 1]) {
                    return None;
                }
                if n == 1 {
                    return Some(Place::At(0));
                }
                let k = self.interval(t);
                let span = t_[k + 1] - t_[k];
                let u = if span > 0.0 { (t - t_[k]) / span } else { 0.0 };
                Some(Place::Between(k, u.clamp(0.0, 1.0)))
            }
        }
    }

    /// The pose at `t`, held at the ends ([`Ends::Held`]); `None` for an empty path.
    #[must_use]
    pub fn pose_at(&self, t: f64) -> Option<Pose> {
        self.pose_with(t, Ends::Held)
    }

    /// The pose at `t` under `ends`; `None` where [`TimedPath::locate`] finds no place.
    #[must_use]
    pub fn pose_with(&self, t: f64, ends: Ends) -> Option<Pose> {
        Some(match self.locate(t, ends)? {
            Place::At(k) => self.poses[k],
            Place::Between(k, u) => self.poses[k].lerp(&self.poses[k + 1], u),
        })
    }
}

impl FromIterator<(f64, Pose)> for TimedPath {
    fn from_iter<I: IntoIterator<Item = (f64, Pose)>>(samples: I) -> Self {
        let (times_s, poses) = samples.into_iter().unzip();
        Self { times_s, poses }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path(samples: &[(f64, f64)]) -> TimedPath {
        samples
            .iter()
            .map(|&(t, x)| (t, Pose::new(x, 0.0, 0.0)))
            .collect()
    }

    #[test]
    fn each_policy_at_and_beyond_the_ends() {
        let p = path(&[(1.0, 0.0), (2.0, 1.0), (3.0, 3.0)]);
        for ends in [Ends::Held, Ends::HeldAtBothEnds, Ends::Within] {
            assert_eq!(
                p.locate(1.5, ends),
                Some(Place::Between(0, 0.5)),
                "{ends:?}"
            );
            assert_eq!(p.pose_with(2.5, ends).unwrap().x, 2.0, "{ends:?}");
        }
        assert_eq!(p.locate(0.0, Ends::Held), Some(Place::At(0)));
        assert_eq!(p.locate(1.0, Ends::Held), Some(Place::Between(0, 0.0)));
        assert_eq!(p.locate(3.0, Ends::Held), Some(Place::At(2)));
        assert_eq!(p.locate(1.0, Ends::HeldAtBothEnds), Some(Place::At(0)));
        assert_eq!(p.locate(9.0, Ends::HeldAtBothEnds), Some(Place::At(2)));
        assert_eq!(p.locate(0.5, Ends::Within), None);
        assert_eq!(p.locate(f64::NAN, Ends::Within), None);
        assert_eq!(p.locate(3.0, Ends::Within), Some(Place::Between(1, 1.0)));
        assert_eq!(TimedPath::new().pose_at(0.0), None);
    }

    #[test]
    fn samples_at_one_time() {
        let p = path(&[(0.0, 0.0), (1.0, 1.0), (1.0, 5.0), (2.0, 6.0)]);
        // Held: from the later of the two, towards the next.
        assert_eq!(p.pose_at(1.5).unwrap().x, 5.5);
        assert_eq!(p.pose_at(0.5).unwrap().x, 0.5);
        // Within: at their time, from the later.
        assert_eq!(p.locate(1.0, Ends::Within), Some(Place::Between(2, 0.0)));
        assert_eq!(p.pose_with(1.5, Ends::Within).unwrap().x, 5.5);
    }
}
