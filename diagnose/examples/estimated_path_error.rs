//! How far the path `hilsim diagnose` estimates from the lidar (without `truth.csv`) lies from a
//! recording's own truth: the error along the robot's heading, across it, and in heading, with
//! the estimate's stated uncertainty beside them. The encoders are judged against that path, so
//! its error is what they cannot be told apart from.
//!
//! `cargo run --release -p hilsim-diagnose --example estimated_path_error -- SCENARIO RECORDING`
//! (the recording with its `truth.csv`; it is removed before the diagnosis). Add `--csv` for
//! the error at every sample of the path.

use std::path::Path;
use std::process::ExitCode;

use hilsim_diagnose::{diagnose, Options, SimPhysics};
use hilsim_recording::Recording;
use hilsim_sim::Scenario;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("estimated_path_error: {e}");
            ExitCode::from(2)
        }
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let csv = args.iter().any(|a| a == "--csv");
    let paths: Vec<&String> = args.iter().filter(|a| *a != "--csv").collect();
    let [scenario, recording] = paths[..] else {
        return Err("expected SCENARIO RECORDING [--csv]".into());
    };
    let text = std::fs::read_to_string(scenario).map_err(|e| format!("{scenario}: {e}"))?;
    let scenario =
        Scenario::from_toml(&text, Path::new(scenario)).map_err(|e| format!("{scenario}: {e}"))?;
    let mut recording =
        Recording::read_dir(Path::new(recording)).map_err(|e| format!("{recording}: {e}"))?;
    let truth = recording
        .truth
        .take()
        .ok_or("the recording has no truth.csv to measure the estimate against")?;
    let physics = SimPhysics::new(&scenario).map_err(|e| e.to_string())?;
    let d = diagnose(&physics, &recording, &Options::default()).map_err(|e| e.to_string())?;
    let estimated = d.estimated_path.ok_or("the diagnosis estimated no path")?;
    let truth_at = |t: f64| {
        let i = truth.partition_point(|s| s.t_s < t).min(truth.len() - 1);
        truth[i]
    };
    if csv {
        println!("t_s,along_m,across_m,heading_rad");
    }
    let mut errors: [Vec<f64>; 3] = Default::default();
    for e in &estimated {
        let s = truth_at(e.t_s);
        let (dx, dy) = (e.x_m - s.x_m, e.y_m - s.y_m);
        let (sin, cos) = s.yaw_rad.sin_cos();
        let dyaw = (e.yaw_rad - s.yaw_rad + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        let error = [dx * cos + dy * sin, -dx * sin + dy * cos, dyaw];
        if csv {
            println!("{},{},{},{}", e.t_s, error[0], error[1], error[2]);
        }
        for (all, v) in errors.iter_mut().zip(error) {
            all.push(v);
        }
    }
    if !csv {
        for (name, unit, scale, all) in [
            ("along the heading", "mm", 1000.0, &errors[0]),
            ("across it", "mm", 1000.0, &errors[1]),
            ("heading", "mrad", 1000.0, &errors[2]),
        ] {
            let min = all.iter().copied().fold(f64::INFINITY, f64::min);
            let max = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let rms = (all.iter().map(|v| v * v).sum::<f64>() / all.len() as f64).sqrt();
            println!(
                "{name}: {:+.1} to {:+.1} {unit}, RMS {:.1} {unit}",
                min * scale,
                max * scale,
                rms * scale
            );
        }
        for note in d.notes.iter().filter(|n| n.starts_with("no truth.csv")) {
            println!("stated: {note}");
        }
    }
    Ok(())
}
