//! A planar pose in `f64`, the unit every public interface of hilsim uses: the one pose type of
//! the world (the simulator), the recordings (`truth.csv` rows are poses) and every estimator.

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

    /// The pose after a differential drive's wheels, `wheel_base_m` apart, travel `left_m` and
    /// `right_m`: the body moves by their mean along the heading halfway through the turn
    /// (exact for a constant-curvature arc to second order in the turn).
    #[must_use]
    pub fn drive(&self, left_m: f64, right_m: f64, wheel_base_m: f64) -> Self {
        let forward = (left_m + right_m) / 2.0;
        let turn = (right_m - left_m) / wheel_base_m;
        let mid = self.yaw + turn / 2.0;
        Self::new(
            self.x + forward * mid.cos(),
            self.y + forward * mid.sin(),
            self.yaw + turn,
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

    /// This pose expressed in the frame of `origin` (the inverse of [`Pose::compose`]).
    #[must_use]
    pub fn relative_to(&self, origin: &Pose) -> Self {
        let (sin, cos) = origin.yaw.sin_cos();
        let (dx, dy) = (self.x - origin.x, self.y - origin.y);
        Self {
            x: cos * dx + sin * dy,
            y: -sin * dx + cos * dy,
            yaw: wrap_angle(self.yaw - origin.yaw),
        }
    }

    /// A point given in this pose's frame, expressed in the parent frame.
    #[must_use]
    pub fn transform(&self, p: [f64; 2]) -> [f64; 2] {
        let (sin, cos) = self.yaw.sin_cos();
        [
            self.x + cos * p[0] - sin * p[1],
            self.y + sin * p[0] + cos * p[1],
        ]
    }

    /// A point given in the parent frame, expressed in this pose's frame.
    #[must_use]
    pub fn inverse_transform(&self, p: [f64; 2]) -> [f64; 2] {
        let (sin, cos) = self.yaw.sin_cos();
        let (dx, dy) = (p[0] - self.x, p[1] - self.y);
        [cos * dx + sin * dy, -sin * dx + cos * dy]
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn driving_a_quarter_circle_ends_where_the_arc_does() {
        // Wheels 0.2 m apart on a 1 m radius arc, in 1,000 steps: the end is (1, 1), facing +y.
        let (base, radius, steps) = (0.2, 1.0, 1000);
        let angle = std::f64::consts::FRAC_PI_2 / steps as f64;
        let (left, right) = ((radius - base / 2.0) * angle, (radius + base / 2.0) * angle);
        let mut pose = Pose::new(0.0, 0.0, 0.0);
        for _ in 0..steps {
            pose = pose.drive(left, right, base);
        }
        assert!(
            (pose.x - 1.0).abs() < 1e-6 && (pose.y - 1.0).abs() < 1e-6,
            "{pose:?}"
        );
        assert!((pose.yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn relative_to_inverts_compose() {
        let origin = Pose::new(1.0, -2.0, 0.7);
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
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.1 - TAU) - 0.1).abs() < 1e-12);
    }
}
