//! `hilsim report RECORDING [--scenario FILE] [--calibration FILE] --out DIR`: the run report,
//! one self-contained `DIR/index.html`. `hilsim run --report DIR` writes the same page.

use std::fs;
use std::io::{Read, Write};
use std::path::Path;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use hilsim_recording::{write_owned_file_atomically, RecordingDir};
use hilsim_report::Inputs;
use hilsim_sim::Scenario;

use crate::cli::ReportArgs;

pub fn report(args: &ReportArgs, out: &mut dyn Write) -> Result<ExitCode> {
    check_report_dir(&args.out, &[])?;
    let scenario = args.scenario.as_deref().map(Scenario::load).transpose()?;
    // Read as streams, holding at most `MAX_ROWS` rows of a table whatever the recording's length.
    let (recording, thinning) =
        RecordingDir::open(&args.recording)?.read_thinned(hilsim_report::MAX_ROWS)?;
    let beside = args.recording.join("results.json");
    let calibration_file = args
        .calibration
        .clone()
        .or_else(|| beside.is_file().then_some(beside));
    let calibrations = match &calibration_file {
        Some(path) => super::read_calibrations(path)?,
        None => Vec::new(),
    };
    let name = args.recording.display().to_string();
    let title = format!("hilsim report: {name}");
    let html = hilsim_report::render(Inputs {
        title: &title,
        recording: &recording,
        recording_name: &hilsim_report::drawn_name(&name, &thinning),
        scenario: scenario.as_ref(),
        calibrations: &calibrations,
        truth_estimated: false,
    });
    write_report_page(&args.out, &html)?;
    writeln!(out, "report: {}", args.out.join("index.html").display())?;
    Ok(ExitCode::SUCCESS)
}

/// Refuses, before any work, a report directory that is not one: a file, or a directory whose
/// `index.html` is not a previous report (the user's page is never replaced). Without a previous
/// report's page there, none of the `files` the report adds beside its page may exist either:
/// they would be the user's.
pub fn check_report_dir(dir: &Path, files: &[&str]) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("{}: exists and is not a directory", dir.display());
    }
    let page = dir.join("index.html");
    if fs::symlink_metadata(&page).is_err() {
        if let Some(file) = files
            .iter()
            .map(|f| dir.join(f))
            .find(|f| fs::symlink_metadata(f).is_ok())
        {
            bail!(
                "{}: exists, and {} is not a previous hilsim report's; not replacing it",
                file.display(),
                dir.display()
            );
        }
    } else {
        let mut head = Vec::new();
        fs::File::open(&page)
            .and_then(|f| f.take(4096).read_to_end(&mut head))
            .with_context(|| format!("{}: cannot read", page.display()))?;
        if !hilsim_report::is_report(&String::from_utf8_lossy(&head)) {
            bail!(
                "{}: exists and is not a hilsim report; not replacing it",
                page.display()
            );
        }
    }
    Ok(())
}

/// Writes `html` as `dir/index.html` (the directory created if needed), atomically.
pub fn write_report_page(dir: &Path, html: &str) -> Result<()> {
    check_report_dir(dir, &[])?;
    fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    write_owned_file_atomically(&dir.join("index.html"), html.as_bytes())?;
    Ok(())
}
