//! The crate's integration tests, one binary (a binary per file would link the dependency tree
//! once each).

mod effects;
mod occupancy_files;
mod occupancy_rays;
mod world_physics;
