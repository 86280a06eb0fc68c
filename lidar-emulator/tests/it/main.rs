//! The crate's integration tests, one binary (a binary per file would link the dependency tree
//! once each).

mod decoder_corruption;
mod determinism;
mod motor_speed_bounds;
mod mount_timing_wheel_effects;
mod prediction;
mod real_capture;
mod sensor_effects;
mod sensor_geometry;
mod sensor_statistics;
mod wire_roundtrip;
