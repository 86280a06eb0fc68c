//! `hilsim calibrate RECORDING --method em|landmarks|groundtruth [--json]` and
//! `hilsim smooth RECORDING --calibration FILE [--csv OUT]` (the EM paper's Sec. V reuse).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

use anyhow::{bail, Context, Result};
use hilsim_calibrator::{em, groundtruth, landmarks, smoothing};
use hilsim_calibrator::{Calibration, Method, Sensor, SensorModel};
use hilsim_recording::{write_file_atomically, Recording};

use crate::cli::{CalibrateArgs, MethodArg, SmoothArgs};

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Em => Method::Em,
            MethodArg::Landmarks => Method::Landmarks,
            MethodArg::Groundtruth => Method::Groundtruth,
        }
    }
}

/// Where the target is, for the methods that need one (EM, ground truth).
#[derive(Debug, Clone, Copy, Default)]
pub struct TargetOptions {
    pub beam_deg: f64,
    pub start_distance_m: Option<f64>,
}

/// Calibrates a recording with one method.
pub fn calibrate_recording(
    rec: &Recording,
    method: Method,
    target: TargetOptions,
) -> Result<Calibration, hilsim_calibrator::CalibrationError> {
    match method {
        Method::Em => em::calibrate(
            rec,
            &em::EmOptions {
                beam_deg: target.beam_deg,
                start_distance_m: target.start_distance_m,
                ..em::EmOptions::default()
            },
        ),
        Method::Groundtruth => groundtruth::calibrate(
            rec,
            &groundtruth::Options {
                beam_deg: target.beam_deg,
                start_distance_m: target.start_distance_m,
                ..groundtruth::Options::default()
            },
        ),
        Method::Landmarks => landmarks::calibrate(rec, &landmarks::Options::default()),
    }
}

pub fn calibrate(args: &CalibrateArgs, out: &mut dyn Write) -> Result<()> {
    let target = target_options(args.beam, args.start_distance)?;
    let rec = Recording::read_dir(&args.recording)?;
    let method = Method::from(args.method);
    let calibration = calibrate_recording(&rec, method, target)
        .with_context(|| format!("{}: {}", args.recording.display(), method.name()))?;
    if args.json {
        writeln!(out, "{}", calibration.to_json())?;
    } else {
        out.write_all(describe(&calibration).as_bytes())?;
    }
    Ok(())
}

fn target_options(beam: Option<f64>, start: Option<f64>) -> Result<TargetOptions> {
    let beam_deg = beam.unwrap_or(0.0);
    if !beam_deg.is_finite() {
        bail!("--beam: expected a finite angle in degrees");
    }
    if start.is_some_and(|d| !(d.is_finite() && d > 0.0)) {
        bail!("--start-distance: expected a positive distance in metres");
    }
    Ok(TargetOptions {
        beam_deg,
        start_distance_m: start,
    })
}

/// A calibration for people: one line per sensor, the metrics, the notes.
pub fn describe(c: &Calibration) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{}: {} iteration(s), {}",
        c.method.name(),
        c.iterations,
        if c.converged {
            "converged"
        } else {
            "NOT converged"
        }
    );
    for (sensor, model) in &c.sensors {
        let _ = writeln!(
            s,
            "  {:<9} alpha {}  beta {}",
            format!("{sensor:?}").to_lowercase(),
            coefficients(&model.alpha),
            coefficients(&model.beta)
        );
    }
    if let Some(order) = c.order {
        let _ = writeln!(s, "  order {order}");
    }
    if let Some(landmarks) = &c.landmarks {
        for (i, [x, y]) in landmarks.iter().enumerate() {
            let _ = writeln!(s, "  landmark {i}: ({x:.3}, {y:.3}) m");
        }
    }
    if let Some(m) = c.metrics {
        let _ = writeln!(
            s,
            "  distance MSE raw {:.3e} m², calibrated {:.3e} m² (ratio {:.2}); NMSE raw {:.3e}, calibrated {:.3e}",
            m.mse_raw,
            m.mse_calibrated,
            m.mse_ratio(),
            m.nmse_raw,
            m.nmse_calibrated
        );
    }
    for note in &c.notes {
        let _ = writeln!(s, "  note: {note}");
    }
    s
}

fn coefficients(c: &[f64]) -> String {
    let parts: Vec<String> = c.iter().map(|v| format!("{v:.5}")).collect();
    format!("[{}]", parts.join(", "))
}

pub fn smooth(args: &SmoothArgs, out: &mut dyn Write) -> Result<()> {
    let target = target_options(args.beam, args.start_distance)?;
    let trained = read_calibration(&args.calibration)?;
    let rec = Recording::read_dir(&args.recording)?;
    let estimates = smoothing::smooth(
        &rec,
        &trained,
        &em::EmOptions {
            beam_deg: target.beam_deg,
            start_distance_m: target.start_distance_m,
            ..em::EmOptions::default()
        },
    )
    .with_context(|| format!("{}: smoothing", args.recording.display()))?;
    let mut csv = String::from("t_s,distance_m,sd_m\n");
    for e in &estimates {
        let _ = writeln!(
            csv,
            "{},{},{}",
            e.t_s,
            e.distance_m,
            e.variance_m2.max(0.0).sqrt()
        );
    }
    match &args.csv {
        Some(path) => {
            write_file_atomically(path, csv.as_bytes())?;
            writeln!(
                out,
                "smoothed {} samples of {} into {}",
                estimates.len(),
                args.recording.display(),
                path.display()
            )?;
        }
        None => out.write_all(csv.as_bytes())?,
    }
    Ok(())
}

/// Reads the JSON that `hilsim calibrate --json` printed.
fn read_calibration(path: &Path) -> Result<Calibration> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .map_err(|err| anyhow::anyhow!("{}:{}: not JSON: {err}", path.display(), err.line()))?;
    let method = match value["method"].as_str() {
        Some("em") => Method::Em,
        Some("landmarks") => Method::Landmarks,
        Some("groundtruth") => Method::Groundtruth,
        other => bail!(
            "{}: `method` must be em, landmarks or groundtruth, found {other:?}",
            path.display()
        ),
    };
    let mut sensors = BTreeMap::new();
    for (name, sensor) in [
        ("lidar", Sensor::Lidar),
        ("sonar", Sensor::Sonar),
        ("odometer", Sensor::Odometer),
    ] {
        let model = &value["sensors"][name];
        if model.is_null() {
            continue;
        }
        let coeffs = |key: &str| -> Result<Vec<f64>> {
            model[key]
                .as_array()
                .and_then(|a| {
                    a.iter()
                        .map(serde_json::Value::as_f64)
                        .collect::<Option<Vec<_>>>()
                })
                .with_context(|| {
                    format!(
                        "{}: sensors.{name}.{key} must be an array of numbers",
                        path.display()
                    )
                })
        };
        sensors.insert(
            sensor,
            SensorModel {
                alpha: coeffs("alpha")?,
                beta: coeffs("beta")?,
            },
        );
    }
    Ok(Calibration {
        method,
        sensors,
        iterations: 0,
        converged: true,
        metrics: None,
        order: None,
        landmarks: None,
        notes: Vec::new(),
    })
}
