//! `hilsim import BAG --out DIR [--meta FILE] [--lidar T] [--odom T] [--cmd T] [--sonar T]
//! [--truth T] [--wheel-radius-m R] [--wheel-joints LEFT,RIGHT]`: a ROS 2 bag (MCAP or SQLite3)
//! or a ROS 1 bag (`.bag`) into a recording, the lidar's mount from its TF; `hilsim import LOG --out DIR [--poses truth|odometry]`: a real robot's
//! log (CARMEN `.log`/`.clf`, gzipped or not; CoreSLAM `.dat`) into a recording.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use hilsim_recording::Meta;
use hilsim_ros2::{ImportOptions, Role};

#[derive(Debug, clap::Args)]
pub struct ImportArgs {
    /// A ROS 2 bag: an `.mcap` or `.db3` file, or a bag directory (`metadata.yaml` and its files);
    /// a ROS 1 bag (`.bag`, rosbag format 2.0; chunks uncompressed, bz2 or lz4); or a robot's
    /// log: CARMEN (`.log`, `.clf`, either gzipped: `.gz`) or CoreSLAM (`.dat`). A bag's
    /// `/tf_static` (else `/tf`) gives the lidar's mount unless --meta has one, and `/tf`'s odom →
    /// base transforms the odometry when the bag has no odometry topic; each guess is a note.
    pub bag: PathBuf,
    /// The recording directory to write (replaced atomically when complete).
    #[arg(long)]
    pub out: PathBuf,
    /// The robot's `meta.toml` (wheel base, sensor mounts, what is known of the world); its
    /// `[lidar]` mount overrides the bag's TF. Default: a minimal one (the wheel base a guess),
    /// said so.
    #[arg(long, value_name = "FILE")]
    pub meta: Option<PathBuf>,
    /// The lidar's topic (sensor_msgs/LaserScan).
    #[arg(long, value_name = "TOPIC")]
    pub lidar: Option<String>,
    /// The odometer's topic (nav_msgs/Odometry; sensor_msgs/JointState with --wheel-radius-m;
    /// or tf2_msgs/TFMessage, its odom → base transforms).
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
    /// What a CARMEN log's poses are: `truth` (a corrected log's: truth.csv) or `odometry`
    /// (odometry.csv, as wheel travel); default truth. (`--log-poses` is the same.)
    #[arg(long = "poses", alias = "log-poses", value_name = "KIND", value_parser = ["truth", "odometry"])]
    pub log_poses: Option<String>,
}

/// The kinds of robot log `import` reads besides ROS 2 bags, by the file's name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LogKind {
    Carmen,
    CoreSlam,
}

fn log_kind(path: &std::path::Path) -> Option<LogKind> {
    let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    if name.ends_with(".log") || name.ends_with(".clf") {
        Some(LogKind::Carmen)
    } else if name.ends_with(".dat") {
        Some(LogKind::CoreSlam)
    } else if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"))
    {
        // A gzipped file of another name: CARMEN's logger is the one that writes them.
        Some(LogKind::Carmen)
    } else {
        None
    }
}

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
    hilsim_recording::check_input_outside(&args.bag, &args.out)?;
    let text = hilsim_logs::read_text(&args.bag)?;
    let origin = args.bag.display().to_string();
    let (rec, notes) = match kind {
        LogKind::CoreSlam => (
            hilsim_logs::read_coreslam(&text, &origin, &hilsim_logs::CoreSlamOptions::default())?,
            Vec::new(),
        ),
        LogKind::Carmen => {
            let options = hilsim_logs::CarmenOptions {
                poses: match args.log_poses.as_deref() {
                    Some("odometry") => hilsim_logs::Poses::Odometry,
                    _ => hilsim_logs::Poses::Truth,
                },
                ..hilsim_logs::CarmenOptions::default()
            };
            hilsim_logs::read_carmen(&text, &origin, &options)?
        }
    };
    drop(text);
    hilsim_recording::tidy_after_killed_writers(&args.out)?;
    rec.write_dir(&args.out)?;
    let lidar = rec.lidar.as_deref().unwrap_or_default();
    writeln!(
        out,
        "lidar     {} scans: {} rows",
        lidar.last().map_or(0, |s| s.rev + 1),
        lidar.len()
    )?;
    for (name, rows) in [
        ("odometry", rec.odometry.as_ref().map(Vec::len)),
        ("truth", rec.truth.as_ref().map(Vec::len)),
    ] {
        if let Some(rows) = rows {
            writeln!(out, "{name:<9} {rows} rows")?;
        }
    }
    for note in &notes {
        writeln!(out, "note: {note}")?;
    }
    writeln!(out, "wrote {}", args.out.display())?;
    Ok(())
}

pub fn import(args: &ImportArgs, out: &mut dyn Write) -> Result<()> {
    if let Some(kind) = log_kind(&args.bag) {
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
