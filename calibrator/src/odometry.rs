//! The wheels' radii, the wheel base and the lidar's pose on the robot, from the wheel encoders
//! and the lidar of an ordinary drive: Censi, Franchi, Marchionni, Oriolo, "Simultaneous
//! calibration of odometry and sensor parameters for mobile robots", IEEE T-RO 29(2), 2013.
//!
//! The drive is cut into intervals ([`Tuple`]s: the wheels' mean speeds and the lidar's
//! scan-matched motion); the closed form of the paper starts a maximum-likelihood estimate with
//! outliers left out, whose covariance is the Cramér–Rao bound at the estimate.

mod checks;
mod closed_form;
mod estimate;
mod from_recording;
pub mod interval;
pub mod kinematics;
mod likelihood;
pub mod tuples;

pub use estimate::{calibrate_intervals, calibrate_tuples};
pub use from_recording::{
    calibrate, drive_intervals, DriveIntervals, LatencyEstimate, RecordingOptions, MAX_INTERVAL_S,
    MAX_LIDAR_LATENCY_S, MIN_SCAN_POINTS,
};
pub use interval::Interval;
pub use kinematics::Geometry;
pub use likelihood::OUTLIER_CHI2_3;
pub use tuples::{parse_tuples, Tuple, MAX_TUPLES};
