//! End-to-end tests of the `hilsim` binary: each runs the built binary in a fresh temporary
//! directory with the user's environment removed.

mod bad_input;
mod bounded_input;
mod calibrate;
mod calibrate_odometry;
mod common;
mod dataset;
mod diagnose;
mod hil;
mod import_logs;
mod import_ros1;
mod lidar_models;
mod limits;
mod outputs;
mod readme;
mod record;
mod report;
mod ros2;
mod run;
mod scenario_test;
mod serve;
mod world;
