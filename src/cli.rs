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
    Dataset(DatasetArgs),
    /// Run a firmware build in the loop with the lidar and robot command ports.
    Hil(HilArgs),
    /// Compare a simulation with a real recording: locate the mismatch, name the physics the
    /// simulation left out, fit it and show the held-out improvement (or prove it blind with
    /// `--self-test N`).
    Diagnose(DiagnoseArgs),
    /// Draw a recording as one self-contained HTML page: the world, the paths, the scans, each
    /// sensor's error against distance and the calibration.
    Report(ReportArgs),
    /// Turn a ROS 2 bag (MCAP or SQLite3, CDR), a ROS 1 bag (`.bag`), or a robot's log (CARMEN
    /// `.log`/`.clf`, CoreSLAM `.dat`), into a recording.
    Import(ImportArgs),
    /// Write a recording as ROS 2 messages in an MCAP file (Foxglove, RViz, `ros2 bag play`).
    Export(ExportArgs),
    /// Write a scenario that replays a recorded run in its world (the user's map, or one built
    /// from the run's scans): `hilsim record` on it makes the run's twin.
    World(WorldArgs),
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

/// Compare a simulation with a real recording: locate the mismatch, name the physics left out,
/// fit it, show the held-out improvement. Or prove it blind with `--self-test N`.
#[derive(Debug, clap::Args)]
pub struct DiagnoseArgs {
    /// The scenario the recording is a run of (for `--self-test`: the nominal scenario, default
    /// the built-in `scenarios/diagnose-room.toml`). Without it, `--real` is judged in the world
    /// built from its own scans as `hilsim world` builds it (built again under the lidar's
    /// named delay and mount when the path is the recording's truth).
    #[arg(long, value_name = "SCENARIO")]
    pub sim: Option<PathBuf>,
    /// The real recording (a directory in the recording format).
    #[arg(long, value_name = "RECORDING", conflicts_with = "self_test")]
    pub real: Option<PathBuf>,
    /// Print the result as one JSON object (`interfaces.md`).
    #[arg(long)]
    pub json: bool,
    /// Write the evidence as SVG plots and an HTML page (`index.html`) into this directory.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Run N blind trials: each draws an effect (or none) and its parameters, records a "real"
    /// run with it, diagnoses it against the nominal scenario and scores the answer.
    // Wide enough for any count typed, so that the range check below says what is expected.
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub self_test: Option<i128>,
    /// Seed of the self-test's draws (default 1).
    #[arg(long, value_name = "S", requires = "self_test")]
    pub seed: Option<u64>,
    /// Self-test: strength of the drawn effects, a factor on the documented moderate ranges.
    #[arg(
        long,
        value_name = "X",
        requires = "self_test",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    pub strength: f64,
    /// Self-test: conceal only this effect in every trial (a catalogue name, or `none`), to
    /// study one class.
    #[arg(long, value_name = "EFFECT", requires = "self_test")]
    pub only: Option<String>,
    /// Self-test: what makes the "real" recordings: `hilsim` (its own simulator with the drawn
    /// effect switched on) or `independent` (a generator that shares no model code with it,
    /// with random nuisances, two effects at once in a fifth of the trials and an effect
    /// outside the catalogue) or `varied` (the independent one with each effect in a form the
    /// catalogue does not write: a random smooth monotone curve, or a physical form from the
    /// literature).
    #[arg(long, value_name = "REALITY", requires = "self_test", default_value = "hilsim",
          value_parser = ["hilsim", "independent", "varied"])]
    pub reality: String,
    /// Self-test: run only trial I (of the N), print its whole diagnosis and, with `--report`,
    /// write its report and its "real" recording (`DIR/recording`).
    #[arg(long, value_name = "I", requires = "self_test")]
    pub trial: Option<u64>,
    /// Self-test: remove each "real" recording's `truth.csv` before diagnosing it, as a robot's
    /// log without motion capture (the trajectory is then estimated from the lidar).
    #[arg(long, requires = "self_test")]
    pub without_truth: bool,
    /// Self-test on a real log: conceal none, one or two mechanisms in the recording at this
    /// directory itself in each trial, build the trial's world from it as `hilsim world` does
    /// (or take `--sim`'s), diagnose it blind and score it against the untouched log's own
    /// diagnosis and its halves'.
    #[arg(
        long,
        value_name = "RECORDING",
        requires = "self_test",
        conflicts_with = "only"
    )]
    pub on: Option<PathBuf>,
    /// Exit 1 when the verdict is not `none` (a mismatch was found), for CI jobs; the result is
    /// still printed.
    #[arg(long, conflicts_with = "self_test")]
    pub fail_on_mismatch: bool,
    /// A sensor's practical floor: a mismatch smaller than this many millimetres (and than
    /// `--floor-noise-share` of the declared noise) is not reported, however significant
    /// (`SENSOR=MM`, SENSOR one of lidar, sonar, odometer, drive; repeatable; defaults in
    /// docs/diagnose.md).
    #[arg(long = "floor", value_name = "SENSOR=MM", conflicts_with = "self_test")]
    pub floors: Vec<String>,
    /// The share of the declared noise's standard deviation below which a mismatch is not
    /// reported (default 0.25).
    #[arg(long, value_name = "X", conflicts_with = "self_test")]
    pub floor_noise_share: Option<f64>,
    /// A calibration of the robot (`hilsim calibrate --json`): the simulation takes what it
    /// found instead of the scenario's declared models (an odometry calibration's wheels and
    /// lidar mount; an em, landmarks or groundtruth calibration's range bias and noise), so that
    /// what is left is what the calibration did not explain.
    #[arg(long, value_name = "FILE", conflicts_with = "self_test")]
    pub calibration: Option<PathBuf>,
}

