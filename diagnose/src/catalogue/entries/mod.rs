//! The catalogue's entries, one file each: each a unit value (the latency's one per sensor)
//! implementing [`super::Entry`], with its parameters' ranges and their sources.

mod drive_motor_lag;
mod drive_wheel_base;
mod lidar_dropout;
mod lidar_incidence_angle;
mod lidar_mixed_pixels;
mod lidar_motion_skew;
mod lidar_mount_offset;
mod lidar_range_bias;
mod lidar_reflectivity;
mod lidar_warmup_drift;
mod odometer_wheel_radius;
mod odometer_wheel_slip;
mod sensor_latency;
mod sonar_beam_width;
mod sonar_range_bias;
mod sonar_speed_of_sound;

pub(crate) use drive_motor_lag::DriveMotorLag;
pub(crate) use drive_wheel_base::DriveWheelBase;
pub(crate) use lidar_dropout::LidarDropout;
pub(crate) use lidar_incidence_angle::LidarIncidenceAngle;
pub(crate) use lidar_mixed_pixels::LidarMixedPixels;
pub(crate) use lidar_motion_skew::LidarMotionSkew;
pub(crate) use lidar_mount_offset::{mounted, LidarMountOffset, MOUNT_YAW_RESOLUTION_DEG};
pub(crate) use lidar_range_bias::{range_bias, LidarRangeBias};
pub(crate) use lidar_reflectivity::{LidarReflectivity, REFERENCE_REFLECTIVITY};
pub(crate) use lidar_warmup_drift::LidarWarmupDrift;
pub(crate) use odometer_wheel_radius::OdometerWheelRadius;
pub(crate) use odometer_wheel_slip::OdometerWheelSlip;
pub(crate) use sensor_latency::SensorLatency;
pub(crate) use sonar_beam_width::SonarBeamWidth;
pub(crate) use sonar_range_bias::SonarRangeBias;
pub(crate) use sonar_speed_of_sound::SonarSpeedOfSound;
