//! The odometry calibration on a real rover's drive: the CoreSLAM data set (Steux and El
//! Hamzaoui, ICARCV 2010; `exp1.dat` as shipped with BreezySLAM's examples), a wheeled rover with
//! a Hokuyo URG-04LX mounted 145 mm ahead of its axle:
//!
//! ```text
//! cargo run --release -p hilsim-calibrator --example odometry_on_coreslam -- exp1.dat
//! ```
//!
//! reads the log into a recording, calibrates it, then asks whether the calibrated geometry
//! predicts the scan-matched motion better than the nominal one on data it was not fitted to:
//! it calibrates on one half of the drive and, on the other half, prints the RMS of the
//! predicted minus the scan-matched lidar motion of each interval and the drift of the
//! dead-reckoned lidar path from the scan-matched one, for both geometries; then the halves
//! swapped, and how far the two halves' calibrations differ in their standard deviations.
//!
//! Options: `--lidar-latency-s S` takes the scans to be S seconds older than their line's
//! encoder counts (default: the calibration estimates it; see below); `--interval-s S` sets the
//! intervals' length (default the
//! calibration's, 1 s); `--first-beam-left` reads the beams the other way round (the first at
//! +120°), to show that the scan matcher's turns then disagree with the wheels'.
//!
//! The log is read by `hilsim_logs::read_coreslam`, whose documentation gives the log's
//! conventions and where each comes from. The log does not say when its timestamp was taken
//! relative to the encoder counts on the line; the calibration estimates the lidar's latency
//! against the encoders from the turns, and on `exp1.dat` finds the scans about 0.19 s older
//! than the counts on their line, about two scans (with the latency held at 0 the turn's
//! residual spread, the "scan matcher's error" it prints, is 99 mrad instead of 22).

use std::process::ExitCode;

use hilsim_calibrator::odometry::{
    calibrate, calibrate_intervals, drive_intervals, kinematics::residual, DriveIntervals,
    Geometry, Interval, RecordingOptions,
};
use hilsim_calibrator::scan_match::MatchFailure;
use hilsim_calibrator::OdometryModel;
use hilsim_logs::{read_coreslam, CoreSlamOptions};
use hilsim_recording::Pose;

/// An interval turns "clearly" when the wheels say it turned by more than 3° (50 mrad), well
/// above the scan matcher's milliradians, so that the sign of its turn is not noise.
const CLEAR_TURN_RAD: f64 = 0.05;
/// An interval drives "clearly" when the wheels say it moved more than 5 cm.
const CLEAR_TRAVEL_M: f64 = 0.05;

/// What the command line asks.
struct Args {
    path: String,
    options: RecordingOptions,
    first_beam_left: bool,
}

const USAGE: &str =
    "usage: odometry_on_coreslam EXP1.DAT [--lidar-latency-s S] [--interval-s S] [--first-beam-left]";

fn main() -> ExitCode {
    let args = match parse_args(std::env::args().skip(1)) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("odometry_on_coreslam: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("odometry_on_coreslam: {e}");
            ExitCode::from(2)
        }
    }
}

fn parse_args(mut args: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut path = None;
    let mut out = Args {
        path: String::new(),
        options: RecordingOptions::default(),
        first_beam_left: false,
    };
    while let Some(arg) = args.next() {
        let mut seconds = |name: &str| -> Result<f64, String> {
            let v = args
                .next()
                .ok_or(format!("{name} needs a number of seconds"))?;
            v.parse::<f64>()
                .ok()
                .filter(|s| s.is_finite() && *s >= 0.0)
                .ok_or(format!(
                    "{name}: `{v}` is not a number of seconds (0 or more)"
                ))
        };
        match arg.as_str() {
            "--lidar-latency-s" => {
                out.options.lidar_latency_s = Some(seconds("--lidar-latency-s")?);
            }
            "--interval-s" => out.options.interval_s = seconds("--interval-s")?,
            "--first-beam-left" => out.first_beam_left = true,
            _ if path.is_none() && !arg.starts_with("--") => path = Some(arg),
            _ => return Err(format!("unexpected argument `{arg}`")),
        }
    }
    out.path = path.ok_or("no log given")?;
    Ok(out)
}

