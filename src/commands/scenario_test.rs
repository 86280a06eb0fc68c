//! `hilsim scenario test [DIR|FILE…] [--json] [--junit FILE]`: run scenario files and check
//! their assertions.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Result};
use hilsim_recording::{check_output_file, write_file_atomically};
use hilsim_scenarios::{TestResults, JUNIT_XML};
use hilsim_sim::Scenario;

use crate::cli::ScenarioTestArgs;

pub fn test(args: &ScenarioTestArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let roots = match args.paths.as_slice() {
        [] => vec![PathBuf::from("scenarios")],
        paths => paths.to_vec(),
    };
    let mut files = Vec::new();
    for root in &roots {
        files.extend(hilsim_scenarios::scenario_files(root)?);
    }
    // Validate every file before running any: bad input fails before work starts.
    let scenarios: Vec<(PathBuf, Scenario)> = files
        .into_iter()
        .map(|f| Scenario::load(&f).map(|s| (f, s)))
        .collect::<Result<_, _>>()?;
    if scenarios.is_empty() {
        let roots: Vec<String> = roots.iter().map(|p| p.display().to_string()).collect();
        bail!("{}: no scenario files (*.toml) found", roots.join(", "));
    }
    if let Some(file) = &args.junit {
        let inputs: Vec<&Path> = scenarios.iter().map(|(path, _)| path.as_path()).collect();
        check_output_file(file, JUNIT_XML, &inputs)?;
    }
    // On all cores; the reports come back in the input order.
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    let named: Vec<(String, Scenario)> = scenarios
        .into_iter()
        .map(|(path, s)| (path.display().to_string(), s))
        .collect();
    let reports = hilsim_scenarios::execute_all(&named, workers);
    let results = named
        .iter()
        .zip(reports)
        .map(|((path, _), report)| report.map(|r| (path.clone(), r)))
        .collect::<Result<Vec<_>, _>>()?;
    let results = TestResults(results);
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
