//! `hilsim run [SCENARIO] [--out DIR] [--seed N] [--via memory|serial]`: the main job.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{Context, Result};
use hilsim_lidar_emulator::{Emulation, Run};
use hilsim_recording::write_file_atomically;
use hilsim_sim::Scenario;

use crate::cli::{RunArgs, Via};
use crate::metrics::{self, Metrics, Outcome};

/// Everything one run of a scenario produced.
pub struct Report {
    pub scenario: Scenario,
    pub run: Run,
    pub calibrations: Vec<hilsim_calibrator::Calibration>,
    pub metrics: Metrics,
    pub outcomes: Vec<Outcome>,
}

impl Report {
    pub fn passed(&self) -> bool {
        self.outcomes.iter().all(|o| o.passed)
    }
}

/// Simulates, emulates the sensors, computes the metrics and checks the assertions; with
/// `Via::Serial` the lidar data reaches the metrics through a pty and the decoder.
pub fn execute(scenario: Scenario, origin: &str, via: Via) -> Result<Report> {
    let emulation = Emulation::new(&scenario, scenario.seed)
        .with_context(|| format!("{origin}: sensor model"))?;
    let run = match via {
        Via::Memory => emulation.run(),
        Via::Serial => {
            let (run, _) = hilsim_hil::loopback::run_through_pty(emulation)
                .context("the serial path (pty)")?;
            run
        }
    };
    let mut metrics = metrics::of_run(&run);
    let mut calibrations = Vec::new();
    for method in &scenario.calibration.methods {
        let method = match method {
            hilsim_sim::scenario::Method::Em => hilsim_calibrator::Method::Em,
            hilsim_sim::scenario::Method::Landmarks => hilsim_calibrator::Method::Landmarks,
            hilsim_sim::scenario::Method::Groundtruth => hilsim_calibrator::Method::Groundtruth,
        };
        let calibration = super::calibrate::calibrate_recording(
            &run.recording,
            method,
            super::calibrate::TargetOptions::default(),
        )
        .with_context(|| format!("{origin}: {} calibration", method.name()))?;
        metrics.extend(metrics::of_calibration(&calibration));
        calibrations.push(calibration);
    }
    let outcomes = metrics::check(&scenario.expect, &metrics);
    Ok(Report {
        scenario,
        run,
        calibrations,
        metrics,
        outcomes,
    })
}

pub fn run(args: &RunArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let origin = args.scenario.as_ref().map_or_else(
        || "<built-in straight-board>".to_string(),
        |p| p.display().to_string(),
    );
    let scenario = super::load_scenario(args.scenario.as_deref(), args.seed)?;
    let report = execute(scenario, &origin, args.via)?;
    summarise(&report, out)?;
    if let Some(dir) = &args.out {
        let results = results_json(&report);
        hilsim_recording::replace_dir_atomically(dir, |tmp| -> Result<()> {
            report.run.recording.write_files(tmp)?;
            write_file_atomically(&tmp.join("results.json"), results.as_bytes())?;
            Ok(())
        })?;
        writeln!(out, "wrote {}", dir.display())?;
    }
    Ok(if report.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The short human summary: what was simulated, samples per sensor, the checks.
pub fn summarise(report: &Report, out: &mut dyn Write) -> Result<()> {
    let m = &report.metrics;
    let get = |k: &str| m.get(k).copied().unwrap_or(0.0);
    // A metric that could not be computed (e.g. no truth on the serial path) reads "n/a".
    let rms = |k: &str| {
        m.get(k)
            .map_or_else(|| "n/a".to_string(), |v| format!("{v:.4} m"))
    };
    let rec = &report.run.recording;
    writeln!(
        out,
        "scenario {} (seed {}): {:.2} s simulated, robot travelled {:.3} m, {} collision(s)",
        report.scenario.name,
        report.scenario.seed,
        get("sim.duration_s"),
        get("sim.distance_m"),
        report.run.collisions.len()
    )?;
    for c in &report.run.collisions {
        writeln!(
            out,
            "  collision at t = {:.2} s with {:?}",
            c.t_s, c.obstacle
        )?;
    }
    if rec.lidar.is_some() {
        writeln!(
            out,
            "  lidar     {:>8} readings in {} revolutions, {:.1}% valid, range error RMS {}",
            get("lidar.readings"),
            get("lidar.revolutions"),
            100.0 * get("lidar.valid_fraction"),
            rms("lidar.rmse_m")
        )?;
    }
    if rec.sonar.is_some() {
        writeln!(
            out,
            "  sonar     {:>8} pings, range error RMS {}",
            get("sonar.readings"),
            rms("sonar.rmse_m")
        )?;
    }
    if rec.odometry.is_some() {
        writeln!(
            out,
            "  odometer  {:>8} readings, reported/true travel {}",
            get("odometer.readings"),
            m.get("odometer.scale")
                .map_or_else(|| "n/a".to_string(), |v| format!("{v:.4}"))
        )?;
    }
    if report.calibrations.is_empty() {
        writeln!(out, "  calibration: none requested by the scenario")?;
    }
    for calibration in &report.calibrations {
        for line in super::calibrate::describe(calibration).lines() {
            writeln!(out, "  {line}")?;
        }
    }
    for o in &report.outcomes {
        writeln!(out, "  {}", o.describe())?;
    }
    Ok(())
}

fn results_json(report: &Report) -> String {
    let value = serde_json::json!({
        "scenario": report.scenario.name,
        "seed": report.scenario.seed,
        "metrics": report.metrics,
        "calibrations": report.calibrations.iter().map(hilsim_calibrator::Calibration::to_json).collect::<Vec<_>>(),
        "expectations": report.outcomes,
        "passed": report.passed(),
    });
    let mut text = serde_json::to_string_pretty(&value).unwrap_or_default();
    text.push('\n');
    text
}
