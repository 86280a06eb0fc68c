//! The crate's integration tests, one binary (a binary per file would link the dependency tree
//! once each).

mod foreign_bags;
mod hostile_bags;
mod ros1_bags;
