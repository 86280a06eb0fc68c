//! A sensor's pose on the robot.

use hilsim_sim::{scenario, Pose};

/// Mount pose in the robot frame (x forward, y left), yaw in radians.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Mount {
    /// Forward offset, metres.
    pub x_m: f64,
    /// Leftward offset, metres.
    pub y_m: f64,
    /// Yaw relative to the robot's forward axis, radians.
    pub yaw_rad: f64,
}

impl Mount {
    /// The sensor's pose in the world when the robot is at `robot`.
    #[must_use]
    pub fn in_world(&self, robot: &Pose) -> Pose {
        robot.compose(self.x_m, self.y_m, self.yaw_rad)
    }
}

impl From<scenario::Mount> for Mount {
    fn from(m: scenario::Mount) -> Self {
        Self {
            x_m: m.x_m,
            y_m: m.y_m,
            yaw_rad: m.yaw_deg.to_radians(),
        }
    }
}
