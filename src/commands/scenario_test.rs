//! `hilsim scenario test [DIR|FILE…] [--json] [--junit FILE]`: run scenario files and check
//! their assertions.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Result;
use hilsim_recording::{check_output_file, write_file_atomically, FileKind};
use hilsim_scenarios::Report;
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
    let reports = named
        .iter()
        .zip(hilsim_scenarios::execute_all(&named, workers))
        .map(|((path, _), report)| report.map(|r| (path, r)))
        .collect::<Result<Vec<_>, _>>()?;
    let failed = reports.iter().filter(|(_, r)| !r.passed()).count();
    let passed = reports.len() - failed;
    if let Some(file) = &args.junit {
        write_file_atomically(file, junit(&reports).as_bytes())?;
    }
    if args.json {
        let scenarios: Vec<serde_json::Value> = reports
            .iter()
            .map(|(path, r)| {
                serde_json::json!({
                    "scenario": r.scenario.name,
                    "path": path,
                    "passed": r.passed(),
                    "expectations": r.outcomes,
                })
            })
            .collect();
        let summary = serde_json::json!({
            "passed": passed,
            "failed": failed,
            "scenarios": scenarios,
        });
        writeln!(out, "{summary}")?;
    } else {
        for (path, report) in &reports {
            writeln!(
                out,
                "{} {} ({}, {} assertion(s))",
                if report.passed() { "PASS" } else { "FAIL" },
                hilsim_recording::printable(&report.scenario.name),
                hilsim_recording::printable(path),
                report.outcomes.len()
            )?;
            for o in report.outcomes.iter().filter(|o| !o.passed) {
                writeln!(out, "    {}", o.describe())?;
            }
        }
        writeln!(out, "{passed} passed, {failed} failed")?;
    }
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// How the JUnit file starts: the XML declaration and the suites' element with its name.
const JUNIT_START: &str =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"hilsim scenario test\"";

/// `--junit`'s file, as a previous one is recognised.
const JUNIT_XML: FileKind = FileKind {
    name: "a JUnit XML file of hilsim scenario tests",
    starts_with: JUNIT_START.as_bytes(),
};

/// JUnit XML (the Ant schema CI systems read): a `testsuite` per scenario, a `testcase` per
/// assertion, failed ones with a `failure`, skipped ones with `skipped`.
fn junit(reports: &[(&String, Report)]) -> String {
    let mut xml = String::from(JUNIT_START);
    let total: usize = reports.iter().map(|(_, r)| r.outcomes.len()).sum();
    let failures: usize = reports
        .iter()
        .map(|(_, r)| r.outcomes.iter().filter(|o| !o.passed).count())
        .sum();
    xml.push_str(&format!(" tests=\"{total}\" failures=\"{failures}\">\n"));
    for (path, report) in reports {
        let failed = report.outcomes.iter().filter(|o| !o.passed).count();
        let skipped = report
            .outcomes
            .iter()
            .filter(|o| o.skipped.is_some())
            .count();
        xml.push_str(&format!(
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{failed}\" skipped=\"{skipped}\" \
             file=\"{}\">\n",
            escape(&report.scenario.name),
            report.outcomes.len(),
            escape(path)
        ));
        for o in &report.outcomes {
            xml.push_str(&format!(
                "    <testcase classname=\"{}\" name=\"{}\">",
                escape(&report.scenario.name),
                escape(&o.metric)
            ));
            if let Some(why) = o.skipped {
                xml.push_str(&format!("<skipped message=\"{}\"/>", escape(why)));
            } else if !o.passed {
                xml.push_str(&format!("<failure message=\"{}\"/>", escape(&o.describe())));
            }
            xml.push_str("</testcase>\n");
        }
        xml.push_str("  </testsuite>\n");
    }
    xml.push_str("</testsuites>\n");
    xml
}

/// Text as an XML attribute value.
fn escape(text: &str) -> String {
    text.chars()
        .map(|c| match c {
            '&' => "&amp;".to_string(),
            '<' => "&lt;".to_string(),
            '>' => "&gt;".to_string(),
            '"' => "&quot;".to_string(),
            '\'' => "&apos;".to_string(),
            c if (c as u32) < 0x20 && c != '\t' && c != '\n' => " ".to_string(),
            c => c.to_string(),
        })
        .collect()
}

fn display(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}
