//! The model every estimate of the method rests on: a differential drive whose wheels turn at
//! constant speeds over an interval moves along a circular arc, and the lidar, bolted on the
//! robot at `ℓ`, sees that motion as `s = ℓ⁻¹ ⊕ r ⊕ ℓ` (Censi et al. 2013, Sec. III).

use hilsim_recording::{wrap_angle, Pose};

/// The six parameters, in the order of the covariance: left and right wheel radii and the wheel
/// base (metres), then the lidar's pose on the robot (x, y metres; yaw radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// The left wheel's radius, metres.
    pub left_radius_m: f64,
    /// The right wheel's radius, metres.
    pub right_radius_m: f64,
    /// The distance between the wheels' contact points, metres.
    pub wheel_base_m: f64,
    /// The lidar's pose on the robot (x forward, y left, yaw counter-clockwise).
    pub lidar: [f64; 3],
}

/// How many parameters [`Geometry`] has.
pub const PARAMETERS: usize = 6;

impl Geometry {
    /// The parameters as a vector in the covariance's order.
    #[must_use]
    pub fn to_array(&self) -> [f64; PARAMETERS] {
        [
            self.left_radius_m,
            self.right_radius_m,
            self.wheel_base_m,
            self.lidar[0],
            self.lidar[1],
            self.lidar[2],
        ]
    }

    /// The geometry of a vector in the covariance's order.
    #[must_use]
    pub fn from_array(p: [f64; PARAMETERS]) -> Self {
        Self {
            left_radius_m: p[0],
            right_radius_m: p[1],
            wheel_base_m: p[2],
            lidar: [p[3], p[4], p[5]],
        }
    }

    /// The robot's motion over steps of wheel turns (left, right radians), each step an arc,
    /// in its own frame at the start; the turn is not wrapped.
    #[must_use]
    pub fn robot_motion(&self, wheel_turns_rad: &[[f64; 2]]) -> [f64; 3] {
        let mut pose = [0.0f64, 0.0, 0.0];
        for [left, right] in wheel_turns_rad {
            let [dx, dy, dturn] = arc(
                self.left_radius_m * left,
                self.right_radius_m * right,
                self.wheel_base_m,
            );
            let (sin, cos) = pose[2].sin_cos();
            pose = [
                pose[0] + cos * dx - sin * dy,
                pose[1] + sin * dx + cos * dy,
                pose[2] + dturn,
            ];
        }
        pose
    }

    /// The lidar's motion in its own frame at the start, when the robot moves by `robot`.
    #[must_use]
    pub fn lidar_motion(&self, robot: [f64; 3]) -> [f64; 3] {
        let mount = Pose::new(self.lidar[0], self.lidar[1], self.lidar[2]);
        let moved = Pose {
            x: robot[0],
            y: robot[1],
            yaw: robot[2],
        }
        .compose(mount.x, mount.y, mount.yaw);
        let s = moved.relative_to(&mount);
        // The turn unwrapped: an interval may turn by more than half a revolution.
        [s.x, s.y, robot[2]]
    }
}

/// The motion of a differential drive whose wheels, `wheel_base_m` apart, travel `left_m` and
/// `right_m` at a constant ratio: a circular arc (a straight line when they travel alike),
/// in the frame at its start.
#[must_use]
pub fn arc(left_m: f64, right_m: f64, wheel_base_m: f64) -> [f64; 3] {
    let forward = (left_m + right_m) / 2.0;
    let turn = (right_m - left_m) / wheel_base_m;
    let [along, across] = arc_factors(turn);
    [forward * along, forward * across, turn]
}

/// `sin θ / θ` and `(1 − cos θ) / θ`: where an arc of unit length turning by `θ` ends. Their
/// series below 10⁻⁴ rad, where the quotients lose their digits.
#[must_use]
pub fn arc_factors(turn: f64) -> [f64; 2] {
    if turn.abs() < 1e-4 {
        let t2 = turn * turn;
        [1.0 - t2 / 6.0, turn / 2.0 * (1.0 - t2 / 12.0)]
    } else {
        [turn.sin() / turn, (1.0 - turn.cos()) / turn]
    }
}

/// The observed minus the predicted lidar motion, the angle wrapped.
#[must_use]
pub fn residual(observed: [f64; 3], predicted: [f64; 3]) -> [f64; 3] {
    [
        observed[0] - predicted[0],
        observed[1] - predicted[1],
        wrap_angle(observed[2] - predicted[2]),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lidar_on_the_axle_centre_sees_the_robot_motion() {
        let g = Geometry {
            left_radius_m: 0.02,
            right_radius_m: 0.02,
            wheel_base_m: 0.09,
            lidar: [0.0, 0.0, 0.0],
        };
        let r = g.robot_motion(&[[0.5, 1.0]]);
        let s = g.lidar_motion(r);
        for k in 0..3 {
            assert!((r[k] - s[k]).abs() < 1e-15);
        }
        // Turn: (0.02 - 0.01) / 0.09 rad.
        assert!((r[2] - 0.01 / 0.09).abs() < 1e-15);
    }

    #[test]
    fn a_lidar_ahead_of_the_axle_swings_sideways_on_a_turn_in_place() {
        let g = Geometry {
            left_radius_m: 0.02,
            right_radius_m: 0.02,
            wheel_base_m: 0.1,
            lidar: [0.1, 0.0, 0.0],
        };
        // Wheels opposite: a quarter turn to the left in place.
        let quarter = std::f64::consts::FRAC_PI_2;
        let speed = quarter * 0.1 / 2.0 / 0.02;
        let s = g.lidar_motion(g.robot_motion(&[[-speed, speed]]));
        // The lidar ends at (0, 0.1) of the robot's start frame, facing +y: in its own start
        // frame at (-0.1, 0.1).
        assert!(
            (s[0] + 0.1).abs() < 1e-12 && (s[1] - 0.1).abs() < 1e-12,
            "{s:?}"
        );
        assert!((s[2] - quarter).abs() < 1e-12);
    }

    #[test]
    fn steps_of_one_arc_compose_to_that_arc() {
        let g = Geometry {
            left_radius_m: 0.021,
            right_radius_m: 0.02,
            wheel_base_m: 0.09,
            lidar: [0.0, 0.0, 0.0],
        };
        let whole = g.robot_motion(&[[3.0, 5.0]]);
        let steps = g.robot_motion(&[[1.0, 5.0 / 3.0]; 3]);
        for k in 0..3 {
            assert!((whole[k] - steps[k]).abs() < 1e-12, "{whole:?} {steps:?}");
        }
    }

    #[test]
    fn the_arc_series_meets_the_quotients() {
        // Just below the switch, the series and the quotients (which keep about 1e-12 of
        // their digits there) agree.
        let t: f64 = 0.99e-4;
        let [a, b] = arc_factors(t);
        assert!((a - t.sin() / t).abs() < 1e-12, "{a}");
        assert!((b - (1.0 - t.cos()) / t).abs() < 1e-10, "{b}");
    }
}
