//! `hilsim import BAG --out DIR [--meta FILE] [--lidar T] [--odom T] [--cmd T] [--sonar T]
//! [--truth T] [--wheel-radius-m R] [--wheel-joints LEFT,RIGHT]`: a ROS 2 bag (MCAP or SQLite3)
//! or a ROS 1 bag (`.bag`) into a recording, the lidar's mount from its TF; `hilsim import LOG
//! --out DIR [--poses truth|odometry]`: a real robot's log (CARMEN `.log`/`.clf`, gzipped or
//! not; CoreSLAM `.dat`) into a recording.

use std::collections::BTreeMap;
use std::io::Write;

use anyhow::{bail, Result};
use hilsim_logs::{CarmenOptions, LogKind, Poses};
use hilsim_recording::{check_input_outside, tidy_after_killed_writers, Meta};
use hilsim_ros2::{ImportOptions, Role};

use crate::cli::ImportArgs;

/// A robot's log into a recording.
fn import_log(args: &ImportArgs, kind: LogKind, out: &mut dyn Write) -> Result<()> {
    let bag_only = [
        ("--meta", args.meta.is_some()),
        ("--lidar", args.lidar.is_some()),
        ("--odom", args.odom.is_some()),
        ("--cmd", args.cmd.is_some()),
        ("--sonar", args.sonar.is_some()),
        ("--truth", args.truth.is_some()),
        ("--wheel-radius-m", args.wheel_radius_m.is_some()),
        ("--wheel-joints", args.wheel_joints.is_some()),
    ];
    if let Some((flag, _)) = bag_only.iter().find(|(_, given)| *given) {
        bail!(
            "{flag} is for ROS bags; {} is a robot's log",
            args.bag.display()
        );
    }
    if kind == LogKind::CoreSlam && args.log_poses.is_some() {
        bail!("--poses is for CARMEN logs; a CoreSLAM log has encoder counts, not poses");
    }
    let carmen = CarmenOptions {
        poses: match args.log_poses.as_deref() {
            Some("odometry") => Poses::Odometry,
            _ => Poses::Truth,
        },
        ..CarmenOptions::default()
    };
    check_input_outside(&args.bag, &args.out)?;
    let log = hilsim_logs::read_log(&args.bag, kind, &carmen)?;
    tidy_after_killed_writers(&args.out)?;
    log.recording.write_dir(&args.out)?;
    log.write_summary(out)?;
    writeln!(out, "wrote {}", args.out.display())?;
    Ok(())
}

pub fn import(args: &ImportArgs, out: &mut dyn Write) -> Result<()> {
    if let Some(kind) = LogKind::of(&args.bag) {
        return import_log(args, kind, out);
    }
    if args.log_poses.is_some() {
        bail!(
            "--poses is for CARMEN logs; {} is a ROS bag",
            args.bag.display()
        );
    }
    if args
        .wheel_radius_m
        .is_some_and(|r| !(r.is_finite() && r > 0.0 && r <= 10.0))
    {
        bail!("--wheel-radius-m: expected a radius in metres, above 0 and at most 10");
    }
    let wheel_joints = match args
        .wheel_joints
        .as_deref()
        .map(|j| j.split(',').collect::<Vec<_>>())
    {
        None => None,
        Some(names) => match names.as_slice() {
            [left, right] if !left.is_empty() && !right.is_empty() && left != right => {
                Some([(*left).to_string(), (*right).to_string()])
            }
            _ => bail!("--wheel-joints: expected LEFT,RIGHT, two different joint names"),
        },
    };
    let meta = args.meta.as_deref().map(Meta::read).transpose()?;
    let topics: BTreeMap<Role, String> = [
        (Role::Lidar, &args.lidar),
        (Role::Odometry, &args.odom),
        (Role::Commands, &args.cmd),
        (Role::Sonar, &args.sonar),
        (Role::Truth, &args.truth),
    ]
    .into_iter()
    .filter_map(|(role, topic)| Some((role, topic.clone()?)))
    .collect();
    let options = ImportOptions {
        topics,
        meta,
        wheel_radius_m: args.wheel_radius_m,
        wheel_joints,
    };
    // The bag is read while the recording is written: it must not be inside what is replaced.
    check_input_outside(&args.bag, &args.out)?;
    tidy_after_killed_writers(&args.out)?;
    let report = hilsim_ros2::import(&args.bag, &args.out, &options)?;
    report.write_summary(out)?;
    writeln!(out, "wrote {}", args.out.display())?;
    Ok(())
}
