//! `hilsim export RECORDING --mcap OUT [--scenario FILE] [--calibration FILE]`: a recording as
//! ROS 2 messages in an MCAP file (and the `--mcap OUT` of `record` and `run`).

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use hilsim_calibrator::landmarks::Inverse;
use hilsim_calibrator::Sensor;
use hilsim_recording::{check_output_file, OutputTarget, Recording};
use hilsim_sim::Scenario;

#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// A recording directory.
    pub recording: PathBuf,
    /// The MCAP file to write (replaced atomically when complete).
    #[arg(long, value_name = "OUT")]
    pub mcap: PathBuf,
    /// The scenario the recording ran: its world is drawn as markers (`/world`).
    #[arg(long, value_name = "FILE")]
    pub scenario: Option<PathBuf>,
    /// A calibration (`hilsim calibrate --json`): the scans with each reading inverted through
    /// its lidar model are sent too, as `/scan_calibrated`.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
}

pub fn export(args: &ExportArgs, out: &mut dyn Write) -> Result<()> {
    let mut inputs = Recording::files_in(&args.recording);
    inputs.extend(args.scenario.iter().chain(&args.calibration).cloned());
    check_mcap_output(&args.mcap, &inputs)?;
    // Both inputs are read before the output is opened.
    let world = match &args.scenario {
        Some(path) => Some(world(&super::load_scenario(Some(path), None)?)),
        None => None,
    };
    let calibration = args
        .calibration
        .as_deref()
        .map(super::read_calibration)
        .transpose()?;
    let recording = Recording::read_dir(&args.recording)?;
    let calibrated = match (&calibration, args.calibration.as_deref()) {
        (Some(calibration), Some(path)) => Some(calibrated_ranges(&recording, calibration, path)?),
        _ => None,
    };
    let options = hilsim_ros2::ExportOptions {
        world: world.as_ref(),
        calibrated_m: calibrated.as_deref(),
        ..hilsim_ros2::ExportOptions::default()
    };
    hilsim_ros2::export_with(&recording, &options, &args.mcap)?;
    // Written to standard output, the file is the output: the line saying so goes beside it.
    if OutputTarget::of(&args.mcap).is_ok_and(|t| t == OutputTarget::Stdout) {
        eprintln!("wrote {}", args.mcap.display());
    } else {
        writeln!(out, "wrote {}", args.mcap.display())?;
    }
    Ok(())
}

/// Each lidar reading's distance by the calibration's lidar model (the distance whose mean
/// reading it is); NaN for an invalid reading.
fn calibrated_ranges(
    recording: &Recording,
    calibration: &hilsim_calibrator::Calibration,
    path: &Path,
) -> Result<Vec<f64>> {
    let model = calibration
        .sensors
        .get(&Sensor::Lidar)
        .with_context(|| format!("{}: no lidar model", path.display()))?;
    let lidar = recording.lidar.as_deref().unwrap_or_default();
    // Search up to past the farthest reading: a lidar model is fitted below 100 m.
    let farthest = lidar.iter().map(|s| s.range_m).fold(1.0, f64::max);
    let inverse = Inverse::new(&model.alpha, [0.0, 2.0 * farthest + 100.0])
        .with_context(|| format!("{}: the lidar model", path.display()))?;
    Ok(lidar
        .iter()
        .map(|s| {
            if s.invalid {
                f64::NAN
            } else {
                inverse.distance(s.range_m)
            }
        })
        .collect())
}

/// Checks, before any work, that `path` may take an MCAP file: nothing there, a previous MCAP
/// file, or a device or standard output written through; never one of `inputs`.
pub fn check_mcap_output(path: &Path, inputs: &[PathBuf]) -> Result<()> {
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    check_output_file(path, hilsim_ros2::MCAP_FILE, &inputs)?;
    Ok(())
}

/// Writes `recording` as MCAP at `path`.
pub fn write_mcap(
    recording: &Recording,
    world: Option<&hilsim_ros2::World>,
    path: &Path,
) -> Result<()> {
    hilsim_ros2::export(recording, world, path)?;
    Ok(())
}

/// A scenario's obstacles as the exporter draws them.
pub fn world(scenario: &Scenario) -> hilsim_ros2::World {
    let w = &scenario.world;
    hilsim_ros2::World {
        walls: w.walls.iter().map(|wall| [wall.from, wall.to]).collect(),
        cylinders: w.cylinders.iter().map(|c| (c.center, c.radius)).collect(),
        boards: w
            .boards
            .iter()
            .map(|b| (b.center, b.length, b.thickness, b.yaw_deg.to_radians()))
            .collect(),
    }
}
