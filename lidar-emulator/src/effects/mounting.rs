//! `lidar_mount_offset` and `sensor_latency`: where a sensor really is on the robot, and when its
//! readings are really stamped. Neither changes what a sensor measures, only where and when.

use hilsim_recording::Mount;
use hilsim_sim::scenario::LidarMountOffset;

/// The lidar's real mount: the declared one moved by `offset` in the robot's frame (x forward,
/// y left, yaw counter-clockwise). A unit bolted on a few degrees rotated turns every bearing by
/// that much; one off-centre moves every ray's origin.
#[must_use]
pub fn real_mount(declared: Mount, offset: Option<LidarMountOffset>) -> Mount {
    let Some(o) = offset else {
        return declared;
    };
    Mount {
        x_m: declared.x_m + o.x_m,
        y_m: declared.y_m + o.y_m,
        yaw_deg: declared.yaw_deg + o.yaw_deg,
    }
}

/// A reading taken at `t_s` as a driver that stamps it `latency_s` late records it (to the
/// microsecond, like every recorded time).
#[must_use]
pub fn stamped_s(t_s: f64, latency_s: f64) -> f64 {
    hilsim_sim::exact_time_s(t_s + latency_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_offset_is_the_declared_mount_and_an_offset_adds_in_the_robot_frame() {
        let declared = Mount {
            x_m: 0.1,
            y_m: 0.0,
            yaw_deg: 0.0,
        };
        assert_eq!(real_mount(declared, None), declared);
        let moved = real_mount(
            declared,
            Some(LidarMountOffset {
                yaw_deg: 3.0,
                x_m: -0.02,
                y_m: 0.01,
            }),
        );
        assert!((moved.x_m - 0.08).abs() < 1e-12 && (moved.y_m - 0.01).abs() < 1e-12);
        assert_eq!(moved.yaw_deg, 3.0);
    }

    #[test]
    fn a_stamp_is_late_by_the_latency_and_exact() {
        assert_eq!(stamped_s(1.2, 0.05), 1.25);
        assert_eq!(stamped_s(0.15, 0.0), 0.15);
    }
}
