//! `hilsim scenario test [DIR|FILE…]`: run scenario files and check their assertions.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use hilsim_sim::Scenario;

use crate::cli::ScenarioTestArgs;

pub fn test(args: &ScenarioTestArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let roots = if args.paths.is_empty() {
        vec![PathBuf::from("scenarios")]
    } else {
        args.paths.clone()
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
        anyhow::bail!("{}: no scenario files (*.toml) found", display(&roots));
    }
    // On all cores; the reports come back in the input order.
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    let named: Vec<(String, Scenario)> = scenarios
        .into_iter()
        .map(|(path, s)| (path.display().to_string(), s))
        .collect();
    let reports = named
        .iter()
        .zip(hilsim_scenarios::execute_all(&named, workers))
        .map(|((path, _), report)| report.map(|r| (path, r)))
        .collect::<Result<Vec<_>, _>>()?;
    let (mut passed, mut failed) = (0, 0);
    for (path, report) in &reports {
        let ok = report.passed();
        writeln!(
            out,
            "{} {} ({}, {} assertion(s))",
            if ok { "PASS" } else { "FAIL" },
            report.scenario.name,
            path,
            report.outcomes.len()
        )?;
        for o in report.outcomes.iter().filter(|o| !o.passed) {
            writeln!(out, "    {}", o.describe())?;
        }
        if ok {
            passed += 1;
        } else {
            failed += 1;
        }
    }
    writeln!(out, "{passed} passed, {failed} failed")?;
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn display(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}
