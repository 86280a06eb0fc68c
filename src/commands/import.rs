//! `hilsim import BAG --out DIR [--meta FILE] [--lidar T] [--odom T] [--cmd T] [--sonar T]
//! [--truth T] [--wheel-radius-m R] [--wheel-joints LEFT,RIGHT]`: a ROS 2 bag (MCAP or SQLite3)
//! or a ROS 1 bag (`.bag`) into a recording, the lidar's mount from its TF; `hilsim import LOG
//! --out DIR [--poses truth|odometry]`: a real robot's log (CARMEN `.log`/`.clf`, gzipped or
//! not; CoreSLAM `.dat`) into a recording.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Result};
use hilsim_logs::LogKind;
use hilsim_recording::{check_input_outside, tidy_after_killed_writers, Meta};
use hilsim_ros2::ImportFlags;

use crate::cli::ImportArgs;

/// A robot's log into a recording.
fn import_log(args: &ImportArgs, kind: LogKind, out: &mut dyn Write) -> Result<ExitCode> {
    let given = [
        (args.meta.is_some()).then_some("--meta"),
        flags(args).first_given(),
    ];
    if let Some(flag) = given.into_iter().flatten().next() {
        bail!(
            "{flag} is for ROS bags; {} is a robot's log",
            args.bag.display()
        );
    }
    let log = hilsim_logs::import_log(&args.bag, kind, args.log_poses.as_deref(), &args.out)?;
    log.write_summary(out)?;
    writeln!(out, "wrote {}", args.out.display())?;
    Ok(ExitCode::SUCCESS)
}

/// The flags only a bag's import reads.
fn flags(args: &ImportArgs) -> ImportFlags<'_> {
    ImportFlags {
        lidar: args.lidar.as_deref(),
        odom: args.odom.as_deref(),
        cmd: args.cmd.as_deref(),
        sonar: args.sonar.as_deref(),
        truth: args.truth.as_deref(),
        wheel_radius_m: args.wheel_radius_m,
        wheel_joints: args.wheel_joints.as_deref(),
    }
}

pub fn import(args: &ImportArgs, out: &mut dyn Write) -> Result<ExitCode> {
    if let Some(kind) = LogKind::of(&args.bag) {
        return import_log(args, kind, out);
    }
    if args.log_poses.is_some() {
        bail!(
            "--poses is for CARMEN logs; {} is a ROS bag",
            args.bag.display()
        );
    }
    let mut options = flags(args).options()?;
    options.meta = args.meta.as_deref().map(Meta::read).transpose()?;
    // The bag is read while the recording is written: it must not be inside what is replaced.
    check_input_outside(&args.bag, &args.out)?;
    tidy_after_killed_writers(&args.out)?;
    let report = hilsim_ros2::import(&args.bag, &args.out, &options)?;
    report.write_summary(out)?;
    writeln!(out, "wrote {}", args.out.display())?;
    Ok(ExitCode::SUCCESS)
}
