//! `hilsim calibrate RECORDING --method em|landmarks|groundtruth|odometry [--json]`,
//! `hilsim calibrate --method odometry --tuples FILE` and
//! `hilsim smooth RECORDING --calibration FILE [--csv OUT]` (the EM paper's Sec. V reuse).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use hilsim_calibrator::{odometry, request, smoothing, Calibration, Method, Request, Settings};
use hilsim_recording::{check_output_file, write_file_atomically, Meta, OutputTarget, Recording};

use crate::cli::{CalibrateArgs, SmoothArgs};

/// Prints the calibration; exit 1 when one of its checks failed (the result is still printed).
pub fn calibrate(args: &CalibrateArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let settings = request(args).settings()?;
    let method = args.method;
    let (calibration, input) = match (&args.recording, &args.tuples) {
        (_, Some(tuples)) => (calibrate_tuples(tuples)?, tuples.as_path()),
        (Some(recording), None) => (
            calibrate_dir(recording, method, &settings)?,
            recording.as_path(),
        ),
        (None, None) => bail!("a recording or --tuples is needed"),
    };
    if args.json {
        writeln!(out, "{}", calibration.to_json())?;
    } else {
        out.write_all(calibration.describe().as_bytes())?;
    }
    let Some(why) = calibration.untrusted() else {
        return Ok(ExitCode::SUCCESS);
    };
    eprintln!("hilsim: {}: {}: {why}", input.display(), method.name());
    Ok(ExitCode::from(1))
}

/// The calibration asked for by the flags, as given.
fn request(args: &CalibrateArgs) -> Request<'_> {
    Request {
        method: args.method,
        tuples: args.tuples.is_some(),
        beam_deg: args.beam,
        start_distance_m: args.start_distance,
        settle_s: args.settle_s,
        min_revolutions: args.min_revolutions,
        priors: &args.priors,
        wheel_radius_m: args.wheel_radius_m,
        interval_s: args.interval_s,
        lidar_latency_s: args.lidar_latency_s,
        lidar_model: args.lidar_model.as_deref(),
    }
}

/// The calibration of a recording directory, with a note for each key of its `meta.toml` the
/// recording format does not have.
fn calibrate_dir(dir: &Path, method: Method, settings: &Settings) -> Result<Calibration> {
    let rec = Recording::read_dir(dir)?;
    let mut calibration = hilsim_calibrator::calibrate_with(&rec, method, settings)
        .with_context(|| format!("{}: {}", dir.display(), method.name()))?;
    calibration.notes.extend(Meta::unknown_key_notes(dir));
    Ok(calibration)
}

/// Most bytes of a tuples file: 128 MiB, a million tuples of the paper's format.
const MAX_TUPLES_BYTES: u64 = 128 << 20;

/// The odometry calibration of a tuples file.
fn calibrate_tuples(path: &Path) -> Result<Calibration> {
    let text = hilsim_recording::read_small_text(path, MAX_TUPLES_BYTES, "tuples file")?;
    let origin = path.display().to_string();
    let (tuples, unsound) = odometry::parse_tuples(&text, &origin)?;
    odometry::calibrate_tuples(&tuples, unsound).with_context(|| format!("{origin}: odometry"))
}

/// Writes the smoothed distances; exit 1 when the recording fails a check against the
/// calibration (the distances are still written; the failed checks go to stderr).
pub fn smooth(args: &SmoothArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let target = request::target(args.beam, args.start_distance)?;
    if let Some(csv) = &args.csv {
        let mut inputs = Recording::files_in(&args.recording);
        inputs.push(args.calibration.clone());
        let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
        check_output_file(csv, hilsim_calibrator::SMOOTHED_CSV, &inputs)?;
    }
    let trained = smoothing::read_trained(&args.calibration)?;
    let rec = Recording::read_dir(&args.recording)?;
    let (estimates, checks) =
        smoothing::smooth_checked(&rec, &trained, &hilsim_calibrator::em_options(target))
            .with_context(|| format!("{}: smoothing", args.recording.display()))?;
    let csv = hilsim_calibrator::smoothed_csv(&estimates);
    match &args.csv {
        Some(path) => {
            write_file_atomically(path, csv.as_bytes())?;
            // With the table on standard output, the line saying so goes beside it.
            let mut stderr = std::io::stderr();
            let out: &mut dyn Write = if OutputTarget::is_stdout(path) {
                &mut stderr
            } else {
                out
            };
            let (n, recording) = (estimates.len(), args.recording.display());
            writeln!(
                out,
                "smoothed {n} samples of {recording} into {}",
                path.display()
            )?;
        }
        None => out.write_all(csv.as_bytes())?,
    }
    let failed: Vec<_> = checks.iter().filter(|c| !c.pass).collect();
    if failed.is_empty() {
        return Ok(ExitCode::SUCCESS);
    }
    for check in &failed {
        eprintln!("hilsim: check FAILED: {}: {}", check.name, check.detail);
    }
    eprintln!(
        "hilsim: {}: the recording does not fit the calibration ({} check(s) failed); the \
         distances are not to be trusted",
        args.recording.display(),
        failed.len()
    );
    Ok(ExitCode::from(1))
}
