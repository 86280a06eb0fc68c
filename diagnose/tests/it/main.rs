//! The crate's integration tests, one binary (a binary per file would link the dependency tree
//! once each).

mod catalogue;
mod dead_sensors;
mod estimated_path;
mod mismatch;
mod on_log;
mod range_shape;
mod sim_physics;
