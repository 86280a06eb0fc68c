//! `hilsim run [SCENARIO] [--out DIR] [--seed N] [--via memory|serial] [--json]`: the main job.

use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

use anyhow::Result;
use hilsim_recording::check_output_file;
use hilsim_scenarios::{builtin, McapExport, RecordedRun, Report, StreamTarget, Via};
use hilsim_sim::Scenario;

use crate::cli::{self, RunArgs};

pub fn run(args: &RunArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let origin = args.scenario.as_ref().map_or_else(
        || builtin::STRAIGHT_BOARD_ORIGIN.to_string(),
        |p| p.display().to_string(),
    );
    let (scenario, via) = validate(args, &origin)?;
    let world = hilsim_scenarios::drawn_world(&scenario);
    let streamed = StreamTarget::new(via, args.out.as_deref(), args.mcap.as_deref())?;
    let report = execute(args, scenario, &origin, via, streamed.dir(), out)?;
    if let Some(dir) = &args.report {
        let html = report.page(&origin);
        hilsim_report::write_report_files(dir, &[("index.html".into(), html)])?;
        if !args.json {
            writeln!(out, "report: {}", dir.join("index.html").display())?;
        }
    }
    if let Some(mcap) = &args.mcap {
        match streamed.dir() {
            Some(dir) => McapExport::of_dir(dir, Some(world))?.write(mcap)?,
            None => hilsim_ros2::export(&report.run.recording, Some(&world), mcap)?,
        };
        if !args.json {
            writeln!(out, "wrote {}", mcap.display())?;
        }
    }
    drop(streamed);
    Ok(super::exit_code(report.passed()))
}

/// The scenario and the lidar's path, every output checked before the run, so that a refused
/// one costs nothing.
fn validate(args: &RunArgs, origin: &str) -> Result<(Scenario, Via)> {
    if let Some(dir) = &args.report {
        hilsim_report::check_report_dir(dir, &[])?;
    }
    if let Some(dir) = &args.out {
        hilsim_recording::check_replaceable_recording(&hilsim_recording::resolve_output_dir(dir)?)?;
        hilsim_recording::tidy_after_killed_writers(dir)?;
    }
    if let Some(mcap) = &args.mcap {
        let inputs = Vec::from_iter(args.scenario.as_deref());
        check_output_file(mcap, hilsim_ros2::MCAP_FILE, &inputs)?;
    }
    let scenario = hilsim_scenarios::builtin::load_or_default(args.scenario.as_deref(), args.seed)?;
    let via = match args.via {
        cli::Via::Memory => Via::Memory,
        cli::Via::Serial => Via::Serial,
    };
    via.check(&scenario, origin)?;
    Ok((scenario, via))
}

/// Runs the scenario, streamed into `streamed_to` when given, prints the summary (or the
/// results' JSON) and writes the recording with its `results.json` to `--out`.
fn execute(
    args: &RunArgs,
    scenario: Scenario,
    origin: &str,
    via: Via,
    streamed_to: Option<&Path>,
    out: &mut dyn Write,
) -> Result<Report> {
    let run = RecordedRun::execute(scenario, origin, via, streamed_to)?;
    let results = run.report.results_json();
    if args.json {
        out.write_all(results.as_bytes())?;
    } else {
        out.write_all(run.report.summary().as_bytes())?;
    }
    let report = run.finish(args.out.as_deref(), &results)?;
    if let (Some(dir), false) = (&args.out, args.json) {
        writeln!(out, "wrote {}", dir.display())?;
    }
    Ok(report)
}
