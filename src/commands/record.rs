//! `hilsim record SCENARIO --out DIR [--seed N]`: the samples go to disk as they are taken, so a
//! run of any length records in flat memory, written by a thread of its own.

use std::process::ExitCode;

use anyhow::{Context, Result};
use hilsim_lidar_emulator::Emulation;
use hilsim_recording::{check_output_file, BackgroundStream, RecordingStream};
use hilsim_scenarios::McapExport;

use crate::cli::RecordArgs;

pub fn record(args: &RecordArgs) -> Result<ExitCode> {
    if let Some(mcap) = &args.mcap {
        check_output_file(mcap, hilsim_ros2::MCAP_FILE, &[&args.scenario])?;
    }
    let scenario = hilsim_scenarios::builtin::load_or_default(Some(&args.scenario), args.seed)?;
    let emulation = Emulation::new(&scenario, scenario.seed)
        .with_context(|| format!("{}: sensor model", args.scenario.display()))?;
    hilsim_recording::tidy_after_killed_writers(&args.out)?;
    let stream = RecordingStream::create(&args.out, emulation.meta().clone(), emulation.tables())?;
    // The CSV text is made and written on the other core while the simulation runs.
    let mut sink = BackgroundStream::spawn(stream)?;
    emulation.record_into(&mut sink)?;
    sink.finish()?;
    if let Some(mcap) = &args.mcap {
        // The recording as written (it streamed to disk, so it is read back, as streams).
        let world = hilsim_scenarios::drawn_world(&scenario);
        McapExport::of_dir(&args.out, Some(world))?.write(mcap)?;
    }
    Ok(ExitCode::SUCCESS)
}
