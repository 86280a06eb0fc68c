//! The odometry's poses: dead-reckoned from the wheel travel as `/odom` sends them, and read
//! along at the truth's times to place `odom` in `map`.

use hilsim_recording::{DeadReckoning, OdometrySample};

use super::merge::Head;
use super::messages::{pose, twist};
use super::source::Stream;
use crate::msgs::{Pose, Twist};
use crate::Error;

/// `/odom`'s pose and velocity from the wheel travel: the pose dead-reckoned
/// ([`DeadReckoning`], the midpoint rule, which the import inverts), the velocity the body's
/// travel over the step divided by its time.
#[derive(Default)]
pub(super) struct Odometer {
    reckoning: DeadReckoning,
    last_t_s: Option<f64>,
}

impl Odometer {
    pub(super) fn step(
        &mut self,
        t_s: f64,
        left: f64,
        right: f64,
        wheel_base: f64,
    ) -> (Pose, Twist) {
        let mut velocity = Twist::default();
        let travel = self.reckoning.step(left, right, wheel_base);
        if let (Some((forward, turn)), Some(t0)) = (travel, self.last_t_s) {
            let dt = t_s - t0;
            if dt > 0.0 {
                velocity = twist(forward / dt, turn / dt);
            }
        }
        self.last_t_s = Some(t_s);
        let at = self.reckoning.pose();
        (pose(at.x, at.y, at.yaw), velocity)
    }
}

/// The odometry's poses (dead-reckoned as `/odom` sends them), read along as the truth's times
/// advance: the two rows around the latest time asked.
pub(super) struct OdometryPath<'a> {
    rows: Head<'a, OdometrySample>,
    odometer: Odometer,
    wheel_base: f64,
    /// The last row at or before the time asked, and the first after it, with their poses.
    before: Option<(f64, hilsim_recording::Pose)>,
    after: Option<(f64, hilsim_recording::Pose)>,
}

impl<'a> OdometryPath<'a> {
    pub(super) fn new(
        odometry: Stream<'a, OdometrySample>,
        wheel_base: f64,
    ) -> Result<Self, Error> {
        Ok(Self {
            rows: Head::new(odometry)?,
            odometer: Odometer::default(),
            wheel_base,
            before: None,
            after: None,
        })
    }

    /// The pose at `t_s` as tf2 interpolates between two stamped transforms: the position
    /// linearly, the yaw along the shorter way (a quaternion slerp about z), which is
    /// [`hilsim_recording::Pose::lerp`]; the first or last pose outside the rows' times. `None`
    /// without odometry. Times asked must not go backwards (the truth's rows do not).
    pub(super) fn at(&mut self, t_s: f64) -> Result<Option<hilsim_recording::Pose>, Error> {
        loop {
            if self.after.is_none() {
                let Some(o) = self.rows.take()? else { break };
                let (pose, _) = self
                    .odometer
                    .step(o.t_s, o.left_m, o.right_m, self.wheel_base);
                let (x, y) = (pose.position.x, pose.position.y);
                let pose = hilsim_recording::Pose::new(x, y, pose.orientation.yaw());
                self.after = Some((o.t_s, pose));
            }
            match self.after {
                Some((t, _)) if t <= t_s => self.before = self.after.take(),
                _ => break,
            }
        }
        Ok(match (self.before, self.after) {
            (Some((t0, p0)), Some((t1, p1))) => Some(p0.lerp(&p1, (t_s - t0) / (t1 - t0))),
            (Some((_, p)), None) | (None, Some((_, p))) => Some(p),
            (None, None) => None,
        })
    }
}
