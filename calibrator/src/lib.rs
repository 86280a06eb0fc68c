//! Calibration of distance sensors from recordings (`hilsim_recording::Recording`): the
//! ground-truth-less EM calibrator with its Kalman/RTS smoother (Alhashimi, Varagnolo,
//! Gustafsson, IEEE Sensors J. 2017), the landmark calibrator (Alhashimi, Magnusson, Knorn,
//! Varagnolo, Sensors 2021) and the ground-truth baseline; and of the robot that carries them:
//! its wheels' radii, wheel base and lidar mount from an ordinary drive (Censi, Franchi,
//! Marchionni, Oriolo, IEEE T-RO 2013), on a point-to-line ICP scan matcher.
//!
//! It reads recordings only and never depends on the physics (`hilsim-sim`, rapier): a
//! calibrator that could only read simulations would be useless on a real robot's data.
#![warn(missing_docs)]

mod by_method;
pub mod calibration;
mod calibration_file;
pub mod checks;
mod describe;
pub mod em;
pub mod error;
pub mod groundtruth;
pub mod kalman_smoother;
pub mod landmarks;
pub mod odometry;
pub mod random_walk_smoother;
pub mod request;
pub mod scan_match;
mod smoothed_table;
pub mod smoothing;
pub mod stats;
pub mod target_samples;

pub use by_method::{calibrate, calibrate_with, em_options, Settings};
pub use calibration::{
    Calibration, LidarModelMetrics, Method, Metrics, OdometryModel, Sensor, SensorModel,
};
pub use error::CalibrationError;
pub use request::Request;
pub use smoothed_table::{smoothed_csv, SMOOTHED_CSV};
pub use target_samples::{SampleOptions, START_DISTANCE_RANGE_M};