fn run(args: &Args) -> Result<(), String> {
    let path = &args.path;
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let options = CoreSlamOptions {
        first_beam_left: args.first_beam_left,
        ..CoreSlamOptions::default()
    };
    let rec = read_coreslam(&text, path, &options).map_err(|e| e.to_string())?;
    let scans = rec.odometry.as_deref().unwrap_or_default();
    let calibration = calibrate(&rec, &args.options).map_err(|e| format!("{path}: {e}"))?;
    println!(
        "{path}: {} scans over {:.1} s; intervals of {} s{}",
        scans.len(),
        scans.last().map_or(0.0, |s| s.t_s),
        args.options.interval_s,
        if args.first_beam_left {
            "; the beams read clockwise (first at +120°)"
        } else {
            ""
        }
    );
    print!("{}", calibration.describe());

    let drive = drive_intervals(&rec, &args.options).map_err(|e| format!("{path}: {e}"))?;
    println!();
    print_conventions(&drive);
    if let Some(m) = &calibration.odometry {
        let calibrated = Geometry {
            left_radius_m: m.left_wheel_radius_m,
            right_radius_m: m.right_wheel_radius_m,
            wheel_base_m: m.wheel_base_m,
            lidar: [m.lidar_x_m, m.lidar_y_m, m.lidar_yaw_rad],
        };
        println!();
        println!(
            "the whole drive ({} intervals), calibrated on itself:",
            drive.intervals.len()
        );
        println!(
            "  {:<11} {:>13} {:>14} {:>14} {:>15}",
            "geometry", "RMS transl mm", "RMS rot mrad", "end drift m", "end drift deg"
        );
        for (name, g) in [("nominal", &drive.nominal), ("calibrated", &calibrated)] {
            let s = score(g, &drive.intervals);
            println!(
                "  {name:<11} {:>13.1} {:>14.1} {:>14.3} {:>15.2}",
                s.rms_translation_m * 1e3,
                s.rms_rotation_rad * 1e3,
                s.end_drift_m,
                s.end_drift_rad.to_degrees()
            );
        }
    }
    let [first, second] = halves(&drive);
    println!();
    let a = held_out("first", &first, "second", &second, &drive.nominal)?;
    println!();
    let b = held_out("second", &second, "first", &first, &drive.nominal)?;
    println!();
    print_agreement(&a, &b);
    Ok(())
}

/// The drive's intervals, and whether the scan matcher and the wheels agree on the sign of
/// each clear turn and each clear drive: the check of the conventions.
fn print_conventions(drive: &DriveIntervals) {
    let mut kinds = [0usize; 3];
    for f in &drive.failed {
        kinds[match f {
            MatchFailure::NotConverged { .. } => 0,
            MatchFailure::Degenerate { .. } => 1,
            _ => 2,
        }] += 1;
    }
    println!(
        "intervals: {} matched, {} failed to match ({} did not settle, {} geometry did not fix \
         the motion, {} other), {} standing still, {} gaps, {} sparse ({} revolutions)",
        drive.intervals.len(),
        drive.failed.len(),
        kinds[0],
        kinds[1],
        kinds[2],
        drive.still,
        drive.gaps,
        drive.sparse,
        drive.revolutions
    );
    let (mut turns, mut turns_agree, mut drives, mut drives_agree) = (0, 0, 0, 0);
    for t in &drive.intervals {
        let wheels = drive.nominal.robot_motion(&t.wheel_turns_rad);
        let [l, r] = t.total_turns_rad();
        let travel = (l + r) / 2.0 * drive.nominal.left_radius_m;
        if wheels[2].abs() > CLEAR_TURN_RAD {
            turns += 1;
            turns_agree += usize::from(wheels[2].signum() == t.lidar_motion[2].signum());
        }
        if travel.abs() > CLEAR_TRAVEL_M {
            drives += 1;
            drives_agree += usize::from(travel.signum() == t.lidar_motion[0].signum());
        }
    }
    println!(
        "conventions: the scan-matched turn has the wheels' sign in {turns_agree} of {turns} \
         intervals turning more than {:.0}°; the scan-matched forward motion has the wheels' \
         sign in {drives_agree} of {drives} intervals moving more than {:.0} cm",
        CLEAR_TURN_RAD.to_degrees(),
        CLEAR_TRAVEL_M * 100.0
    );
}

