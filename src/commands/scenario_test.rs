//! `hilsim scenario test [DIR|FILE…] [--json] [--junit FILE]`: run scenario files and check
//! their assertions.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Result;
use hilsim_recording::{check_output_file, write_file_atomically};
use hilsim_scenarios::{TestResults, JUNIT_XML};

use crate::cli::ScenarioTestArgs;

pub fn test(args: &ScenarioTestArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let roots = match args.paths.as_slice() {
        [] => vec![PathBuf::from("scenarios")],
        paths => paths.to_vec(),
    };
    // Every file validated before any runs: bad input fails before work starts.
    let scenarios = hilsim_scenarios::load_scenarios(&roots)?;
    if let Some(file) = &args.junit {
        let inputs: Vec<&Path> = scenarios.iter().map(|(path, _)| path.as_path()).collect();
        check_output_file(file, JUNIT_XML, &inputs)?;
    }
    // On all cores; the reports come back in the input order.
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    let results = TestResults::execute(scenarios, workers)?;
    if let Some(file) = &args.junit {
        write_file_atomically(file, results.junit().as_bytes())?;
    }
    if args.json {
        writeln!(out, "{}", results.to_json())?;
    } else {
        results.write_text(out)?;
    }
    Ok(super::exit_code(results.failed() == 0))
}
