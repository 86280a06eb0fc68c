//! One interval of the drive as the estimate reads it: the wheels' turns over it, step by step
//! as the encoders reported them, and the lidar's scan-matched motion over it.
//!
//! The paper's tuples carry each wheel's mean speed over an interval, a single step: the robot
//! moves along one arc. A recording has the encoders' readings within the interval too, and the
//! robot's motion is then the arcs of each step composed, which holds when the wheels speed up,
//! brake or change from driving to turning within the interval. The closed form carries over:
//! each step's turn is still linear in the wheels' turns, and the whole translation linear in
//! the wheel base once the turn gains are known.

use super::tuples::Tuple;

/// One interval of the drive.
#[derive(Debug, Clone, PartialEq)]
pub struct Interval {
    /// Each step's wheel turns (left, right), radians, in order.
    pub wheel_turns_rad: Vec<[f64; 2]>,
    /// The lidar's displacement over the interval in its own frame at the start (x, y metres,
    /// θ radians), from scan matching.
    pub lidar_motion: [f64; 3],
}

impl Interval {
    /// Each wheel's whole turn over the interval, radians.
    #[must_use]
    pub fn total_turns_rad(&self) -> [f64; 2] {
        self.wheel_turns_rad
            .iter()
            .fold([0.0, 0.0], |[l, r], [a, b]| [l + a, r + b])
    }
}

impl From<&Tuple> for Interval {
    fn from(t: &Tuple) -> Self {
        Self {
            wheel_turns_rad: vec![[t.left_rad_s * t.duration_s, t.right_rad_s * t.duration_s]],
            lidar_motion: t.lidar_motion,
        }
    }
}
