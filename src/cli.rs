//! The command line as typed (clap derive). Validation into a run configuration happens in each
//! command before any file or port is opened.

use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};
use hilsim_recording::Method;

/// hilsim: robot distance sensors in the loop without the hardware.
///
/// Exit codes: 0 success; 1 a check or assertion failed; 2 bad input or usage.
#[derive(Debug, Parser)]
#[command(name = "hilsim", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a scenario, emulate its sensors, calibrate, summarise and check its assertions
    /// (the built-in straight-board scenario when none is given).
    Run(RunArgs),
    /// Simulate a scenario and write a recording, nothing else.
    Record(RecordArgs),
    /// Stream the emulated lidar over a serial link in the Neato XV-11 format.
    Serve(ServeArgs),
    /// Decode a lidar's raw byte stream (a capture file or a serial device path) into readings:
    /// the Neato XV-11's, or another unit's with `--model`.
    Decode(DecodeArgs),
    /// Calibrate the sensors from a recording.
    Calibrate(CalibrateArgs),
    /// Apply a trained calibration to a new recording with one smoother pass (EM paper, Sec. V).
    Smooth(SmoothArgs),
    /// Work with scenario files.
    #[command(subcommand)]
    Scenario(ScenarioCommand),
    /// Generate many seeded, varied runs of a scenario: resumable, shardable.
    Dataset(crate::commands::dataset::DatasetArgs),
    /// Run a firmware build in the loop with the lidar and robot command ports.
    Hil(crate::commands::hil::HilArgs),
    /// Compare a simulation with a real recording: locate the mismatch, name the physics the
    /// simulation left out, fit it and show the held-out improvement (or prove it blind with
    /// `--self-test N`).
    Diagnose(crate::commands::diagnose::DiagnoseArgs),
    /// Draw a recording as one self-contained HTML page: the world, the paths, the scans, each
    /// sensor's error against distance and the calibration.
    Report(ReportArgs),
    /// Turn a ROS 2 bag (MCAP or SQLite3, CDR), a ROS 1 bag (`.bag`), or a robot's log (CARMEN
    /// `.log`/`.clf`, CoreSLAM `.dat`), into a recording.
    Import(crate::commands::import::ImportArgs),
    /// Write a recording as ROS 2 messages in an MCAP file (Foxglove, RViz, `ros2 bag play`).
    Export(crate::commands::export::ExportArgs),
    /// Write a scenario that replays a recorded run in its world (the user's map, or one built
    /// from the run's scans): `hilsim record` on it makes the run's twin.
    World(crate::commands::world::WorldArgs),
}

#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Scenario file; default: the built-in straight-board run of the EM paper.
    pub scenario: Option<PathBuf>,
    /// Write the recording and the results (results.json) into this directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Seed of every random stream (default: the scenario's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// How the lidar data reaches the calibrator.
    #[arg(long, value_enum, default_value_t = Via::Memory)]
    pub via: Via,
    /// Print the results as one JSON object (`results.json`'s) instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Write the run's report (`index.html`: the world, the paths, the scans, the errors
    /// against distance, the calibration) into this directory.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Also write the run as ROS 2 messages in this MCAP file (as `hilsim export`).
    #[arg(long, value_name = "OUT")]
    pub mcap: Option<PathBuf>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Via {
    /// In-process.
    Memory,
    /// Neato packets through a pseudo-terminal and the decoder, as from a real robot.
    Serial,
}