/// The matched intervals of the drive's first and second halves in time (an interval belongs
/// to the half its start lies in).
fn halves(drive: &DriveIntervals) -> [Vec<Interval>; 2] {
    let (Some(start), Some(end)) = (drive.spans_s.first(), drive.spans_s.last()) else {
        return [Vec::new(), Vec::new()];
    };
    let middle = (start[0] + end[1]) / 2.0;
    let mut out = [Vec::new(), Vec::new()];
    for (t, span) in drive.intervals.iter().zip(&drive.spans_s) {
        out[usize::from(span[0] >= middle)].push(t.clone());
    }
    out
}

/// Calibrates on `fit` and prints how the nominal and the calibrated geometry predict `test`;
/// the calibration of `fit`.
fn held_out(
    fit_name: &str,
    fit: &[Interval],
    test_name: &str,
    test: &[Interval],
    nominal: &Geometry,
) -> Result<OdometryModel, String> {
    let calibration =
        calibrate_intervals(fit).map_err(|e| format!("calibrating on the {fit_name} half: {e}"))?;
    let Some(m) = calibration.odometry else {
        return Err(format!("the {fit_name} half's calibration has no odometry"));
    };
    let calibrated = Geometry {
        left_radius_m: m.left_wheel_radius_m,
        right_radius_m: m.right_wheel_radius_m,
        wheel_base_m: m.wheel_base_m,
        lidar: [m.lidar_x_m, m.lidar_y_m, m.lidar_yaw_rad],
    };
    let failed: Vec<&str> = calibration
        .checks
        .iter()
        .filter(|c| !c.pass)
        .map(|c| c.name.as_str())
        .collect();
    let travelled: f64 = test
        .iter()
        .map(|t| t.lidar_motion[0].hypot(t.lidar_motion[1]))
        .sum();
    println!(
        "calibrated on the {fit_name} half ({} intervals; checks failed: {}), tested on the \
         {test_name} half ({} intervals, {travelled:.1} m of lidar travel)",
        fit.len(),
        if failed.is_empty() {
            "none".to_string()
        } else {
            failed.join(", ")
        },
        test.len()
    );
    let sd = m.standard_deviations();
    // The radii's ratio sets the dead-reckoned heading's drift per metre driven straight.
    let ratio = m.right_wheel_radius_m / m.left_wheel_radius_m;
    let ratio_sd = ratio
        * (m.covariance[0][0] / m.left_wheel_radius_m.powi(2)
            + m.covariance[1][1] / m.right_wheel_radius_m.powi(2)
            - 2.0 * m.covariance[0][1] / (m.left_wheel_radius_m * m.right_wheel_radius_m))
            .max(0.0)
            .sqrt();
    println!(
        "  calibrated: radii {:.2} ± {:.2} / {:.2} ± {:.2} mm (right over left {ratio:.4} ± \
         {ratio_sd:.4}), wheel base {:.1} ± {:.1} mm, lidar ({:.1} ± {:.1}, {:.1} ± {:.1}) mm \
         {:.1} ± {:.1} mrad",
        m.left_wheel_radius_m * 1e3,
        sd[0] * 1e3,
        m.right_wheel_radius_m * 1e3,
        sd[1] * 1e3,
        m.wheel_base_m * 1e3,
        sd[2] * 1e3,
        m.lidar_x_m * 1e3,
        sd[3] * 1e3,
        m.lidar_y_m * 1e3,
        sd[4] * 1e3,
        m.lidar_yaw_rad * 1e3,
        sd[5] * 1e3
    );
    println!(
        "  {:<11} {:>13} {:>14} {:>14} {:>15}",
        "geometry", "RMS transl mm", "RMS rot mrad", "end drift m", "end drift deg"
    );
    let mut least_rms_rotation = f64::INFINITY;
    for (name, g) in [("nominal", nominal), ("calibrated", &calibrated)] {
        let s = score(g, test);
        least_rms_rotation = least_rms_rotation.min(s.rms_rotation_rad);
        println!(
            "  {name:<11} {:>13.1} {:>14.1} {:>14.3} {:>15.2}",
            s.rms_translation_m * 1e3,
            s.rms_rotation_rad * 1e3,
            s.end_drift_m,
            s.end_drift_rad.to_degrees()
        );
    }
    // Independent errors of the turns add up as a random walk: the heading drift that the
    // intervals' scatter alone would leave, whatever the geometry.
    println!(
        "  (the intervals' scatter alone leaves the end heading about ±{:.1}° off: √{} × the \
         smaller RMS rotation)",
        (least_rms_rotation * (test.len() as f64).sqrt()).to_degrees(),
        test.len()
    );
    Ok(m)
}

