//! The crate's integration tests, one binary (a binary per file would link the dependency tree
//! once each).

mod firmware_in_the_loop;
mod loopback;
