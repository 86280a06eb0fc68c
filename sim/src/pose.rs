//! A planar pose in `f64`, the unit every public interface of hilsim uses.

use std::f64::consts::{PI, TAU};

/// Position (metres) and heading (radians, counter-clockwise from the x axis).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose {
    /// x, metres.
    pub x: f64,
    /// y, metres.
    pub y: f64,
    /// Heading, radians in (-π, π].
    pub yaw: f64,
}

impl Pose {
    /// A pose; the heading is wrapped into (-π, π].
    #[must_use]
    pub fn new(x: f64, y: f64, yaw: f64) -> Self {
        Self {
            x,
            y,
            yaw: wrap_angle(yaw),
        }
    }

    /// The pose of a frame mounted at `(dx, dy, dyaw)` in this pose's frame (x forward, y left).
    #[must_use]
    pub fn compose(&self, dx: f64, dy: f64, dyaw: f64) -> Self {
        let (sin, cos) = self.yaw.sin_cos();
        Self::new(
            self.x + cos * dx - sin * dy,
            self.y + sin * dx + cos * dy,
            self.yaw + dyaw,
        )
    }

    /// Linear interpolation from `self` (u = 0) to `other` (u = 1), the heading along the
    /// shorter arc. Exact for a constant twist over a short step to first order.
    #[must_use]
    pub fn lerp(&self, other: &Pose, u: f64) -> Self {
        Self::new(
            self.x + (other.x - self.x) * u,
            self.y + (other.y - self.y) * u,
            self.yaw + wrap_angle(other.yaw - self.yaw) * u,
        )
    }
}

/// Wraps an angle into (-π, π].
#[must_use]
pub fn wrap_angle(a: f64) -> f64 {
    let w = (a + PI).rem_euclid(TAU) - PI;
    if w <= -PI {
        w + TAU
    } else {
        w
    }
}
