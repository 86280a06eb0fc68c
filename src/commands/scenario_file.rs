//! The scenario a command runs: a file, or the built-in one.

use std::path::Path;

use anyhow::Result;
use hilsim_sim::Scenario;

/// Loads a scenario file, or the built-in one, and applies a `--seed` override.
pub fn load_scenario(path: Option<&Path>, seed: Option<u64>) -> Result<Scenario> {
    let mut scenario = match path {
        Some(path) => Scenario::load(path)?,
        None => hilsim_scenarios::builtin::straight_board()?,
    };
    if let Some(seed) = seed {
        scenario.seed = seed;
    }
    Ok(scenario)
}
