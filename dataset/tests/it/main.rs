//! The crate's integration tests, one binary (a binary per file would link the dependency tree
//! once each).

mod common;
mod integrity;
mod manifest;
mod resume;
mod seeds_and_varies;
mod shard_merge;
