//! `hilsim world REC --out SCENARIO.toml [--map MAP.yaml] [--resolution-m M] [--poses
//! auto|truth|odometry]`: a scenario that replays a recorded run in its world, and how close
//! its twin's readings come to the log's.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Result;
use hilsim_twin::{build_world, TwinFiles, WorldOptions};

use crate::cli::WorldArgs;

pub fn world(args: &WorldArgs, out: &mut impl Write) -> Result<ExitCode> {
    let options = WorldOptions::from_flags(args.map.clone(), args.resolution_m, &args.poses)?;
    let calibration = args
        .calibration
        .as_deref()
        .map(hilsim_calibrator::Calibration::read);
    let calibration = calibration.transpose()?;
    let world = build_world(&args.recording, &options)?;
    for note in &world.notes {
        writeln!(out, "note: {note}")?;
    }
    let files = TwinFiles::beside(&args.out, args.map.as_deref());
    let mut declared = world.declared();
    let noise_calibrated = match (&calibration, &args.calibration) {
        (Some(c), Some(path)) => declared.calibrate(c, &path.display().to_string())?,
        _ => false,
    };
    let (fit, declared) = world.write_measured(&files, declared, noise_calibrated)?;
    writeln!(out, "{}", fit.summary())?;
    if !noise_calibrated {
        writeln!(out, "{}", declared.measured_noise_line())?;
    }
    writeln!(out, "wrote {}", files.scenario.display())?;
    Ok(ExitCode::SUCCESS)
}
