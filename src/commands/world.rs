//! `hilsim world REC --out SCENARIO.toml [--map MAP.yaml] [--resolution-m M] [--poses
//! auto|truth|odometry]`: a scenario that replays a recorded run in its world, and how close
//! its twin's readings come to the log's.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use hilsim_sim::Scenario;
use hilsim_twin::{build_world, compare, PoseSource, TwinFiles, WorldOptions, COMPARED_WITHIN_M};

#[derive(Debug, clap::Args)]
pub struct WorldArgs {
    /// The recording (as `hilsim import` writes one).
    pub recording: PathBuf,
    /// The scenario to write; its map (`STEM.map.yaml` and `.pgm`), path (`STEM.path.csv`) and
    /// scan schedule (`STEM.scans.csv`) are written beside it.
    #[arg(long, value_name = "SCENARIO.toml")]
    pub out: PathBuf,
    /// The user's map (map_server YAML and its image) instead of one built from the scans.
    #[arg(long, value_name = "MAP.yaml")]
    pub map: Option<PathBuf>,
    /// The built map's cell size, metres.
    #[arg(long, value_name = "M", default_value_t = WorldOptions::default().resolution_m)]
    pub resolution_m: f64,
    /// Where the robot's path comes from: `truth` (truth.csv), `odometry` (the wheels, corrected
    /// by matching scans), or `auto` (truth when the recording has it).
    #[arg(long, value_name = "SOURCE", default_value = "auto", value_parser = ["auto", "truth", "odometry"])]
    pub poses: String,
}

pub fn world(args: &WorldArgs, out: &mut impl Write) -> Result<()> {
    if !(args.resolution_m.is_finite() && (0.005..=1.0).contains(&args.resolution_m)) {
        bail!(
            "--resolution-m {}: expected a cell size from 0.005 to 1 m; see hilsim world --help",
            args.resolution_m
        );
    }
    let poses = match args.poses.as_str() {
        "truth" => PoseSource::Truth,
        "odometry" => PoseSource::Odometry,
        _ => PoseSource::Auto,
    };
    let options = WorldOptions {
        map: args.map.clone(),
        resolution_m: args.resolution_m,
        poses,
        ..WorldOptions::default()
    };
    let world = build_world(&args.recording, &options)?;
    for note in &world.notes {
        writeln!(out, "note: {note}")?;
    }
    let files = TwinFiles::beside(&args.out, args.map.as_deref());
    // First noiseless, to measure how far the log's readings are from the map's.
    world.write(&files, 0.0)?;
    let scenario = Scenario::from_toml(&world.scenario_toml(&files, 0.0), &files.scenario)?;
    let fit = compare(&scenario, &args.recording)?;
    // The lidar's noise declared as the spread of the log against its twin: the log's noise and
    // the map's error together, an upper bound of the lidar's own.
    let noise_m = if fit.spread_m.is_finite() {
        fit.spread_m
    } else {
        0.0
    };
    world.write(&files, noise_m)?;
    writeln!(
        out,
        "twin: {} of {} readings within {COMPARED_WITHIN_M} m paired ({:.1} %); |twin − log| \
         median {:.1} mm, 90th percentile {:.1} mm; log − twin median {:+.1} mm, spread {:.1} mm \
         (declared as the lidar's noise)",
        fit.paired,
        fit.compared,
        100.0 * fit.paired_share(),
        1000.0 * fit.median_abs_m,
        1000.0 * fit.p90_abs_m,
        1000.0 * fit.median_m,
        1000.0 * fit.spread_m,
    )?;
    writeln!(out, "wrote {}", files.scenario.display())?;
    Ok(())
}
