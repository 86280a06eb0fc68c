//! The robot's trajectory: poses at increasing times, interpolated linearly between them (the
//! heading along the shorter arc), as the simulator interpolates within a physics step.

use hilsim_recording::{Ends, Mount, Place, Pose, TimedPath, TruthSample};

use crate::error::MismatchError;

/// Wraps an angle into (−π, π] (the one definition, `hilsim_recording::pose`).
pub use hilsim_recording::pose::wrap_angle as wrap;

/// Poses at increasing times, held at both ends ([`Ends::HeldAtBothEnds`]).
///
/// ```
/// use hilsim_diagnose::Trajectory;
/// use hilsim_recording::{Pose, TruthSample};
/// let t = Trajectory::new(&[
///     TruthSample { t_s: 0.0, x_m: 0.0, y_m: 0.0, yaw_rad: 3.1 },
///     TruthSample { t_s: 1.0, x_m: 1.0, y_m: 0.0, yaw_rad: -3.1 },
/// ])?;
/// let mid = t.pose_at(0.5);
/// assert!((mid.x - 0.5).abs() < 1e-12);
/// assert!((mid.yaw.abs() - std::f64::consts::PI).abs() < 1e-9); // through ±π, not through 0
/// # Ok::<(), hilsim_diagnose::MismatchError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    path: TimedPath,
}

impl Trajectory {
    /// A trajectory through `samples` (time order; at least one, finite).
    ///
    /// # Errors
    /// No samples, a non-finite value, or time going backwards.
    pub fn new(samples: &[TruthSample]) -> Result<Self, MismatchError> {
        Self::from_poses(samples.iter().map(|s| {
            (
                s.t_s,
                Pose {
                    x: s.x_m,
                    y: s.y_m,
                    yaw: s.yaw_rad,
                },
            )
        }))
    }

    /// A trajectory through `(t_s, pose)` pairs, as [`Trajectory::new`].
    ///
    /// # Errors
    /// As [`Trajectory::new`].
    pub fn from_poses(poses: impl IntoIterator<Item = (f64, Pose)>) -> Result<Self, MismatchError> {
        let poses = poses.into_iter();
        let mut path = TimedPath::with_capacity(poses.size_hint().0);
        for (t_s, p) in poses {
            if ![t_s, p.x, p.y, p.yaw].iter().all(|v| v.is_finite()) {
                return Err(MismatchError::Input(format!(
                    "a pose at t = {t_s} s is not finite"
                )));
            }
            if let Some(&last) = path.times().last() {
                if t_s < last {
                    return Err(MismatchError::Input(format!(
                        "the trajectory's time goes backwards at {t_s} s"
                    )));
                }
                if t_s == last {
                    continue;
                }
            }
            path.push(t_s, p);
        }
        if path.times().is_empty() {
            return Err(MismatchError::Input("the trajectory has no poses".into()));
        }
        Ok(Self { path })
    }

    /// Its samples, as [`Trajectory::new`] takes them.
    #[must_use]
    pub fn samples(&self) -> Vec<TruthSample> {
        self.path
            .iter()
            .map(|(t_s, p)| TruthSample {
                t_s,
                x_m: p.x,
                y_m: p.y,
                yaw_rad: p.yaw,
            })
            .collect()
    }

    /// The robot's path when this one was found by placing the lidar (scan matching) through
    /// the mount `declared` while the lidar really sits at `real`: the matching placed the
    /// lidar at `pose ⊕ declared`, and the robot is where that lidar pose puts it through the
    /// real mount, `pose ⊕ declared ⊕ real⁻¹`.
    #[must_use]
    pub fn under_mount(&self, declared: &Mount, real: &Mount) -> Self {
        let path = self
            .path
            .iter()
            .map(|(t, p)| {
                let lidar = declared.in_world(&p);
                let yaw = lidar.yaw - real.yaw_rad();
                let (sin, cos) = yaw.sin_cos();
                let robot = Pose {
                    x: lidar.x - (cos * real.x_m - sin * real.y_m),
                    y: lidar.y - (sin * real.x_m + cos * real.y_m),
                    yaw: wrap(yaw),
                };
                (t, robot)
            })
            .collect();
        Self { path }
    }

    /// The robot's path when this one was found by matching scans whose stamps ran `delay_s`
    /// late: the pose the matching put at stamp t the robot had at t − `delay_s`.
    #[must_use]
    pub fn delayed(&self, delay_s: f64) -> Self {
        Self {
            path: self.path.iter().map(|(t, p)| (t - delay_s, p)).collect(),
        }
    }

    /// The span of headings the path turns through, radians: the largest minus the smallest
    /// heading along it, unwrapped (a full turn is 2π, not 0).
    #[must_use]
    pub fn heading_span_rad(&self) -> f64 {
        let mut heading = 0.0;
        let (mut lo, mut hi) = (0.0f64, 0.0f64);
        for w in self.poses().windows(2) {
            heading += wrap(w[1].yaw - w[0].yaw);
            lo = lo.min(heading);
            hi = hi.max(heading);
        }
        hi - lo
    }

    /// The sample times.
    #[must_use]
    pub fn times(&self) -> &[f64] {
        self.path.times()
    }

    /// The sample poses.
    #[must_use]
    pub fn poses(&self) -> &[Pose] {
        self.path.poses()
    }

    /// The last sample's time.
    #[must_use]
    pub fn end_s(&self) -> f64 {
        self.times()[self.path.len() - 1]
    }

    /// The index of the interval holding `t`: samples `k` and `k + 1` bracket it (clamped).
    #[must_use]
    pub fn interval(&self, t: f64) -> usize {
        self.path.interval(t)
    }

