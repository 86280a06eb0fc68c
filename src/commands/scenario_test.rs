//! `hilsim scenario test [DIR|FILE…]`: run scenario files and check their assertions.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
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
        collect(root, &mut files)?;
    }
    // Validate every file before running any: bad input fails before work starts.
    let scenarios: Vec<(PathBuf, Scenario)> = files
        .into_iter()
        .map(|f| Scenario::load(&f).map(|s| (f, s)))
        .collect::<Result<_, _>>()?;
    if scenarios.is_empty() {
        anyhow::bail!("{}: no scenario files (*.toml) found", display(&roots));
    }
    let reports = run_all(scenarios)?;
    let (mut passed, mut failed) = (0, 0);
    for (path, report) in &reports {
        let ok = report.passed();
        writeln!(
            out,
            "{} {} ({}, {} assertion(s))",
            if ok { "PASS" } else { "FAIL" },
            report.scenario.name,
            path.display(),
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

/// Runs the scenarios on all cores; results come back in the input order.
fn run_all(scenarios: Vec<(PathBuf, Scenario)>) -> Result<Vec<(PathBuf, super::run::Report)>> {
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut slots: Vec<Option<Result<super::run::Report>>> =
        (0..scenarios.len()).map(|_| None).collect();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(&mut slots);
    std::thread::scope(|scope| {
        for _ in 0..workers.min(scenarios.len()) {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some((path, scenario)) = scenarios.get(i) else {
                    break;
                };
                let report = super::run::execute(
                    scenario.clone(),
                    &path.display().to_string(),
                    crate::cli::Via::Memory,
                );
                if let Ok(mut slots) = results.lock() {
                    slots[i] = Some(report);
                }
            });
        }
    });
    scenarios
        .into_iter()
        .zip(slots)
        .map(|((path, _), report)| {
            let report =
                report.with_context(|| format!("{}: the run did not finish", path.display()))??;
            Ok((path, report))
        })
        .collect()
}

fn collect(path: &Path, files: &mut Vec<PathBuf>) -> Result<()> {
    let meta =
        std::fs::metadata(path).with_context(|| format!("{}: cannot read", path.display()))?;
    if meta.is_file() {
        files.push(path.to_path_buf());
        return Ok(());
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
        .with_context(|| format!("{}: cannot list", path.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for entry in entries {
        if entry.is_dir() {
            collect(&entry, files)?;
        } else if entry.extension().is_some_and(|e| e == "toml") {
            files.push(entry);
        }
    }
    Ok(())
}

fn display(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}
