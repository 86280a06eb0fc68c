//! `hilsim run [SCENARIO] [--out DIR] [--seed N] [--via memory|serial] [--json]`: the main job.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Result;
use hilsim_recording::write_file_atomically;
use hilsim_scenarios::{builtin, Via};

use crate::cli::{self, RunArgs};

pub fn run(args: &RunArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let origin = args.scenario.as_ref().map_or_else(
        || builtin::STRAIGHT_BOARD_ORIGIN.to_string(),
        |p| p.display().to_string(),
    );
    // Every output is checked before the run, so that a refused one costs nothing.
    if let Some(dir) = &args.report {
        super::report::check_report_dir(dir, &[])?;
    }
    if let Some(dir) = &args.out {
        hilsim_recording::check_replaceable_recording(&hilsim_recording::resolve_output_dir(dir)?)?;
    }
    if let Some(mcap) = &args.mcap {
        super::export::check_mcap_output(mcap, &Vec::from_iter(args.scenario.clone()))?;
    }
    let scenario = super::load_scenario(args.scenario.as_deref(), args.seed)?;
    let via = match args.via {
        cli::Via::Memory => Via::Memory,
        cli::Via::Serial => Via::Serial,
    };
    let world = super::export::world(&scenario);
    let report = hilsim_scenarios::execute(scenario, &origin, via)?;
    if args.json {
        out.write_all(report.results_json().as_bytes())?;
    } else {
        out.write_all(report.summary().as_bytes())?;
    }
    if let Some(dir) = &args.out {
        let results = report.results_json();
        hilsim_recording::replace_recording_dir(dir, |tmp| -> Result<()> {
            report.run.recording.write_files(tmp)?;
            write_file_atomically(&tmp.join("results.json"), results.as_bytes())?;
            Ok(())
        })?;
        if !args.json {
            writeln!(out, "wrote {}", dir.display())?;
        }
    }
    if let Some(dir) = &args.report {
        let title = format!("hilsim run: {}", report.scenario.name);
        let (recording, thinning) = report.run.recording.thinned(hilsim_report::MAX_ROWS);
        let name = format!("{origin} (seed {}, in memory)", report.scenario.seed);
        let html = hilsim_report::render(hilsim_report::Inputs {
            title: &title,
            recording: &recording,
            recording_name: &hilsim_report::drawn_name(&name, &thinning),
            scenario: Some(&report.scenario),
            calibrations: &report.calibrations,
            truth_estimated: false,
        });
        super::report::write_report_page(dir, &html)?;
        if !args.json {
            writeln!(out, "report: {}", dir.join("index.html").display())?;
        }
    }
    if let Some(mcap) = &args.mcap {
        super::export::write_mcap(&report.run.recording, Some(&world), mcap)?;
        if !args.json {
            writeln!(out, "wrote {}", mcap.display())?;
        }
    }
    Ok(if report.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
