//! Planar poses of the robot and the lidar in the frame of the robot's pose at the start of the
//! recording (x forward, y left), the frame every landmark result is given in.

use std::f64::consts::{PI, TAU};

/// A planar pose: position (metres) and heading (radians, counter-clockwise from x).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose2 {
    /// x, metres.
    pub x: f64,
    /// y, metres.
    pub y: f64,
    /// Heading, radians.
    pub yaw: f64,
}

impl Pose2 {
    /// A pose.
    #[must_use]
    pub fn new(x: f64, y: f64, yaw: f64) -> Self {
        Self { x, y, yaw }
    }

    /// The pose of a frame mounted at `(dx, dy, dyaw)` in this pose's frame.
    #[must_use]
    pub fn compose(&self, dx: f64, dy: f64, dyaw: f64) -> Self {
        let (s, c) = self.yaw.sin_cos();
        Self::new(
            self.x + c * dx - s * dy,
            self.y + s * dx + c * dy,
            self.yaw + dyaw,
        )
    }

    /// This pose expressed in the frame of `origin` (the inverse of [`Pose2::compose`]).
    #[must_use]
    pub fn relative_to(&self, origin: &Pose2) -> Self {
        let (s, c) = origin.yaw.sin_cos();
        let (dx, dy) = (self.x - origin.x, self.y - origin.y);
        Self::new(
            c * dx + s * dy,
            -s * dx + c * dy,
            wrap(self.yaw - origin.yaw),
        )
    }

    /// A point given in this pose's frame, expressed in the parent frame.
    #[must_use]
    pub fn transform(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.yaw.sin_cos();
        [self.x + c * p[0] - s * p[1], self.y + s * p[0] + c * p[1]]
    }

    /// A point given in the parent frame, expressed in this pose's frame.
    #[must_use]
    pub fn inverse_transform(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.yaw.sin_cos();
        let (dx, dy) = (p[0] - self.x, p[1] - self.y);
        [c * dx + s * dy, -s * dx + c * dy]
    }
}

/// Wraps an angle into (-π, π].
#[must_use]
pub fn wrap(a: f64) -> f64 {
    let w = (a + PI).rem_euclid(TAU) - PI;
    if w <= -PI {
        w + TAU
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_to_inverts_compose() {
        let origin = Pose2::new(1.0, -2.0, 0.7);
        let p = origin.compose(0.3, 0.4, -0.2);
        let back = p.relative_to(&origin);
        assert!((back.x - 0.3).abs() < 1e-12);
        assert!((back.y - 0.4).abs() < 1e-12);
        assert!((back.yaw + 0.2).abs() < 1e-12);
        let q = origin.transform([0.5, 0.1]);
        let r = origin.inverse_transform(q);
        assert!((r[0] - 0.5).abs() < 1e-12 && (r[1] - 0.1).abs() < 1e-12);
    }

    #[test]
    fn wrap_stays_in_half_open_interval() {
        assert!((wrap(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap(-PI) - PI).abs() < 1e-12);
        assert!((wrap(0.1 - TAU) - 0.1).abs() < 1e-12);
    }
}