/// How far apart the two halves' calibrations are, each parameter in the standard deviations
/// of the difference (the halves' covariances added: their intervals do not overlap).
fn print_agreement(a: &OdometryModel, b: &OdometryModel) {
    let (pa, pb) = (a.parameters(), b.parameters());
    let parts: Vec<String> = [
        "left radius",
        "right radius",
        "wheel base",
        "lidar x",
        "lidar y",
        "lidar yaw",
    ]
    .iter()
    .enumerate()
    .map(|(i, name)| {
        let sd = (a.covariance[i][i] + b.covariance[i][i]).max(0.0).sqrt();
        format!("{name} {:+.1}", (pb[i] - pa[i]) / sd)
    })
    .collect();
    println!(
        "the halves' calibrations differ (second minus first, in standard deviations of the \
         difference): {}",
        parts.join(", ")
    );
}

/// How a geometry predicts the scan-matched motion of intervals.
struct Score {
    /// RMS over the intervals of the predicted minus the scan-matched lidar translation.
    rms_translation_m: f64,
    /// The same of the turn.
    rms_rotation_rad: f64,
    /// How far the dead-reckoned lidar path ends from the scan-matched one.
    end_drift_m: f64,
    /// The dead-reckoned path's heading at the end minus the scan-matched one's.
    end_drift_rad: f64,
}

/// `g`'s predictions of `intervals`' lidar motions against the scan-matched ones. The paths
/// are the lidar's (the scan matcher's own frame, the same reference for every geometry), each
/// the matched intervals' motions composed in order: an interval left out (a failed match, a
/// gap) is left out of both.
fn score(g: &Geometry, intervals: &[Interval]) -> Score {
    let (mut translation, mut rotation) = (0.0, 0.0);
    let (mut predicted_path, mut matched_path) = (Pose::default(), Pose::default());
    let (mut predicted_turn, mut matched_turn) = (0.0, 0.0);
    for t in intervals {
        let predicted = g.lidar_motion(g.robot_motion(&t.wheel_turns_rad));
        let [dx, dy, dtheta] = residual(predicted, t.lidar_motion);
        translation += dx * dx + dy * dy;
        rotation += dtheta * dtheta;
        predicted_path = predicted_path.compose(predicted[0], predicted[1], predicted[2]);
        let [x, y, theta] = t.lidar_motion;
        matched_path = matched_path.compose(x, y, theta);
        predicted_turn += predicted[2];
        matched_turn += theta;
    }
    let n = intervals.len().max(1) as f64;
    Score {
        rms_translation_m: (translation / n).sqrt(),
        rms_rotation_rad: (rotation / n).sqrt(),
        end_drift_m: (predicted_path.x - matched_path.x).hypot(predicted_path.y - matched_path.y),
        end_drift_rad: predicted_turn - matched_turn,
    }
}
