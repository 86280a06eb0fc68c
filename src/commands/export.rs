//! `hilsim export RECORDING --mcap OUT [--scenario FILE] [--calibration FILE]`: a recording as
//! ROS 2 messages in an MCAP file.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Result;
use hilsim_recording::OutputTarget;
use hilsim_scenarios::{ExportRequest, McapExport};

use crate::cli::ExportArgs;

pub fn export(args: &ExportArgs, out: &mut dyn Write) -> Result<ExitCode> {
    // Every input is read before the output is opened.
    let export = McapExport::prepare(&ExportRequest {
        recording: &args.recording,
        mcap: &args.mcap,
        scenario: args.scenario.as_deref(),
        calibration: args.calibration.as_deref(),
    })?;
    export.write(&args.mcap)?;
    // Written to standard output, the file is the output: the line saying so goes beside it.
    if OutputTarget::is_stdout(&args.mcap) {
        eprintln!("wrote {}", args.mcap.display());
    } else {
        writeln!(out, "wrote {}", args.mcap.display())?;
    }
    Ok(ExitCode::SUCCESS)
}
