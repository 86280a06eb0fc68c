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
        let (forward, turn) = body_travel(left_m, right_m, wheel_base_m);
        let mid = self.yaw + turn / 2.0;
        Self::new(
            self.x + forward * mid.cos(),
            self.y + forward * mid.sin(),
            self.yaw + turn,
        )
    }

    /// The wheel travel (left, right) that drives this pose to `next` ([`Pose::drive`]'s
    /// inverse): the turn is the heading's change the shorter way, the forward travel the
    /// displacement along the heading halfway through the turn, and the wheels, `wheel_base_m`
    /// apart, travel the forward travel ∓ half the turn times the wheel base. Exact for a
    /// step that [`Pose::drive`] can make (a sideways displacement is dropped).
    #[must_use]
    pub fn wheel_travel_to(&self, next: &Pose, wheel_base_m: f64) -> (f64, f64) {
        let turn = wrap_angle(next.yaw - self.yaw);
        let heading = self.yaw + 0.5 * turn;
        let forward = (next.x - self.x) * heading.cos() + (next.y - self.y) * heading.sin();
        (
            forward - 0.5 * turn * wheel_base_m,
            forward + 0.5 * turn * wheel_base_m,
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

/// How a differential drive's body moves when its wheels, `wheel_base_m` apart, travel
/// `left_m` and `right_m`: forward by their mean (metres) and turning by their difference over
/// the wheel base (radians, counter-clockwise).
#[must_use]
pub fn body_travel(left_m: f64, right_m: f64, wheel_base_m: f64) -> (f64, f64) {
    ((left_m + right_m) / 2.0, (right_m - left_m) / wheel_base_m)
}

/// A pose dead-reckoned from a differential drive's cumulative wheel travel (what its encoders
/// count): each reading's travel since the one before moves the pose by [`Pose::drive`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeadReckoning {
    /// The last reading's (left, right) travel, metres.
    last_m: Option<(f64, f64)>,
    pose: Pose,
}

impl DeadReckoning {
    /// Dead reckoning from `start`: the first reading is where the wheels' count starts.
    #[must_use]
    pub fn new(start: Pose) -> Self {
        Self {
            last_m: None,
            pose: start,
        }
    }

    /// Takes a reading of the wheels' cumulative travel and drives the pose by the travel
    /// since the last; returns the body's forward travel (metres) and turn (radians) over
    /// that step ([`body_travel`]), `None` at the first reading.
    pub fn step(&mut self, left_m: f64, right_m: f64, wheel_base_m: f64) -> Option<(f64, f64)> {
        let last = self.last_m.replace((left_m, right_m));
        let (left0, right0) = last?;
        let (dl, dr) = (left_m - left0, right_m - right0);
        self.pose = self.pose.drive(dl, dr, wheel_base_m);
        Some(body_travel(dl, dr, wheel_base_m))
    }

    /// The pose at the last reading.
    #[must_use]
    pub fn pose(&self) -> Pose {
        self.pose
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

    /// Driving by the wheel travel [`Pose::wheel_travel_to`] finds gives that travel back,
    /// for straight steps, turns on the spot and arcs either way, across the ±π seam.
    #[test]
    fn wheel_travel_inverts_driving() {
        let base = 0.23;
        for start in [
            Pose::new(0.0, 0.0, 0.0),
            Pose::new(1.5, -2.0, 3.1),
            Pose::new(-0.3, 0.7, -3.0),
        ] {
            for (left, right) in [
                (0.1, 0.1),
                (-0.05, 0.05),
                (0.02, 0.13),
                (0.3, -0.01),
                (-0.2, -0.25),
                (0.0, 0.0),
            ] {
                let next = start.drive(left, right, base);
                let (l, r) = start.wheel_travel_to(&next, base);
                assert!(
                    (l - left).abs() < 1e-12 && (r - right).abs() < 1e-12,
                    "{start:?} {left} {right}: {l} {r}"
                );
                let again = start.drive(l, r, base);
                assert!((again.x - next.x).abs() < 1e-12 && (again.y - next.y).abs() < 1e-12);
                assert!(wrap_angle(again.yaw - next.yaw).abs() < 1e-12);
            }
        }
    }

    /// Dead reckoning a run of encoder readings lands where driving each step does, and the
    /// steps it gives back are the body's travel.
    #[test]
    fn dead_reckoning_accumulates_drives() {
        let base = 0.2;
        let readings = [(1.0, 2.0), (1.1, 2.12), (1.25, 2.2), (1.25, 2.3)];
        let mut reckoning = DeadReckoning::new(Pose::new(0.5, 0.0, 1.0));
        assert_eq!(reckoning.step(1.0, 2.0, base), None);
        assert_eq!(reckoning.pose(), Pose::new(0.5, 0.0, 1.0));
        let mut pose = Pose::new(0.5, 0.0, 1.0);
        for w in readings.windows(2) {
            let (dl, dr) = (w[1].0 - w[0].0, w[1].1 - w[0].1);
            pose = pose.drive(dl, dr, base);
            let step = reckoning.step(w[1].0, w[1].1, base);
            assert_eq!(step, Some(body_travel(dl, dr, base)));
            assert_eq!(reckoning.pose(), pose);
        }
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