    /// The pose at `t`, interpolated (held constant beyond the ends).
    #[must_use]
    pub fn pose_at(&self, t: f64) -> Pose {
        self.path
            .pose_with(t, Ends::HeldAtBothEnds)
            .unwrap_or_default()
    }

    /// Forward speed (m/s) and turn rate (rad/s) over the interval holding `t`.
    #[must_use]
    pub fn twist_at(&self, t: f64) -> (f64, f64) {
        let (times, poses) = (self.times(), self.poses());
        if times.len() < 2 {
            return (0.0, 0.0);
        }
        let k = self.interval(t);
        let (p, q) = (poses[k], poses[k + 1]);
        let dt = times[k + 1] - times[k];
        let dyaw = wrap(q.yaw - p.yaw);
        let mid = p.yaw + dyaw / 2.0;
        let forward = (q.x - p.x) * mid.cos() + (q.y - p.y) * mid.sin();
        (forward / dt, dyaw / dt)
    }

    /// The wheels' cumulative travel (left, right) at each sample, from zero at the first, for
    /// wheels `wheel_base_m` apart: the body's forward displacement along the mean heading of
    /// each interval and its turn split onto the wheels (the simulator's definition).
    #[must_use]
    pub fn wheel_travel(&self, wheel_base_m: f64) -> Vec<[f64; 2]> {
        let poses = self.poses();
        let mut out = Vec::with_capacity(poses.len());
        let mut w = [0.0; 2];
        out.push(w);
        for k in 1..poses.len() {
            let (p, q) = (poses[k - 1], poses[k]);
            let dyaw = wrap(q.yaw - p.yaw);
            let mid = p.yaw + dyaw / 2.0;
            let forward = (q.x - p.x) * mid.cos() + (q.y - p.y) * mid.sin();
            let turn = dyaw * wheel_base_m / 2.0;
            w = [w[0] + forward - turn, w[1] + forward + turn];
            out.push(w);
        }
        out
    }

    /// `travel` (one value per sample) interpolated at `t`, as [`Trajectory::pose_at`].
    #[must_use]
    pub fn interpolate(&self, travel: &[[f64; 2]], t: f64) -> [f64; 2] {
        match self.path.locate(t, Ends::HeldAtBothEnds) {
            Some(Place::Between(k, u)) => [
                travel[k][0] + (travel[k + 1][0] - travel[k][0]) * u,
                travel[k][1] + (travel[k + 1][1] - travel[k][1]) * u,
            ],
            Some(Place::At(k)) => travel[k],
            None => travel[0],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A path matched from scans stamped late is put back by the delay: the pose found at
    /// stamp t is the robot's at t − delay.
    #[test]
    fn a_delayed_path_runs_early_by_the_delay() {
        let sample = |t_s: f64, x_m: f64| TruthSample {
            t_s,
            x_m,
            y_m: 0.0,
            yaw_rad: 0.0,
        };
        let path = Trajectory::new(&[sample(0.0, 0.0), sample(1.0, 1.0)]).unwrap();
        let delayed = path.delayed(0.25);
        assert_eq!(delayed.times(), &[-0.25, 0.75]);
        assert_eq!(delayed.poses(), path.poses());
        assert!((delayed.pose_at(0.25).x - 0.5).abs() < 1e-12);
    }

    #[test]
    fn a_path_under_another_mount_keeps_the_lidar_where_the_matching_placed_it() {
        let path = Trajectory::new(&[
            TruthSample {
                t_s: 0.0,
                x_m: 1.0,
                y_m: 2.0,
                yaw_rad: 0.3,
            },
            TruthSample {
                t_s: 1.0,
                x_m: 1.2,
                y_m: 2.1,
                yaw_rad: 1.9,
            },
            TruthSample {
                t_s: 2.0,
                x_m: 0.9,
                y_m: 2.4,
                yaw_rad: -3.0,
            },
        ])
        .unwrap();
        let declared = Mount {
            x_m: 0.05,
            y_m: 0.0,
            yaw_deg: 0.0,
        };
        let real = Mount {
            x_m: 0.03,
            y_m: -0.02,
            yaw_deg: 2.0,
        };
        let moved = path.under_mount(&declared, &real);
        for (p, q) in path.poses().iter().zip(moved.poses()) {
            let (a, b) = (declared.in_world(p), real.in_world(q));
            assert!(
                (a.x - b.x).abs() < 1e-12 && (a.y - b.y).abs() < 1e-12,
                "{a:?} {b:?}"
            );
            assert!(wrap(a.yaw - b.yaw).abs() < 1e-12, "{a:?} {b:?}");
            // The robot itself moved: by the mounts' difference, turned with it.
            assert!((p.x - q.x).hypot(p.y - q.y) > 0.01);
        }
        assert_eq!(moved.times(), path.times());
        // 0.3 → 1.9 → −3.0 (through ±π): 1.6 then 1.38 rad further, unwrapped.
        let span = path.heading_span_rad();
        assert!(
            (span - (1.6 + (2.0 * std::f64::consts::PI - 4.9))).abs() < 1e-12,
            "{span}"
        );
        // Through the declared mount itself, nothing moves.
        let same = path.under_mount(&declared, &declared);
        for (p, q) in path.poses().iter().zip(same.poses()) {
            assert!((p.x - q.x).abs() < 1e-12 && (p.y - q.y).abs() < 1e-12);
            assert!(wrap(p.yaw - q.yaw).abs() < 1e-12);
        }
    }
}
