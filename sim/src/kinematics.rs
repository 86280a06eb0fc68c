//! The differential drive's kinematics: what the wheels did when the body moved.

use hilsim_recording::pose::{wrap_angle, Pose};

/// The wheels' cumulative travel after the robot moved from `p0` to `p1`, starting from `prev`:
/// the body's forward displacement (along the mean heading) and its turn, split onto wheels
/// `wheel_base_m` apart. The simulation's own definition of true wheel travel, bit for bit.
///
/// ```
/// use hilsim_sim::{replay::wheel_travel, Pose};
/// let spun = wheel_travel([0.0; 2], &Pose::new(0.0, 0.0, 0.0), &Pose::new(0.0, 0.0, 0.1), 0.2);
/// assert!((spun[0] + 0.01).abs() < 1e-12 && (spun[1] - 0.01).abs() < 1e-12);
/// ```
#[must_use]
pub fn wheel_travel(prev: [f64; 2], p0: &Pose, p1: &Pose, wheel_base_m: f64) -> [f64; 2] {
    let mid_yaw = p0.yaw + wrap_angle(p1.yaw - p0.yaw) / 2.0;
    let forward = (p1.x - p0.x) * mid_yaw.cos() + (p1.y - p0.y) * mid_yaw.sin();
    let turn = wrap_angle(p1.yaw - p0.yaw) * wheel_base_m / 2.0;
    [prev[0] + forward - turn, prev[1] + forward + turn]
}
