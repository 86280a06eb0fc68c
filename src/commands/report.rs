//! `hilsim report RECORDING [--scenario FILE] [--calibration FILE] --out DIR`: the run report,
//! one self-contained `DIR/index.html`. `hilsim run --report DIR` writes the same page.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Result;
use hilsim_recording::RecordingDir;
use hilsim_report::recording_page;
use hilsim_sim::Scenario;

use crate::cli::ReportArgs;

pub fn report(args: &ReportArgs, out: &mut dyn Write) -> Result<ExitCode> {
    hilsim_report::check_report_dir(&args.out, &[])?;
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
        Some(path) => hilsim_calibrator::Calibration::read_all(path)?,
        None => Vec::new(),
    };
    let name = args.recording.display().to_string();
    let html = recording_page(
        &name,
        &recording,
        &thinning,
        scenario.as_ref(),
        &calibrations,
    );
    hilsim_report::write_report_files(&args.out, &[("index.html".into(), html)])?;
    writeln!(out, "report: {}", args.out.join("index.html").display())?;
    Ok(ExitCode::SUCCESS)
}