#[derive(Debug, clap::Args)]
pub struct RecordArgs {
    /// Scenario file.
    pub scenario: PathBuf,
    /// The recording directory to write (replaced atomically when complete).
    #[arg(long)]
    pub out: PathBuf,
    /// Seed of every random stream (default: the scenario's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Also write the recording as ROS 2 messages in this MCAP file (as `hilsim export`).
    #[arg(long, value_name = "OUT")]
    pub mcap: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
pub struct ServeArgs {
    /// Scenario file.
    pub scenario: PathBuf,
    /// Create a pseudo-terminal pair and print the path a client should open (the default).
    #[arg(long, conflicts_with = "port")]
    pub pty: bool,
    /// Write to this existing serial device instead (opened 8N1 at the unit's speed: 115200 for
    /// the XV-11).
    #[arg(long, value_name = "PATH")]
    pub port: Option<PathBuf>,
    /// Pace the stream as a real unit would (the default).
    #[arg(long, conflicts_with = "fast")]
    pub realtime: bool,
    /// Stream as fast as the reader takes it: a client that reads loses nothing; one that takes
    /// nothing for 1 s loses whole revolutions (counted).
    #[arg(long)]
    pub fast: bool,
    /// Start the stream only once a client has opened the pty (the simulation waits for it).
    #[arg(long, conflicts_with = "port")]
    pub wait_for_client: bool,
    /// End with one JSON object on its own line (what was sent and dropped, the faults)
    /// instead of the summary line.
    #[arg(long)]
    pub json: bool,
    /// Seed of every random stream (default: the scenario's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
}

#[derive(Debug, clap::Args)]
pub struct DecodeArgs {
    /// A raw byte capture, or a serial device path.
    pub input: PathBuf,
    /// The unit whose protocol the bytes are in: xv11 (the default), rplidar-a1, lds-01,
    /// lds-02rr, ld06, ydlidar-x4, urg-04lx.
    #[arg(long, default_value = "xv11")]
    pub model: hilsim_sim::scenario::LidarModel,
    /// Write one CSV row per reading to this file.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Print one JSON object of counts.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, clap::Args)]
pub struct CalibrateArgs {
    /// A recording directory.
    #[arg(required_unless_present = "tuples")]
    pub recording: Option<PathBuf>,
    /// Odometry: the paper's tuples instead of a recording (a stream of JSON objects, each an
    /// interval's `T`, wheel speeds `phi_l`, `phi_r` in rad/s and the lidar's scan-matched
    /// motion `sm`: [x, y, theta]).
    #[arg(long, value_name = "FILE", conflicts_with = "recording")]
    pub tuples: Option<PathBuf>,
    /// The calibration method.
    #[arg(long, value_parser = method_parser())]
    pub method: Method,
    /// Print the result as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// The lidar beam facing the target, degrees in the lidar frame (EM, groundtruth; default 0).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub beam: Option<f64>,
    /// Lidar-to-target distance at t = 0 (default: `target_start_distance_m` of meta.toml).
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub start_distance: Option<f64>,
    /// Landmarks: the robot is at rest this long after its wheel commands go to zero (default:
    /// found from the odometry, else from the scans, else 0.3 s).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub settle_s: Option<f64>,
    /// Landmarks: a stop is used when it holds at least this many lidar revolutions at rest
    /// (default 2).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub min_revolutions: Option<f64>,
    /// EM: a Gaussian prior on a bias coefficient, e.g. `sonar.alpha1=1.028±0.003` (`+-` for
    /// `±`); repeatable. A prior on a scale (alpha1) lets EM estimate the drive's speed scale.
    #[arg(
        long = "prior",
        value_name = "SENSOR.COEF=VALUE±SD",
        allow_hyphen_values = true
    )]
    pub priors: Vec<String>,
    /// Odometry: the wheels' nominal radius the encoders' travel was reported with (default:
    /// `meta.toml`'s `[robot] wheel_radius_m`).
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    pub wheel_radius_m: Option<f64>,
    /// Odometry: the length of an interval between matched scans, seconds (default 1).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub interval_s: Option<f64>,
    /// Odometry: how late the lidar's stamps are against the encoders', seconds (default:
    /// estimated from the drive).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub lidar_latency_s: Option<f64>,
    /// Odometry: a calibration whose lidar model (`calibrate --json` of em, landmarks or
    /// groundtruth) turns each range back into a distance before the scans are matched: a
    /// lidar with a range bias measures its motion biased too.
    #[arg(long, value_name = "FILE")]
    pub lidar_model: Option<PathBuf>,
}

/// `--method`: the calibrator's methods by name (`hilsim_recording::Method`), each with its help.
fn method_parser() -> impl clap::builder::TypedValueParser<Value = Method> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new([
        PossibleValue::new(Method::Em.name()).help("Ground-truth-less EM with a Kalman smoother"),
        PossibleValue::new(Method::Landmarks.name()).help("Cylinders in unknown positions"),
        PossibleValue::new(Method::Groundtruth.name()).help("Fit against truth.csv"),
        PossibleValue::new(Method::Odometry.name())
            .help("Wheel radii, wheel base and the lidar's mount from an ordinary drive"),
    ])
    .try_map(|name| Method::from_name(&name).ok_or("not a method"))
}

#[derive(Debug, clap::Args)]
pub struct SmoothArgs {
    /// A recording directory.
    pub recording: PathBuf,
    /// A calibration as printed by `hilsim calibrate --json`.
    #[arg(long, value_name = "FILE")]
    pub calibration: PathBuf,
    /// Write `t_s,distance_m,sd_m` here (atomically) instead of to stdout.
    #[arg(long, value_name = "OUT")]
    pub csv: Option<PathBuf>,
    /// The lidar beam facing the target, degrees (default 0).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub beam: Option<f64>,
    /// Lidar-to-target distance at t = 0 (default: meta.toml).
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub start_distance: Option<f64>,
}

#[derive(Debug, Subcommand)]
pub enum ScenarioCommand {
    /// Run scenario files and check their [[expect]] assertions.
    Test(ScenarioTestArgs),
}

#[derive(Debug, clap::Args)]
pub struct ScenarioTestArgs {
    /// Scenario files or directories of them (`*.toml`, searched recursively); default
    /// `scenarios/`.
    pub paths: Vec<PathBuf>,
    /// Print the results as one JSON object instead of a line per scenario.
    #[arg(long)]
    pub json: bool,
    /// Also write the results as JUnit XML (a test suite per scenario, a test case per
    /// assertion) for CI systems.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
}

