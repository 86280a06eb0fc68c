//! `hilsim export RECORDING --mcap OUT [--scenario FILE] [--calibration FILE]`: a recording as
//! ROS 2 messages in an MCAP file (and the `--mcap OUT` of `record` and `run`).

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use hilsim_calibrator::landmarks::Inverse;
use hilsim_calibrator::Sensor;
use hilsim_recording::{check_output_file, LidarSample, OutputTarget, Recording, RecordingDir};
use hilsim_sim::Scenario;

use crate::cli::ExportArgs;

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
        .map(hilsim_calibrator::Calibration::read)
        .transpose()?;
    let recording = RecordingDir::open(&args.recording)?;
    let inverse = match (&calibration, args.calibration.as_deref()) {
        (Some(calibration), Some(path)) => Some(calibrated_ranges(&recording, calibration, path)?),
        _ => None,
    };
    // An invalid reading has no calibrated range.
    let calibrated = inverse.map(|inverse| {
        move |s: &LidarSample| {
            if s.invalid {
                f64::NAN
            } else {
                inverse.distance(s.range_m)
            }
        }
    });
    let options = hilsim_ros2::ExportOptions {
        world: world.as_ref(),
        calibrated: calibrated
            .as_ref()
            .map(|f| f as &dyn Fn(&LidarSample) -> f64),
        ..hilsim_ros2::ExportOptions::default()
    };
    hilsim_ros2::export_dir(&recording, &options, &args.mcap)?;
    // Written to standard output, the file is the output: the line saying so goes beside it.
    if OutputTarget::of(&args.mcap).is_ok_and(|t| t == OutputTarget::Stdout) {
        eprintln!("wrote {}", args.mcap.display());
    } else {
        writeln!(out, "wrote {}", args.mcap.display())?;
    }
    Ok(())
}

/// The calibration's lidar model inverted: a reading's distance (the distance whose mean
/// reading it is), searched up to past the farthest reading of the recording.
fn calibrated_ranges(
    recording: &RecordingDir,
    calibration: &hilsim_calibrator::Calibration,
    path: &Path,
) -> Result<Inverse> {
    // The recording is checked (as a whole read would, its errors first) on the way.
    let farthest = recording.farthest_lidar_range_m(1.0)?;
    let model = calibration.sensors.get(&Sensor::Lidar).with_context(|| {
        format!(
            "{}: no lidar model (the {} method's calibration; the calibrated scans need em's, \
                 landmarks' or groundtruth's)",
            path.display(),
            calibration.method.name()
        )
    })?;
    // Search up to past the farthest reading: a lidar model is fitted below 100 m.
    Inverse::new(&model.alpha, [0.0, 2.0 * farthest + 100.0])
        .with_context(|| format!("{}: the lidar model", path.display()))
}

/// Writes the recording directory `dir` as MCAP at `path`, reading it as streams.
pub fn write_mcap_of_dir(
    dir: &Path,
    world: Option<&hilsim_ros2::World>,
    path: &Path,
) -> Result<()> {
    let options = hilsim_ros2::ExportOptions {
        world,
        ..hilsim_ros2::ExportOptions::default()
    };
    hilsim_ros2::export_dir(&RecordingDir::open(dir)?, &options, path)?;
    Ok(())
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
