//! One module per subcommand; each validates its arguments before opening anything.

pub mod calibrate;
mod calibration_file;
pub mod dataset;
pub mod decode;
pub mod diagnose;
pub mod export;
pub mod hil;
pub mod import;
pub mod record;
pub mod report;
mod report_dir;
pub mod run;
mod scenario_file;
pub mod scenario_test;
pub mod serve;

pub use calibration_file::{read_calibration, read_calibrations};
pub use scenario_file::load_scenario;
pub mod world;
