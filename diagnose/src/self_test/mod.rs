//! `hilsim diagnose --self-test N --seed S`: the proof, blind. Each trial draws an effect (or
//! none, each of the ten with probability 1/10) and its parameters from the documented moderate
//! ranges (`docs/diagnose.md`), records a "real" run of the nominal scenario with that effect
//! switched on (its own noise seed), diagnoses it against the nominal scenario without being
//! told, and scores the answer. Trial `i` is a function of (S, i) alone.

mod command;
mod conceal;
mod draw;
mod log_report;
pub mod on_log;
mod plan;
mod report;
mod run;
mod score;
mod trial;

/// The most trials a self-test runs: at roughly 10 s of CPU a trial (a 60 s recording made and
/// diagnosed), 100,000 trials are about twelve CPU-days; more is a typo, and a count is checked
/// before anything is allocated for it.
pub const MAX_TRIALS: u64 = 100_000;

pub use command::Flags;
pub use conceal::{not_concealed, Concealment, NOT_CONCEALED};
pub use draw::Drawn;
pub use draw::OUTSIDE;
pub use log_report::trial_text;
pub use plan::{Plan, Reality};
pub use run::{one, run, run_with_progress, SelfTest, TrialRun};
pub use score::{
    Score, GOAL_CORRECT, GOAL_FALSE_ALARMS, GOAL_HELDOUT_RATIO, GOAL_OUTSIDE, GOAL_PARAM_ERROR,
};
pub use trial::Outcome;
