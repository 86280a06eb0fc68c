//! `hilsim world REC --out SCENARIO.toml [--map MAP.yaml] [--resolution-m M] [--poses
//! auto|truth|odometry]`: a scenario that replays a recorded run in its world, and how close
//! its twin's readings come to the log's.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use hilsim_recording::{Mount, Sensor};
use hilsim_sim::Scenario;
use hilsim_twin::{
    build_world, compare, Declared, PoseSource, TwinFiles, WorldOptions, COMPARED_WITHIN_M,
};

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
    /// A calibration of the robot (`hilsim calibrate --json`) whose models the scenario
    /// declares: an em, landmarks or groundtruth calibration's lidar bias and noise; an odometry
    /// calibration's wheel base and lidar mount. Without one the lidar is declared unbiased,
    /// with the noise the log shows against its twin.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
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
    let calibration = args
        .calibration
        .as_deref()
        .map(super::read_calibration)
        .transpose()?;
    let world = build_world(&args.recording, &options)?;
    for note in &world.notes {
        writeln!(out, "note: {note}")?;
    }
    let files = TwinFiles::beside(&args.out, args.map.as_deref());
    let mut declared = world.declared();
    let mut noise_calibrated = false;
    if let Some(c) = &calibration {
        if let Some(model) = c.sensors.get(&Sensor::Lidar) {
            declared.lidar_bias.clone_from(&model.alpha);
            declared.lidar_noise.clone_from(&model.beta);
            noise_calibrated = true;
        }
        if let Some(o) = &c.odometry {
            declared.wheel_base_m = o.wheel_base_m;
            declared.lidar_mount = Mount {
                x_m: o.lidar_x_m,
                y_m: o.lidar_y_m,
                yaw_deg: o.lidar_yaw_rad.to_degrees(),
            };
        }
        if !noise_calibrated && c.odometry.is_none() {
            bail!(
                "{}: the {} method's calibration has no lidar model, no wheels and no lidar \
                 mount for the scenario to declare",
                args.calibration
                    .as_deref()
                    .unwrap_or(Path::new(""))
                    .display(),
                c.method.name()
            );
        }
    }
    // First noiseless, to measure how far the log's readings are from the map's.
    let noiseless = Declared {
        lidar_noise: vec![0.0],
        ..declared.clone()
    };
    world.write(&files, &noiseless)?;
    let scenario = Scenario::from_toml(&world.scenario_toml(&files, &noiseless), &files.scenario)?;
    let fit = compare(&scenario, &args.recording)?;
    if !noise_calibrated && fit.spread_m.is_finite() {
        // The spread of the log against its twin by range, as the papers' noise polynomial:
        // the map's quantisation taken out (the diagnosis carries it itself), what is left is
        // an upper bound of the lidar's noise.
        let cell = scenario
            .files
            .map
            .as_ref()
            .map_or(0.0, |m| m.resolution_m());
        declared.lidar_noise = fit.noise_polynomial(cell);
    }
    world.write(&files, &declared)?;
    writeln!(
        out,
        "twin: {} of {} readings within {COMPARED_WITHIN_M} m paired ({:.1} %); |twin − log| \
         median {:.1} mm, 90th percentile {:.1} mm; log − twin median {:+.1} mm, spread {:.1} mm",
        fit.paired,
        fit.compared,
        100.0 * fit.paired_share(),
        1000.0 * fit.median_abs_m,
        1000.0 * fit.p90_abs_m,
        1000.0 * fit.median_m,
        1000.0 * fit.spread_m,
    )?;
    if !noise_calibrated {
        writeln!(
            out,
            "declared the lidar's noise (its spread against the twin by range, less the map's \
             cells): {:?} (β₀, β₁, β₂ of σ = β₀ + β₁ d + β₂ d², metres)",
            declared.lidar_noise
        )?;
    }
    writeln!(out, "wrote {}", files.scenario.display())?;
    Ok(())
}
