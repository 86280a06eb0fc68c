//! Synthetic datasets: many seeded, varied runs of one scenario, made on all cores, resumable
//! after an interruption and split across machines with no coordination.
//!
//! A dataset is defined by its parameters ([`Params`], stored in `DIR/dataset.toml`): the base
//! scenario (its SHA-256), the seed `S`, the number of runs `N` and the varied keys. Run `r` is a
//! pure function of those and `r` alone:
//!
//! - its seed is [`run_seed`]`(S, r)` (SplitMix64);
//! - each `--vary KEY=LO..HI` draws its value from a stream of its own derived from `(S, r, KEY)`
//!   ([`draw`]), set in the parsed scenario document at the key path ([`Vary`]); the result is
//!   validated like any scenario file, and a run whose scenario is invalid is recorded as failed;
//! - its directory `DIR/run-NNNNNN/` holds the recording (`interfaces.md` format) and the run's
//!   own `scenario.toml` (seed and values in place): `hilsim record run-NNNNNN/scenario.toml`
//!   makes the same recording again, byte for byte.
//!
//! So the dataset is the same whatever the number of threads or shards ([`Shard`]: shard `I/K`
//! makes the runs with `r mod K = I − 1`), and a rerun skips what exists. `DIR/manifest.csv`
//! ([`manifest`]) has one row per run made or failed, with a content hash of the run's files
//! ([`scan_run`]); it is rebuilt from the run directories on every call, so it always agrees with
//! them. [`merge`] gathers shards into one directory.
//!
//! The crate prints nothing: progress goes to a [`Progress`] the caller implements.
#![warn(missing_docs)]

mod content;
mod dataset;
mod error;
mod generate;
pub mod layout;
mod lock;
pub mod manifest;
mod merge;
mod params;
mod progress;
mod seed;
mod shard;
mod text;
mod vary;

pub use content::{scan_run, RunContent};
pub use dataset::{Dataset, RunFailure, MAX_RUNS};
pub use error::Error;
pub use generate::Options;
pub use merge::{merge, MergeSummary};
pub use params::{Params, FORMAT};
pub use progress::{Plan, Progress, RunReport, Summary};
pub use seed::{draw, run_seed, MAX_SEED};
pub use shard::Shard;
pub use vary::Vary;
