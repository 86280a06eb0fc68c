//! Draws a scenario's world as a map_server map (YAML and PGM), as a SLAM map of the room would
//! hold it, optionally with every shape moved outward:
//!
//! ```text
//! cargo run --release -p hilsim-twin --example map_of_scenario -- SCENARIO RESOLUTION_M OFFSET_M OUT.yaml
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scenario, resolution, offset, out] = args.as_slice() else {
        eprintln!("usage: map_of_scenario SCENARIO RESOLUTION_M OFFSET_M OUT.yaml");
        return ExitCode::from(2);
    };
    let run = || -> Result<(), String> {
        let scenario =
            hilsim_sim::Scenario::load(&PathBuf::from(scenario)).map_err(|e| e.to_string())?;
        let number = |s: &str| {
            s.parse::<f64>()
                .map_err(|_| format!("`{s}` is not a number"))
        };
        let map = hilsim_twin::map_of_world(&scenario, number(resolution)?, number(offset)?)
            .map_err(|e| e.to_string())?;
        map.write(&PathBuf::from(out)).map_err(|e| e.to_string())
    };
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("map_of_scenario: {e}");
            ExitCode::from(2)
        }
    }
}
