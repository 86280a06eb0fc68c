//! `hilsim export RECORDING --mcap OUT [--scenario FILE]`: a recording as ROS 2 messages in an
//! MCAP file (and the `--mcap OUT` of `record` and `run`).

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Result;
use hilsim_recording::Recording;
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
}

pub fn export(args: &ExportArgs, out: &mut dyn Write) -> Result<()> {
    // Both inputs are read before the output is opened.
    let world = match &args.scenario {
        Some(path) => Some(world(&super::load_scenario(Some(path), None)?)),
        None => None,
    };
    let recording = Recording::read_dir(&args.recording)?;
    write_mcap(&recording, world.as_ref(), &args.mcap)?;
    writeln!(out, "wrote {}", args.mcap.display())?;
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
