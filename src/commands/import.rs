//! `hilsim import BAG --out DIR [--meta FILE] [--lidar T] [--odom T] [--cmd T] [--sonar T]
//! [--truth T] [--wheel-radius-m R] [--wheel-joints LEFT,RIGHT]`: a ROS 2 bag (MCAP or SQLite3)
//! into a recording.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use hilsim_recording::Meta;
use hilsim_ros2::{ImportOptions, Role};

#[derive(Debug, clap::Args)]
pub struct ImportArgs {
    /// A ROS 2 bag: an `.mcap` or `.db3` file, or a bag directory (`metadata.yaml` and its files).
    pub bag: PathBuf,
    /// The recording directory to write (replaced atomically when complete).
    #[arg(long)]
    pub out: PathBuf,
    /// The robot's `meta.toml` (wheel base, sensor mounts, what is known of the world); default:
    /// a minimal one, said so.
    #[arg(long, value_name = "FILE")]
    pub meta: Option<PathBuf>,
    /// The lidar's topic (sensor_msgs/LaserScan).
    #[arg(long, value_name = "TOPIC")]
    pub lidar: Option<String>,
    /// The odometer's topic (nav_msgs/Odometry, or sensor_msgs/JointState with
    /// --wheel-radius-m).
    #[arg(long, value_name = "TOPIC")]
    pub odom: Option<String>,
    /// The commands' topic (geometry_msgs/Twist or TwistStamped).
    #[arg(long, value_name = "TOPIC")]
    pub cmd: Option<String>,
    /// The sonar's topic (sensor_msgs/Range).
    #[arg(long, value_name = "TOPIC")]
    pub sonar: Option<String>,
    /// The true pose's topic (geometry_msgs/PoseStamped, or a motion capture's
    /// nav_msgs/Odometry).
    #[arg(long, value_name = "TOPIC")]
    pub truth: Option<String>,
    /// The wheels' radius, metres: wheel joint angles (JointState) times it are wheel travel.
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub wheel_radius_m: Option<f64>,
    /// The left and right wheels' joints in JointState (default: the joints named `…left…` and
    /// `…right…`).
    #[arg(long, value_name = "LEFT,RIGHT")]
    pub wheel_joints: Option<String>,
}

pub fn import(args: &ImportArgs, out: &mut dyn Write) -> Result<()> {
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
    let mut topics = BTreeMap::new();
    for (role, topic) in [
        (Role::Lidar, &args.lidar),
        (Role::Odometry, &args.odom),
        (Role::Commands, &args.cmd),
        (Role::Sonar, &args.sonar),
        (Role::Truth, &args.truth),
    ] {
        if let Some(topic) = topic {
            topics.insert(role, topic.clone());
        }
    }
    let options = ImportOptions {
        topics,
        meta,
        wheel_radius_m: args.wheel_radius_m,
        wheel_joints,
    };
    // The bag is read while the recording is written: it must not be inside what is replaced.
    hilsim_recording::check_input_outside(&args.bag, &args.out)?;
    hilsim_recording::tidy_after_killed_writers(&args.out)?;
    let report = hilsim_ros2::import(&args.bag, &args.out, &options)?;
    for (role, (topic, kind)) in &report.chosen {
        let rows = report.rows.get(role).copied().unwrap_or(0);
        writeln!(
            out,
            "{role:<9} {} ({}): {rows} rows",
            hilsim_recording::printable(topic),
            kind.ros_name()
        )?;
    }
    for note in &report.notes {
        writeln!(out, "note: {note}")?;
    }
    writeln!(out, "wrote {}", args.out.display())?;
    Ok(())
}
