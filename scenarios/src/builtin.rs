//! The scenarios built into `hilsim`, for commands run without a scenario file.

use std::path::Path;

use hilsim_sim::scenario::ScenarioError;
use hilsim_sim::Scenario;

/// The default scenario: the straight-board run of the EM paper (Sec. VI).
pub const STRAIGHT_BOARD: &str = include_str!("../straight-board.toml");
/// The name errors in [`STRAIGHT_BOARD`] are reported under.
pub const STRAIGHT_BOARD_ORIGIN: &str = "<built-in straight-board>";

/// The diagnosis's self-test room.
pub const DIAGNOSE_ROOM: &str = include_str!("../diagnose-room.toml");
/// The name errors in [`DIAGNOSE_ROOM`] are reported under.
pub const DIAGNOSE_ROOM_ORIGIN: &str = "<built-in diagnose-room>";

/// The default scenario, parsed.
///
/// # Errors
/// Never for the checked-in file (the crate's tests parse it); the parser's error otherwise.
pub fn straight_board() -> Result<Scenario, ScenarioError> {
    Scenario::from_toml(STRAIGHT_BOARD, Path::new(STRAIGHT_BOARD_ORIGIN))
}

/// The scenario file at `path`, or the default scenario when none is given, its seed replaced
/// by `seed` when one is given.
///
/// # Errors
/// The file is unreadable or invalid.
pub fn load_or_default(path: Option<&Path>, seed: Option<u64>) -> Result<Scenario, ScenarioError> {
    let mut scenario = match path {
        Some(path) => Scenario::load(path)?,
        None => straight_board()?,
    };
    scenario.seed = seed.unwrap_or(scenario.seed);
    Ok(scenario)
}

/// The self-test room, parsed.
///
/// # Errors
/// Never for the checked-in file (the crate's tests parse it); the parser's error otherwise.
pub fn diagnose_room() -> Result<Scenario, ScenarioError> {
    Scenario::from_toml(DIAGNOSE_ROOM, Path::new(DIAGNOSE_ROOM_ORIGIN))
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_built_in_scenarios_parse() {
        assert_eq!(super::straight_board().unwrap().name, "straight-board");
        assert_eq!(super::diagnose_room().unwrap().name, "diagnose-room");
    }
}