/// `hilsim dataset`.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct DatasetArgs {
    #[command(subcommand)]
    pub command: Option<DatasetCommand>,
    /// Scenario file: the base of every run.
    #[arg(required = true)]
    pub scenario: Option<PathBuf>,
    /// Number of runs N (runs 0 to N-1).
    #[arg(long, required = true, value_name = "N")]
    pub runs: Option<u64>,
    /// The dataset directory: created, or resumed when it holds this dataset.
    #[arg(long, required = true, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The dataset's seed S (default: the scenario's `seed`); run r's seed derives from (S, r).
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "J")]
    pub jobs: Option<usize>,
    /// Make only shard I of K: the runs r with r mod K = I-1 (I counts from 1).
    #[arg(long, value_name = "I/K", conflicts_with = "run")]
    pub shard: Option<String>,
    /// Make only run R (e.g. to make one run again on its own).
    #[arg(long, value_name = "R")]
    pub run: Option<u64>,
    /// Draw this scenario number per run, uniformly in [LO, HI] (repeatable), e.g.
    /// `robot.start.x=0.5..1.5`.
    #[arg(long, value_name = "KEY=LO..HI")]
    pub vary: Vec<String>,
}

#[derive(Debug, Subcommand)]
pub enum DatasetCommand {
    /// Merge dataset directories (the shards of one dataset) into one, and rebuild its manifest.
    Merge(MergeArgs),
}

#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// The merged dataset directory (new or empty, or one of the shards' own directory).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Dataset directories to bring into DIR (none: merge DIR's own shards in place).
    pub sources: Vec<PathBuf>,
    /// Worker threads for hashing and copying (default: one per core).
    #[arg(long, value_name = "J")]
    pub jobs: Option<usize>,
}

#[derive(Debug, clap::Args)]
pub struct HilArgs {
    /// Scenario file; its drive program is not run (the firmware drives).
    pub scenario: PathBuf,
    /// The firmware's command line, split into words as a shell would (no shell runs): it gets
    /// HILSIM_LIDAR_PORT and HILSIM_ROBOT_PORT in its environment.
    #[arg(long, value_name = "'CMD ARGS…'")]
    pub firmware: String,
    /// Write the run as a recording (truth included) into this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The run's length in seconds, overriding the scenario's `duration_s`.
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// Seconds the firmware may go without a request before it counts as hung; also the time
    /// it has to start reading the lidar.
    #[arg(long, value_name = "S", default_value_t = 5.0)]
    pub watchdog: f64,
    /// Seed of every random stream (default: the scenario's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// End with one JSON object on its own line (how it ended, the metrics, the assertions, the
    /// stream and the firmware) instead of the summary.
    #[arg(long)]
    pub json: bool,
}

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

#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// A recording directory.
    pub recording: PathBuf,
    /// The MCAP file to write (replaced atomically when complete).
    #[arg(long, value_name = "OUT")]
    pub mcap: PathBuf,
    /// The scenario the recording ran: its world is drawn as markers (`/world`).
    #[arg(long, value_name = "FILE")]
    pub scenario: Option<PathBuf>,
    /// A calibration (`hilsim calibrate --json`): the scans with each reading inverted through
    /// its lidar model are sent too, as `/scan_calibrated`.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
pub struct WorldArgs {
    /// The recording (as `hilsim import` writes one).
    pub recording: PathBuf,
    /// The scenario to write; its map (`STEM.map.yaml` and `.pgm`), path (`STEM.path.csv`) and
    /// scan schedule (`STEM.scans.csv`) are written beside it.
    #[arg(long, value_name = "SCENARIO.toml")]
    pub out: PathBuf,
    /// The user's map (map_server YAML and its image) instead of one built from the scans.
    #[arg(long, value_name = "MAP.yaml")]
    pub map: Option<PathBuf>,
    /// The built map's cell size, metres.
    #[arg(long, value_name = "M", default_value_t = hilsim_twin::WorldOptions::default().resolution_m)]
    pub resolution_m: f64,
    /// Where the robot's path comes from: `truth` (truth.csv), `odometry` (the wheels, corrected
    /// by matching scans), or `auto` (truth when the recording has it).
    #[arg(long, value_name = "SOURCE", default_value = "auto", value_parser = ["auto", "truth", "odometry"])]
    pub poses: String,
    /// A calibration of the robot (`hilsim calibrate --json`) whose models the scenario
    /// declares: an em, landmarks or groundtruth calibration's lidar bias and noise; an odometry
    /// calibration's wheel base and lidar mount. Without one the lidar is declared unbiased,
    /// with the noise the log shows against its twin.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
}
