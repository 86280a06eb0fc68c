//! The crate's integration tests, one binary (a binary per file would link the dependency tree
//! once each).

mod carmen;
mod coreslam;
mod text;