/// Draw a recording: the world, the paths, the scans, each sensor's error against distance
/// and the calibration, as one self-contained HTML page.
#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    /// The recording directory.
    pub recording: PathBuf,
    /// The scenario the recording is a run of: its world is drawn and its declared sensor
    /// models shown.
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// A calibration to show: the JSON of `hilsim calibrate --json`, or a run's `results.json`
    /// (default: RECORDING/results.json when there is one).
    #[arg(long)]
    pub calibration: Option<PathBuf>,
    /// The directory to write `index.html` into (created if needed; a previous report's page is
    /// replaced, anything else refused).
    #[arg(long)]
    pub out: PathBuf,
}

/// A clap error as one line (`<what>; see hilsim <cmd> --help`), as every other error is, for
/// scripts that read one line of stderr. Values the user typed are shown terminal-safe.
pub fn usage_error_line(err: &clap::Error, args: &[std::ffi::OsString]) -> String {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    let (path, cmd) = command_path(args);
    let text = |kind| match err.get(kind) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        Some(ContextValue::Strings(v)) if !v.is_empty() => Some(v.join(", ")),
        Some(ContextValue::StyledStr(s)) => Some(s.to_string()),
        _ => None,
    };
    let typed = |kind| text(kind).map(|s| hilsim_recording::printable(&s).into_owned());
    let valid = text(ContextKind::ValidValue)
        .map(|v| format!(" (expected one of: {v})"))
        .unwrap_or_default();
    let suggestion = text(ContextKind::SuggestedArg)
        .or_else(|| text(ContextKind::SuggestedSubcommand))
        .map(|s| format!(" (did you mean `{s}`?)"))
        .unwrap_or_default();
    let what = match (
        err.kind(),
        text(ContextKind::InvalidArg),
        typed(ContextKind::InvalidValue),
    ) {
        (ErrorKind::MissingRequiredArgument, Some(arg), _) => format!("missing {arg}"),
        (ErrorKind::InvalidValue, Some(arg), Some(value)) if value.is_empty() => {
            format!("{arg}: a value is required{valid}")
        }
        (ErrorKind::InvalidValue, Some(arg), Some(value)) => {
            format!("{arg}: invalid value `{value}`{valid}")
        }
        (ErrorKind::ValueValidation, Some(arg), Some(value)) => {
            let why = std::error::Error::source(err)
                .map(|e| format!(": {e}"))
                .unwrap_or_default();
            format!("{arg}: invalid value `{value}`{why}")
        }
        (ErrorKind::UnknownArgument, _, _) => match typed(ContextKind::InvalidArg) {
            Some(arg) if arg.starts_with('-') => format!("unknown option `{arg}`{suggestion}"),
            Some(arg) => format!("unexpected argument `{arg}`{suggestion}"),
            None => "unexpected argument".to_string(),
        },
        (ErrorKind::InvalidSubcommand, _, _) => match typed(ContextKind::InvalidSubcommand) {
            Some(sub) => format!("unknown command `{sub}`{suggestion}"),
            None => "unknown command".to_string(),
        },
        (
            ErrorKind::MissingSubcommand | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand,
            _,
            _,
        ) => {
            let subs: Vec<&str> = cmd
                .get_subcommands()
                .map(clap::Command::get_name)
                .filter(|name| *name != "help")
                .collect();
            format!("missing a command (one of: {})", subs.join(", "))
        }
        (ErrorKind::ArgumentConflict, Some(arg), _) => match text(ContextKind::PriorArg) {
            Some(prior) if prior == arg => format!("{arg} given more than once"),
            Some(prior) => format!("{arg} cannot be used with {prior}"),
            None => format!("{arg} cannot be used with the other arguments given"),
        },
        // Anything else: clap's own wording, its lines joined, without the usage block.
        _ => err
            .render()
            .to_string()
            .lines()
            .map(str::trim)
            .filter(|l| {
                !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more information")
            })
            .map(|l| l.strip_prefix("error: ").unwrap_or(l))
            .collect::<Vec<_>>()
            .join(" ")
            .replace('\n', " "),
    };
    format!("{what}; see {path} --help")
}

/// `hilsim` followed by the subcommands named in `args` (`hilsim dataset merge`), and the last
/// of them.
fn command_path(args: &[std::ffi::OsString]) -> (String, clap::Command) {
    use clap::CommandFactory;
    let mut cmd = Cli::command();
    let mut path = String::from("hilsim");
    for arg in args.iter().skip(1) {
        let Some(arg) = arg.to_str() else { break };
        if arg.starts_with('-') {
            continue;
        }
        let Some(sub) = cmd.find_subcommand(arg).cloned() else {
            break;
        };
        path.push(' ');
        path.push_str(sub.get_name());
        cmd = sub;
    }
    (path, cmd)
}
