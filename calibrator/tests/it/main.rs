//! The crate's integration tests, one binary (a binary per file would link the dependency tree
//! once each).

mod any_lidar;
mod em;
mod em_bad_input;
mod groundtruth;
mod landmark_checks_weak_runs;
mod landmarks_bad_input;
mod landmarks_model;
mod landmarks_recording;
mod odometry_coverage;
mod odometry_tuples;
mod scan_match;
mod smoother;
mod trained_smoothing;
mod uncertainty_coverage;
