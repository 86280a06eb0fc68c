//! A recording as an MCAP file of ROS 2 messages (profile `ros2`, schemas `ros2msg`, messages
//! CDR), what `ros2 bag play`, RViz and Foxglove read. Topics and frames:
//!
//! | topic | type | frame |
//! |---|---|---|
//! | `/scan` | `sensor_msgs/msg/LaserScan`, one per revolution | `laser` |
//! | `/sonar` | `sensor_msgs/msg/Range` | `sonar` |
//! | `/odom` | `nav_msgs/msg/Odometry` (the wheel travel dead-reckoned) | `odom` → `base_link` |
//! | `/cmd_vel` | `geometry_msgs/msg/TwistStamped` | `base_link` |
//! | `/ground_truth/pose` | `geometry_msgs/msg/PoseStamped` | `map` |
//! | `/tf` | `tf2_msgs/msg/TFMessage`: `odom` → `base_link` (odometry), `map` → `odom` (truth) | |
//! | `/tf_static` | `tf2_msgs/msg/TFMessage`: `base_link` → `laser`, `base_link` → `sonar` | |
//!
//! The frames are one tree (REP 105): `map` → `odom` → `base_link` → `laser`, `sonar`.
//! | `/world` | `visualization_msgs/msg/MarkerArray` (with a world) | `map` |
//! | `/scan_calibrated` | `sensor_msgs/msg/LaserScan` (with calibrated ranges) | `laser` |

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use std::convert::Infallible;

use hilsim_recording::{
    AtomicFile, CommandSample, LidarSample, Meta, OdometrySample, Recording, RecordingDir, Rows,
    SampleSink, SonarSample, Tables, TruthSample,
};
use mcap::records::{MessageHeader, Metadata};
use mcap::write::NoSeek;
use mcap::{Compression, WriteOptions};

use crate::cdr::encode;
use crate::definitions::schema_text;
use crate::import::{ODOMETRY_START_KEYS, START_KEY, START_METADATA};
use crate::msgs::{
    ColorRgba, Header, LaserScan, Marker, MarkerArray, Odometry, Pose, PoseStamped, Quaternion,
    Range, TfMessage, Time, Transform, TransformStamped, Twist, TwistStamped, Vector3,
};
use crate::Error;

/// The stamp of the recording's t = 0: one second after the epoch, not zero, which ROS reads
/// as "no time" (tf2 takes a zero stamp as "the latest").
pub const START_NS: i64 = 1_000_000_000;

/// What of the world is drawn, in the world (`map`) frame, metres and radians.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct World {
    /// Walls as segments (from, to).
    pub walls: Vec<[[f64; 2]; 2]>,
    /// Upright cylinders (centre, radius).
    pub cylinders: Vec<([f64; 2], f64)>,
    /// Boards (centre, length, thickness, direction of the length from the x axis).
    pub boards: Vec<([f64; 2], f64, f64, f64)>,
}

/// What an export wrote.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ExportReport {
    /// Messages per topic.
    pub messages: BTreeMap<String, u64>,
}

/// A recording's t_s as a stamp (within the range [`check_stamps`] allows).
fn stamp_ns(t_s: f64) -> i64 {
    START_NS + (t_s * 1e9).round() as i64
}

fn header(t_ns: i64, frame: &str) -> Header {
    Header {
        stamp: Time::from_ns(t_ns),
        frame_id: frame.to_string(),
    }
}

/// rosbag2's QoS for a channel: `/tf_static` is latched (transient local), so a player sends it
/// to subscribers that join late; the rest reliable and volatile.
fn qos(latched: bool) -> String {
    let never = "    sec: 2147483647\n    nsec: 4294967295\n";
    format!(
        "- history: 3\n  depth: 0\n  reliability: 1\n  durability: {}\n  deadline:\n{never}  \
         lifespan:\n{never}  liveliness: 1\n  liveliness_lease_duration:\n{never}  \
         avoid_ros_namespace_conventions: false\n",
        if latched { 1 } else { 2 }
    )
}

/// An MCAP file being written: channels by topic and a reused message buffer.
struct Bag<'p, W: Write> {
    writer: mcap::Writer<NoSeek<W>>,
    out: &'p Path,
    channels: BTreeMap<&'static str, u16>,
    sequence: u32,
    buffer: Vec<u8>,
    report: ExportReport,
}

impl<W: Write> Bag<'_, W> {
    fn fail(&self, err: mcap::McapError) -> Error {
        mcap_failure(self.out, err)
    }

    fn channel(&mut self, topic: &'static str, type_name: &str) -> Result<u16, mcap::McapError> {
        if let Some(&id) = self.channels.get(topic) {
            return Ok(id);
        }
        let text = schema_text(type_name).unwrap_or_default();
        let schema = self
            .writer
            .add_schema(type_name, "ros2msg", text.as_bytes())?;
        let metadata = BTreeMap::from([(
            "offered_qos_profiles".to_string(),
            qos(topic == "/tf_static"),
        )]);
        let id = self.writer.add_channel(schema, topic, "cdr", &metadata)?;
        self.channels.insert(topic, id);
        Ok(id)
    }

    fn write<T: serde::Serialize>(
        &mut self,
        topic: &'static str,
        type_name: &str,
        t_ns: i64,
        message: &T,
    ) -> Result<(), Error> {
        self.write_message(topic, type_name, t_ns, message)
            .map_err(|err| self.fail(err))
    }

    fn write_message<T: serde::Serialize>(
        &mut self,
        topic: &'static str,
        type_name: &str,
        t_ns: i64,
        message: &T,
    ) -> Result<(), mcap::McapError> {
        let channel_id = self.channel(topic, type_name)?;
        encode(message, &mut self.buffer);
        let time = u64::try_from(t_ns).unwrap_or(0);
        self.sequence = self.sequence.wrapping_add(1);
        self.writer.write_to_known_channel(
            &MessageHeader {
                channel_id,
                sequence: self.sequence,
                log_time: time,
                publish_time: time,
            },
            &self.buffer,
        )?;
        *self.report.messages.entry(topic.to_string()).or_insert(0) += 1;
        Ok(())
    }
}

/// Writes `recording` as an MCAP file at `out` (atomically: a temporary sibling renamed into
/// place when complete), with `world` drawn as markers when given; chunks zstd-compressed (as
/// `ros2 bag record --storage-preset-profile zstd_fast` writes them).
///
/// # Errors
/// The file cannot be written.
pub fn export(
    recording: &Recording,
    world: Option<&World>,
    out: &Path,
) -> Result<ExportReport, Error> {
    let options = ExportOptions {
        world,
        ..ExportOptions::default()
    };
    export_with(recording, &options, out)
}

/// What an export writes besides the recording.
#[derive(Clone, Copy)]
pub struct ExportOptions<'a> {
    /// The world, drawn as markers (`/world`).
    pub world: Option<&'a World>,
    /// zstd chunks (else plain, as rosbag2's default preset writes them).
    pub compress: bool,
    /// A lidar reading's calibrated range (NaN for none), sent as `/scan_calibrated`.
    pub calibrated: Option<&'a dyn Fn(&LidarSample) -> f64>,
}

impl Default for ExportOptions<'_> {
    fn default() -> Self {
        Self {
            world: None,
            compress: true,
            calibrated: None,
        }
    }
}

/// As [`export`], with the options given.
///
/// # Errors
/// The file cannot be written.
pub fn export_with(
    recording: &Recording,
    options: &ExportOptions<'_>,
    out: &Path,
) -> Result<ExportReport, Error> {
    let mut extent = Extent::default();
    for c in &recording.commands {
        extent.note_command(c);
    }
    recording
        .odometry
        .iter()
        .flatten()
        .for_each(|o| extent.note_odometry(o));
    recording
        .lidar
        .iter()
        .flatten()
        .for_each(|r| extent.note_lidar(r));
    recording
        .sonar
        .iter()
        .flatten()
        .for_each(|s| extent.note_sonar(s));
    recording
        .truth
        .iter()
        .flatten()
        .for_each(|p| extent.note_truth(p));
    fn rows<T: Copy>(table: Option<&[T]>) -> Stream<'_, T> {
        Box::new(table.unwrap_or_default().iter().copied().map(Ok))
    }
    let source = Source {
        meta: &recording.meta,
        tables: Tables {
            odometry: recording.odometry.is_some(),
            lidar: recording.lidar.is_some(),
            sonar: recording.sonar.is_some(),
            truth: recording.truth.is_some(),
        },
        commands: rows(Some(&recording.commands)),
        odometry: rows(recording.odometry.as_deref()),
        odometry_again: rows(recording.odometry.as_deref()),
        lidar: rows(recording.lidar.as_deref()),
        sonar: rows(recording.sonar.as_deref()),
        truth: rows(recording.truth.as_deref()),
    };
    write_file(source, &extent, options, out)
}

/// As [`export_with`], reading the recording directory as streams: its tables are checked
/// first (a malformed one is the error [`Recording::read_dir`] gives, and nothing is written),
/// then read again row by row, merged by time into the file. Memory is bounded whatever the
/// recording's length: a few rows of each table, one revolution (at most
/// [`MAX_SCAN_READINGS`] readings), the MCAP chunk being filled (768 KiB) and the file's index of
/// its chunks (a few dozen bytes per chunk).
///
/// # Errors
/// A table is malformed, or the file cannot be written.
pub fn export_dir(
    dir: &RecordingDir,
    options: &ExportOptions<'_>,
    out: &Path,
) -> Result<ExportReport, Error> {
    let mut extent = Extent::default();
    dir.check(&mut extent)?;
    fn rows<'a, T: 'a>(table: Option<Rows<T>>) -> Stream<'a, T> {
        match table {
            Some(rows) => Box::new(rows),
            None => Box::new(std::iter::empty()),
        }
    }
    let source = Source {
        meta: dir.meta(),
        tables: dir.tables(),
        commands: Box::new(dir.commands()?),
        odometry: rows(dir.odometry()?),
        odometry_again: rows(dir.odometry()?),
        lidar: rows(dir.lidar()?),
        sonar: rows(dir.sonar()?),
        truth: rows(dir.truth()?),
    };
    write_file(source, &extent, options, out)
}

/// Writing `out` failed: an I/O error in the system's words ("No space left on device", a pipe
/// whose reader left), as the recording crate reports one, not the mcap crate's wrapper's.
fn mcap_failure(out: &Path, err: mcap::McapError) -> Error {
    match err {
        mcap::McapError::Io(io) => Error::Recording(hilsim_recording::Error {
            path: out.to_path_buf(),
            line: None,
            kind: hilsim_recording::ErrorKind::Io(io),
        }),
        other => Error::bag(out, other.to_string()),
    }
}

fn write_file(
    source: Source<'_>,
    extent: &Extent,
    options: &ExportOptions<'_>,
    out: &Path,
) -> Result<ExportReport, Error> {
    extent.check_stamps()?;
    let file = AtomicFile::create(out)?;
    let fail = |err: mcap::McapError| mcap_failure(out, err);
    let writer = WriteOptions::new()
        .profile("ros2")
        .library(concat!("hilsim ", env!("CARGO_PKG_VERSION")))
        .compression(options.compress.then_some(Compression::Zstd))
        .disable_seeking(true)
        .create(NoSeek::new(file))
        .map_err(fail)?;
    let mut bag = Bag {
        writer,
        out,
        channels: BTreeMap::new(),
        sequence: 0,
        buffer: Vec::with_capacity(1 << 14),
        report: ExportReport::default(),
    };
    write_all(&mut bag, source, extent, options)?;
    bag.writer.finish().map_err(fail)?;
    let report = std::mem::take(&mut bag.report);
    let file = bag.writer.into_inner().into_inner();
    file.commit()?;
    Ok(report)
}

/// A table's samples in time order.
type Stream<'a, T> = Box<dyn Iterator<Item = Result<T, hilsim_recording::Error>> + 'a>;

/// What an export reads: the metadata, which tables there are, and each table as a stream (the
/// odometry twice: the messages, and the path the truth's transforms are placed on).
struct Source<'a> {
    meta: &'a Meta,
    tables: Tables,
    commands: Stream<'a, CommandSample>,
    odometry: Stream<'a, OdometrySample>,
    odometry_again: Stream<'a, OdometrySample>,
    lidar: Stream<'a, LidarSample>,
    sonar: Stream<'a, SonarSample>,
    truth: Stream<'a, TruthSample>,
}

/// What the messages need from whole tables before the first is written: the scans' and the
/// sonar's largest range (their `range_max`, `max_range`), where the odometry started, whether
/// there is any truth.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Extent {
    /// Rows seen of each table, in `TABLES`' order.
    rows: [u64; 5],
    /// The first row whose time no stamp holds: its table, its row (1-based) and its time.
    beyond_stamp: Option<(&'static str, u64, f64)>,
    range_max: f32,
    sonar_max: f32,
    first_odometry: Option<OdometrySample>,
    truth: bool,
}

impl Default for Extent {
    fn default() -> Self {
        Self {
            rows: [0; 5],
            beyond_stamp: None,
            range_max: 1.0,
            sonar_max: 1.0,
            first_odometry: None,
            truth: false,
        }
    }
}

/// Whether a stamp holds time `t_s`: `builtin_interfaces/Time`'s `sec` is an int32, so a stamp
/// ends 2³¹ s (68 years) after the epoch, and a time beyond would wrap. Checked in the integers
/// `stamp_ns` makes (an f64 near 2³¹ s is coarser than a nanosecond).
fn stamp_holds(t_s: f64) -> bool {
    let ns = i128::from(START_NS).saturating_add((t_s * 1e9).round() as i128);
    let range =
        i128::from(i32::MIN) * 1_000_000_000..=i128::from(i32::MAX) * 1_000_000_000 + 999_999_999;
    t_s.is_finite() && range.contains(&ns)
}

/// The tables, in the order [`Extent`] counts their rows.
const TABLES: [&str; 5] = [
    "commands.csv",
    "odometry.csv",
    "lidar.csv",
    "sonar.csv",
    "truth.csv",
];

impl Extent {
    /// Counts a row of table `k` (of [`TABLES`]) and keeps the first whose time `t_s` a stamp
    /// cannot hold.
    fn note_time(&mut self, k: usize, t_s: f64) {
        self.rows[k] += 1;
        if self.beyond_stamp.is_none() && !stamp_holds(t_s) {
            self.beyond_stamp = Some((TABLES[k], self.rows[k], t_s));
        }
    }

    /// Refuses a recording with a time that a ROS 2 stamp cannot hold, naming the table and
    /// row, rather than wrapping it to another century.
    fn check_stamps(&self) -> Result<(), Error> {
        let Some((table, row, t_s)) = self.beyond_stamp else {
            return Ok(());
        };
        let (earliest, latest) = (
            i64::from(i32::MIN) - START_NS / 1_000_000_000,
            i64::from(i32::MAX) - START_NS / 1_000_000_000,
        );
        Err(Error::bag(
            Path::new(table),
            format!(
                "row {row}: t_s {t_s:e} s, beyond what a ROS 2 stamp holds (its seconds are an \
                 int32: t_s from {earliest} to {latest} s)"
            ),
        ))
    }

    fn note_command(&mut self, c: &CommandSample) {
        self.note_time(0, c.t_s);
    }
    fn note_odometry(&mut self, o: &OdometrySample) {
        self.note_time(1, o.t_s);
        self.first_odometry.get_or_insert(*o);
    }
    fn note_lidar(&mut self, r: &LidarSample) {
        self.note_time(2, r.t_s);
        if !r.invalid {
            self.range_max = self.range_max.max(r.range_m as f32);
        }
    }
    fn note_sonar(&mut self, s: &SonarSample) {
        self.note_time(3, s.t_s);
        self.sonar_max = self.sonar_max.max(s.range_m as f32);
    }
    fn note_truth(&mut self, p: &TruthSample) {
        self.note_time(4, p.t_s);
        self.truth = true;
    }
}

impl SampleSink for Extent {
    type Error = Infallible;
    fn command(&mut self, c: &CommandSample) -> Result<(), Infallible> {
        self.note_command(c);
        Ok(())
    }
    fn odometry(&mut self, o: &OdometrySample) -> Result<(), Infallible> {
        self.note_odometry(o);
        Ok(())
    }
    fn lidar(&mut self, r: &LidarSample) -> Result<(), Infallible> {
        self.note_lidar(r);
        Ok(())
    }
    fn sonar(&mut self, s: &SonarSample) -> Result<(), Infallible> {
        self.note_sonar(s);
        Ok(())
    }
    fn truth(&mut self, p: &TruthSample) -> Result<(), Infallible> {
        self.note_truth(p);
        Ok(())
    }
}

/// The most readings one `/scan` message holds: a longer revolution (rows of one `rev`) is sent
/// as several scans. A Neato revolution has 360; the bound keeps what is held for a scan small
/// whatever the file says.
pub const MAX_SCAN_READINGS: usize = 100_000;

/// A stream with its next sample taken out and looked at.
struct Head<'a, T> {
    next: Option<T>,
    rest: Stream<'a, T>,
}

impl<'a, T> Head<'a, T> {
    fn new(mut rest: Stream<'a, T>) -> Result<Self, Error> {
        let next = rest.next().transpose()?;
        Ok(Self { next, rest })
    }

    /// The next sample, the one after it taken out.
    fn take(&mut self) -> Result<Option<T>, Error> {
        let next = self.rest.next().transpose()?;
        Ok(std::mem::replace(&mut self.next, next))
    }
}

/// The lidar's rows a revolution at a time (consecutive rows of one `rev`, at most
/// [`MAX_SCAN_READINGS`]).
struct Revolutions<'a> {
    rows: Head<'a, LidarSample>,
    current: Vec<LidarSample>,
}

impl<'a> Revolutions<'a> {
    fn new(rows: Stream<'a, LidarSample>) -> Result<Self, Error> {
        let mut revolutions = Self {
            rows: Head::new(rows)?,
            current: Vec::new(),
        };
        revolutions.advance()?;
        Ok(revolutions)
    }

    /// Moves to the next revolution (empty at the end).
    fn advance(&mut self) -> Result<(), Error> {
        self.current.clear();
        while let Some(next) = &self.rows.next {
            let full = self.current.len() == MAX_SCAN_READINGS;
            if full
                || self
                    .current
                    .first()
                    .is_some_and(|first| first.rev != next.rev)
            {
                break;
            }
            self.current.extend(self.rows.take()?);
        }
        Ok(())
    }
}

/// What the next message is made from.
enum Next {
    /// The revolution [`Merge::revolution`] holds.
    Scan,
    Command(CommandSample),
    Odometry(OdometrySample),
    Sonar(SonarSample),
    Truth(TruthSample),
}

/// The tables merged by time, holding one row of each (one revolution of the lidar's) ahead.
/// At one time a scan comes first, then a command, the odometry, the sonar and the truth (as a
/// stable sort of the tables in that order would put them).
struct Merge<'a> {
    scans: Revolutions<'a>,
    /// Whether the revolution held has been given out (it is left until the next call).
    scan_given: bool,
    commands: Head<'a, CommandSample>,
    odometry: Head<'a, OdometrySample>,
    sonar: Head<'a, SonarSample>,
    truth: Head<'a, TruthSample>,
}

impl<'a> Merge<'a> {
    fn new(
        lidar: Stream<'a, LidarSample>,
        commands: Stream<'a, CommandSample>,
        odometry: Stream<'a, OdometrySample>,
        sonar: Stream<'a, SonarSample>,
        truth: Stream<'a, TruthSample>,
    ) -> Result<Self, Error> {
        Ok(Self {
            scans: Revolutions::new(lidar)?,
            scan_given: false,
            commands: Head::new(commands)?,
            odometry: Head::new(odometry)?,
            sonar: Head::new(sonar)?,
            truth: Head::new(truth)?,
        })
    }

    /// The revolution of the last [`Next::Scan`].
    fn revolution(&self) -> &[LidarSample] {
        &self.scans.current
    }

    /// The next message's time and what it is made from; `None` at the end of every table.
    fn next(&mut self) -> Result<Option<(f64, Next)>, Error> {
        if std::mem::take(&mut self.scan_given) {
            self.scans.advance()?;
        }
        let times = [
            self.scans.current.first().map(|s| s.t_s),
            self.commands.next.map(|c| c.t_s),
            self.odometry.next.map(|o| o.t_s),
            self.sonar.next.map(|s| s.t_s),
            self.truth.next.map(|p| p.t_s),
        ];
        // The earliest time; a tie goes to the first in `times`' order.
        let mut earliest: Option<(usize, f64)> = None;
        for (i, t) in times.into_iter().enumerate() {
            if let Some(t) = t {
                if earliest.is_none_or(|(_, e)| t.total_cmp(&e).is_lt()) {
                    earliest = Some((i, t));
                }
            }
        }
        let Some((which, t_s)) = earliest else {
            return Ok(None);
        };
        let next = match which {
            0 => {
                self.scan_given = true;
                Some(Next::Scan)
            }
            1 => self.commands.take()?.map(Next::Command),
            2 => self.odometry.take()?.map(Next::Odometry),
            3 => self.sonar.take()?.map(Next::Sonar),
            _ => self.truth.take()?.map(Next::Truth),
        };
        Ok(next.map(|next| (t_s, next)))
    }
}

fn write_all<W: Write>(
    bag: &mut Bag<'_, W>,
    source: Source<'_>,
    extent: &Extent,
    options: &ExportOptions<'_>,
) -> Result<(), Error> {
    let (world, calibrated) = (options.world, options.calibrated);
    let mut metadata = BTreeMap::from([(START_KEY.to_string(), START_NS.to_string())]);
    if let Some(first) = extent.first_odometry {
        for (key, value) in ODOMETRY_START_KEYS
            .iter()
            .zip([first.left_m, first.right_m])
        {
            metadata.insert((*key).to_string(), value.to_string());
        }
    }
    bag.writer
        .write_metadata(&Metadata {
            name: START_METADATA.to_string(),
            metadata,
        })
        .map_err(|err| bag.fail(err))?;
    let meta = source.meta;
    let wheel_base = meta.robot.wheel_base_m;
    // The frames as REP 105 chains them, one tree that a viewer shows in `map`: map → odom
    // (where the odometry started, from the truth) → base_link (the odometry) → laser, sonar
    // (the mounts). Without odometry the truth places base_link in map; without truth, odom is
    // put at map's origin; with neither, base_link is.
    let mut fixed = Vec::new();
    match (!extent.truth, extent.first_odometry.is_none()) {
        (true, false) => fixed.push(transform(START_NS, "map", "odom", 0.0, 0.0, 0.0)),
        (true, true) => fixed.push(transform(START_NS, "map", "base_link", 0.0, 0.0, 0.0)),
        (false, _) => {}
    }
    if source.tables.lidar {
        let lidar = meta.lidar.unwrap_or_default();
        fixed.push(transform(
            START_NS,
            "base_link",
            "laser",
            lidar.x_m,
            lidar.y_m,
            lidar.yaw_rad(),
        ));
    }
    if source.tables.sonar {
        // A sonar without a mount in meta.toml is at the robot's centre, facing forward.
        let (x, y, yaw_deg) = meta
            .sonar
            .as_ref()
            .map_or((0.0, 0.0, 0.0), |s| (s.x_m, s.y_m, s.yaw_deg));
        fixed.push(transform(
            START_NS,
            "base_link",
            "sonar",
            x,
            y,
            yaw_deg.to_radians(),
        ));
    }
    if !fixed.is_empty() {
        bag.write(
            "/tf_static",
            "tf2_msgs/msg/TFMessage",
            START_NS,
            &TfMessage { transforms: fixed },
        )?;
    }
    if let Some(world) = world {
        bag.write(
            "/world",
            "visualization_msgs/msg/MarkerArray",
            START_NS,
            &markers(world),
        )?;
    }
    let (range_max, sonar_max) = (extent.range_max, extent.sonar_max);
    let sonar_fov = meta
        .sonar
        .as_ref()
        .map_or(0.0, |s| (2.0 * s.half_angle_deg).to_radians() as f32);
    let mut odometry_path = OdometryPath::new(source.odometry_again, wheel_base)?;
    let mut dead_reckoning = DeadReckoning::default();
    let mut merge = Merge::new(
        source.lidar,
        source.commands,
        source.odometry,
        source.sonar,
        source.truth,
    )?;
    while let Some((t_s, next)) = merge.next()? {
        let t_ns = stamp_ns(t_s);
        match next {
            Next::Scan => {
                let rev = merge.revolution();
                let mut scan = laser_scan(rev, range_max);
                bag.write("/scan", "sensor_msgs/msg/LaserScan", t_ns, &scan)?;
                if let Some(calibrated) = calibrated {
                    // The same revolution, each reading replaced by its calibrated range.
                    let reported = laser_scan_ranges(rev, |i| {
                        let d = calibrated(&rev[i]);
                        if d.is_finite() {
                            d as f32
                        } else {
                            f32::NAN
                        }
                    });
                    scan.ranges = reported;
                    scan.range_max = f32::MAX;
                    bag.write("/scan_calibrated", "sensor_msgs/msg/LaserScan", t_ns, &scan)?;
                }
            }
            Next::Command(c) => {
                let twist = TwistStamped {
                    header: header(t_ns, "base_link"),
                    twist: twist(
                        0.5 * (c.left_mps + c.right_mps),
                        (c.right_mps - c.left_mps) / wheel_base,
                    ),
                };
                bag.write("/cmd_vel", "geometry_msgs/msg/TwistStamped", t_ns, &twist)?;
            }
            Next::Odometry(o) => {
                let (pose, velocity) = dead_reckoning.step(o.t_s, o.left_m, o.right_m, wheel_base);
                let mut message = Odometry {
                    header: header(t_ns, "odom"),
                    child_frame_id: "base_link".into(),
                    ..Odometry::default()
                };
                message.pose.pose = pose;
                message.twist.twist = velocity;
                bag.write("/odom", "nav_msgs/msg/Odometry", t_ns, &message)?;
                let (x, y, yaw) = (pose.position.x, pose.position.y, pose.orientation.yaw());
                let tf = transform(t_ns, "odom", "base_link", x, y, yaw);
                bag.write(
                    "/tf",
                    "tf2_msgs/msg/TFMessage",
                    t_ns,
                    &TfMessage {
                        transforms: vec![tf],
                    },
                )?;
            }
            Next::Sonar(s) => {
                let range = Range {
                    header: header(t_ns, "sonar"),
                    radiation_type: 0,
                    field_of_view: sonar_fov,
                    min_range: 0.0,
                    max_range: sonar_max,
                    range: s.range_m as f32,
                };
                bag.write("/sonar", "sensor_msgs/msg/Range", t_ns, &range)?;
            }
            Next::Truth(p) => {
                let pose = PoseStamped {
                    header: header(t_ns, "map"),
                    pose: pose(p.x_m, p.y_m, p.yaw_rad),
                };
                bag.write(
                    "/ground_truth/pose",
                    "geometry_msgs/msg/PoseStamped",
                    t_ns,
                    &pose,
                )?;
                // base_link is in map where the truth says: through odom when there is
                // odometry (odom's place is the truth composed with the inverse of the
                // odometry's pose at that time, as tf2 interpolates it).
                let tf = match odometry_path.at(p.t_s)? {
                    Some(odom_pose) => {
                        // odom's origin in base_link, then in map through the truth.
                        let origin = hilsim_recording::Pose::default().relative_to(&odom_pose);
                        let odom = hilsim_recording::Pose::new(p.x_m, p.y_m, p.yaw_rad)
                            .compose(origin.x, origin.y, origin.yaw);
                        transform(t_ns, "map", "odom", odom.x, odom.y, odom.yaw)
                    }
                    None => transform(t_ns, "map", "base_link", p.x_m, p.y_m, p.yaw_rad),
                };
                bag.write(
                    "/tf",
                    "tf2_msgs/msg/TFMessage",
                    t_ns,
                    &TfMessage {
                        transforms: vec![tf],
                    },
                )?;
            }
        }
    }
    Ok(())
}

/// A revolution's angles unwrapped into one increasing turn from the first, degrees from it,
/// and the step between neighbouring slots (the smallest between the angles).
fn slots(rev: &[LidarSample]) -> (Vec<f64>, f64) {
    let first = rev[0].angle_deg;
    let mut turns = 0.0;
    let mut previous = first;
    let unwrapped: Vec<f64> = rev
        .iter()
        .map(|s| {
            if s.angle_deg < previous {
                turns += 360.0;
            }
            previous = s.angle_deg;
            s.angle_deg + turns - first
        })
        .collect();
    let step = unwrapped
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 1e-9)
        .fold(f64::INFINITY, f64::min);
    (unwrapped, if step.is_finite() { step } else { 1.0 })
}

/// A reading's slot: a revolution of wildly uneven angles is capped at 100,000 slots.
fn slot(a: f64, step: f64) -> usize {
    ((a / step).round() as usize).min(99_999)
}

/// A LaserScan's ranges for a revolution, `range(i)` for its row i, NaN where none.
fn laser_scan_ranges(rev: &[LidarSample], range: impl Fn(usize) -> f32) -> Vec<f32> {
    let (unwrapped, step) = slots(rev);
    let slots = unwrapped.last().map_or(1, |&a| slot(a, step) + 1);
    let mut ranges = vec![f32::NAN; slots];
    for (i, &a) in unwrapped.iter().enumerate() {
        ranges[slot(a, step)] = range(i);
    }
    ranges
}

/// One revolution as a LaserScan: readings placed at `angle_min + i·angle_increment`, the
/// increment the smallest step between the revolution's angles (a reading lost leaves a NaN);
/// invalid readings are NaN, strengths the intensities.
fn laser_scan(rev: &[LidarSample], range_max: f32) -> LaserScan {
    let first = rev[0].angle_deg;
    let (unwrapped, step) = slots(rev);
    let slot = |a: f64| slot(a, step);
    let slots = unwrapped.last().map_or(1, |&a| slot(a) + 1);
    let mut ranges = vec![f32::NAN; slots];
    let mut intensities = vec![0.0f32; slots];
    for (s, &a) in rev.iter().zip(&unwrapped) {
        let i = slot(a);
        ranges[i] = if s.invalid {
            f32::NAN
        } else {
            s.range_m as f32
        };
        intensities[i] = f32::from(s.strength);
    }
    let last_slot = slot(*unwrapped.last().unwrap_or(&0.0));
    let time_increment = if last_slot > 0 {
        (rev[rev.len() - 1].t_s - rev[0].t_s) / last_slot as f64
    } else {
        0.0
    };
    let angle_min = first.to_radians();
    let increment = step.to_radians();
    LaserScan {
        header: header(stamp_ns(rev[0].t_s), "laser"),
        angle_min: angle_min as f32,
        angle_max: (angle_min + (slots - 1) as f64 * increment) as f32,
        angle_increment: increment as f32,
        time_increment: time_increment as f32,
        scan_time: (time_increment * 360.0 / step) as f32,
        range_min: 0.0,
        range_max,
        ranges,
        intensities,
    }
}

fn twist(v: f64, w: f64) -> Twist {
    Twist {
        linear: Vector3 {
            x: v,
            y: 0.0,
            z: 0.0,
        },
        angular: Vector3 {
            x: 0.0,
            y: 0.0,
            z: w,
        },
    }
}

fn pose(x: f64, y: f64, yaw: f64) -> Pose {
    Pose {
        position: Vector3 { x, y, z: 0.0 },
        orientation: Quaternion::from_yaw(yaw),
    }
}

fn transform(t_ns: i64, parent: &str, child: &str, x: f64, y: f64, yaw: f64) -> TransformStamped {
    TransformStamped {
        header: header(t_ns, parent),
        child_frame_id: child.to_string(),
        transform: Transform {
            translation: Vector3 { x, y, z: 0.0 },
            rotation: Quaternion::from_yaw(yaw),
        },
    }
}

/// The odometer's pose from its wheel travel: over a step the robot turns by (dr − dl)/b and
/// moves (dl + dr)/2 along its mean heading (the midpoint rule, which the import inverts).
#[derive(Default)]
struct DeadReckoning {
    last: Option<(f64, f64, f64)>,
    x: f64,
    y: f64,
    yaw: f64,
}

impl DeadReckoning {
    fn step(&mut self, t_s: f64, left: f64, right: f64, wheel_base: f64) -> (Pose, Twist) {
        let mut velocity = Twist::default();
        if let Some((t0, l0, r0)) = self.last {
            let (dl, dr) = (left - l0, right - r0);
            let ds = 0.5 * (dl + dr);
            let turn = (dr - dl) / wheel_base;
            let heading = self.yaw + 0.5 * turn;
            self.x += ds * heading.cos();
            self.y += ds * heading.sin();
            self.yaw = hilsim_recording::wrap_angle(self.yaw + turn);
            let dt = t_s - t0;
            if dt > 0.0 {
                velocity = twist(ds / dt, turn / dt);
            }
        }
        self.last = Some((t_s, left, right));
        (pose(self.x, self.y, self.yaw), velocity)
    }
}

/// The odometry's poses (dead-reckoned as `/odom` sends them), read along as the truth's times
/// advance: the two rows around the latest time asked.
struct OdometryPath<'a> {
    rows: Head<'a, OdometrySample>,
    dead_reckoning: DeadReckoning,
    wheel_base: f64,
    /// The last row at or before the time asked, and the first after it, with their poses.
    before: Option<(f64, hilsim_recording::Pose)>,
    after: Option<(f64, hilsim_recording::Pose)>,
}

impl<'a> OdometryPath<'a> {
    fn new(odometry: Stream<'a, OdometrySample>, wheel_base: f64) -> Result<Self, Error> {
        Ok(Self {
            rows: Head::new(odometry)?,
            dead_reckoning: DeadReckoning::default(),
            wheel_base,
            before: None,
            after: None,
        })
    }

    /// The pose at `t_s` as tf2 interpolates between two stamped transforms: the position
    /// linearly, the yaw along the shorter way (a quaternion slerp about z), which is
    /// [`hilsim_recording::Pose::lerp`]; the first or last pose outside the rows' times. `None`
    /// without odometry. Times asked must not go backwards (the truth's rows do not).
    fn at(&mut self, t_s: f64) -> Result<Option<hilsim_recording::Pose>, Error> {
        loop {
            if self.after.is_none() {
                let Some(o) = self.rows.take()? else { break };
                let (pose, _) =
                    self.dead_reckoning
                        .step(o.t_s, o.left_m, o.right_m, self.wheel_base);
                let (x, y) = (pose.position.x, pose.position.y);
                let pose = hilsim_recording::Pose::new(x, y, pose.orientation.yaw());
                self.after = Some((o.t_s, pose));
            }
            match self.after {
                Some((t, _)) if t <= t_s => self.before = self.after.take(),
                _ => break,
            }
        }
        Ok(match (self.before, self.after) {
            (Some((t0, p0)), Some((t1, p1))) => Some(p0.lerp(&p1, (t_s - t0) / (t1 - t0))),
            (Some((_, p)), None) | (None, Some((_, p))) => Some(p),
            (None, None) => None,
        })
    }
}

/// The world as markers: walls and boards as thin boxes 0.3 m high, cylinders as cylinders.
fn markers(world: &World) -> MarkerArray {
    const HEIGHT_M: f64 = 0.3;
    let wall_colour = ColorRgba {
        r: 0.6,
        g: 0.6,
        b: 0.65,
        a: 1.0,
    };
    let board_colour = ColorRgba {
        r: 0.8,
        g: 0.6,
        b: 0.35,
        a: 1.0,
    };
    let cylinder_colour = ColorRgba {
        r: 0.2,
        g: 0.5,
        b: 0.9,
        a: 1.0,
    };
    let mut markers = Vec::new();
    let mut add = |ns: &str, kind: i32, pose: Pose, scale: Vector3, color: ColorRgba| {
        markers.push(Marker {
            header: header(START_NS, "map"),
            ns: ns.to_string(),
            id: i32::try_from(markers.len()).unwrap_or(i32::MAX),
            kind,
            action: 0,
            pose,
            scale,
            color,
            ..Marker::default()
        });
    };
    for [from, to] in &world.walls {
        let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
        let centre = [0.5 * (from[0] + to[0]), 0.5 * (from[1] + to[1])];
        let mut p = pose(centre[0], centre[1], dy.atan2(dx));
        p.position.z = 0.5 * HEIGHT_M;
        let scale = Vector3 {
            x: dx.hypot(dy),
            y: 0.02,
            z: HEIGHT_M,
        };
        add("walls", Marker::CUBE, p, scale, wall_colour);
    }
    for &(centre, length, thickness, yaw) in &world.boards {
        let mut p = pose(centre[0], centre[1], yaw);
        p.position.z = 0.5 * HEIGHT_M;
        let scale = Vector3 {
            x: length,
            y: thickness,
            z: HEIGHT_M,
        };
        add("boards", Marker::CUBE, p, scale, board_colour);
    }
    for &(centre, radius) in &world.cylinders {
        let mut p = pose(centre[0], centre[1], 0.0);
        p.position.z = 0.5 * HEIGHT_M;
        let scale = Vector3 {
            x: 2.0 * radius,
            y: 2.0 * radius,
            z: HEIGHT_M,
        };
        add("cylinders", Marker::CYLINDER, p, scale, cylinder_colour);
    }
    MarkerArray { markers }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A time that a stamp's int32 seconds cannot hold is refused, naming the table and row,
    /// not wrapped to 1901.
    #[test]
    fn times_no_stamp_holds_are_refused_not_wrapped() {
        use hilsim_recording::{Meta, TruthSample};
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("x.mcap");
        let mut rec = Recording::new(Meta::default());
        let pose = |t_s| TruthSample {
            t_s,
            x_m: 0.0,
            y_m: 0.0,
            yaw_rad: 0.0,
        };
        // The last second a stamp holds, from t = 0 stamped at START_NS.
        rec.truth = Some(vec![pose(0.0), pose(2_147_483_646.5)]);
        export(&rec, None, &out).unwrap();
        // One second later the seconds would be 2³¹: refused, at the nanosecond.
        rec.truth = Some(vec![pose(2_147_483_647.0)]);
        assert!(export(&rec, None, &out).is_err());
        rec.truth = Some(vec![pose(0.0), pose(1.0), pose(3.7e292)]);
        let err = export(&rec, None, &out).unwrap_err().to_string();
        assert!(
            err.starts_with("truth.csv: row 3: t_s 3.7e292 s, beyond what a ROS 2 stamp holds"),
            "{err}"
        );
    }
    use crate::bag::{self, Item};
    use crate::cdr::decode;
    use hilsim_recording::{Meta, Mount};
    use std::cell::Cell;

    /// Every transform of a file (`/tf` and `/tf_static`), and its `/odom` messages.
    fn transforms_and_odometry(path: &Path) -> (Vec<TransformStamped>, Vec<Odometry>) {
        let mut topics = BTreeMap::new();
        let (mut transforms, mut odometry) = (Vec::new(), Vec::new());
        bag::stream(path, |item| {
            match item {
                Item::Channel(c) => {
                    topics.insert(c.id, c.topic);
                }
                Item::Message {
                    channel_id, data, ..
                } => match topics[&channel_id].as_str() {
                    "/tf" | "/tf_static" => {
                        let message: TfMessage = decode(data).unwrap();
                        transforms.extend(message.transforms);
                    }
                    "/odom" => odometry.push(decode(data).unwrap()),
                    _ => {}
                },
                Item::Metadata(_) => {}
            }
            Ok(())
        })
        .unwrap();
        (transforms, odometry)
    }

    /// Each frame's one parent; a frame with two is a broken tree.
    fn parents(transforms: &[TransformStamped]) -> BTreeMap<String, String> {
        let mut parents = BTreeMap::new();
        for tf in transforms {
            let parent = &tf.header.frame_id;
            let old = parents.insert(tf.child_frame_id.clone(), parent.clone());
            assert!(old.is_none_or(|p| &p == parent), "{tf:?}: two parents");
        }
        parents
    }

    fn root(frame: &str, parents: &BTreeMap<String, String>) -> String {
        let mut frame = frame.to_string();
        for _ in 0..10 {
            match parents.get(&frame) {
                Some(parent) => frame.clone_from(parent),
                None => return frame,
            }
        }
        panic!("a cycle through {frame}");
    }

    /// A robot driving an arc, its odometry drifting from the truth (a wheel 2 % long).
    fn run(truth: bool, odometry: bool) -> Recording {
        let mut rec = Recording::new(Meta {
            lidar: Some(Mount::default()),
            ..Meta::default()
        });
        let b = rec.meta.robot.wheel_base_m;
        let (v, w) = (0.2, 0.3);
        let steps = 0..=40;
        if truth {
            rec.truth = Some(
                steps
                    .clone()
                    .map(|i| {
                        let t_s = f64::from(i) * 0.05 + 0.013;
                        let yaw = w * t_s;
                        TruthSample {
                            t_s,
                            x_m: 1.0 + v / w * yaw.sin(),
                            y_m: 2.0 + v / w * (1.0 - yaw.cos()),
                            yaw_rad: yaw,
                        }
                    })
                    .collect(),
            );
        }
        if odometry {
            rec.odometry = Some(
                steps
                    .clone()
                    .map(|i| {
                        let t_s = f64::from(i) * 0.1;
                        OdometrySample {
                            t_s,
                            left_m: (v - 0.5 * w * b) * t_s,
                            right_m: 1.02 * (v + 0.5 * w * b) * t_s,
                        }
                    })
                    .collect(),
            );
        }
        rec.lidar = Some(vec![LidarSample {
            t_s: 0.0,
            rev: 0,
            angle_deg: 0.0,
            range_m: 1.0,
            strength: 10,
            invalid: false,
            warning: false,
            true_range_m: None,
        }]);
        rec.sonar = Some(vec![SonarSample {
            t_s: 0.0,
            range_m: 1.0,
            true_range_m: None,
        }]);
        rec
    }

    /// The frames are one tree rooted at `map` (REP 105: map → odom → base_link → sensors),
    /// `/odom` names its frames as the tree does, and at each truth time the tree puts
    /// base_link where the truth is (odom → base_link interpolated as tf2 does).
    #[test]
    fn the_frames_are_one_tree_that_puts_the_robot_at_the_truth() {
        let dir = tempfile::tempdir().unwrap();
        for (truth, odometry) in [(true, true), (true, false), (false, true), (false, false)] {
            let rec = run(truth, odometry);
            let path = dir.path().join("run.mcap");
            export(&rec, None, &path).unwrap();
            let (transforms, odometry_messages) = transforms_and_odometry(&path);
            let parents = parents(&transforms);
            for frame in ["laser", "sonar", "base_link"] {
                assert_eq!(root(frame, &parents), "map", "{frame} {truth} {odometry}");
            }
            for message in &odometry_messages {
                assert_eq!(message.header.frame_id, "odom");
                assert_eq!(message.child_frame_id, "base_link");
                assert_eq!(root("odom", &parents), "map");
            }
            assert_eq!(
                odometry_messages.len(),
                rec.odometry.as_ref().map_or(0, Vec::len)
            );
            let Some(truth) = &rec.truth else { continue };
            let stamp = |tf: &TransformStamped| tf.header.stamp.ns();
            let planar = |tf: &TransformStamped| {
                let t = &tf.transform;
                hilsim_recording::Pose::new(t.translation.x, t.translation.y, t.rotation.yaw())
            };
            let odom_base: Vec<_> = transforms
                .iter()
                .filter(|tf| tf.child_frame_id == "base_link" && tf.header.frame_id == "odom")
                .collect();
            for p in truth {
                let t_ns = stamp_ns(p.t_s);
                let at = transforms
                    .iter()
                    .find(|tf| tf.header.frame_id == "map" && stamp(tf) == t_ns)
                    .unwrap();
                let in_map = if odom_base.is_empty() {
                    planar(at)
                } else {
                    // odom → base_link at t_ns, between the two stamps around it.
                    let k = odom_base.partition_point(|tf| stamp(tf) <= t_ns);
                    let (a, b) = (odom_base[k - 1], odom_base[k.min(odom_base.len() - 1)]);
                    let f = if k < odom_base.len() {
                        (t_ns - stamp(a)) as f64 / (stamp(b) - stamp(a)) as f64
                    } else {
                        0.0
                    };
                    let between = planar(a).lerp(&planar(b), f);
                    planar(at).compose(between.x, between.y, between.yaw)
                };
                let yaw_error = hilsim_recording::wrap_angle(in_map.yaw - p.yaw_rad);
                // Rounding only: a few sums and products of numbers below 10.
                let close = (in_map.x - p.x_m).abs() < 1e-9 && (in_map.y - p.y_m).abs() < 1e-9;
                assert!(close && yaw_error.abs() < 1e-9, "{p:?}: {in_map:?}");
            }
        }
    }

    /// A recording with every table: the arc of [`run`], three revolutions, commands at times
    /// the other tables share (ties), a sonar.
    fn full() -> Recording {
        let mut rec = run(true, true);
        rec.lidar = Some(
            (0..3u32)
                .flat_map(|rev| {
                    (0..360u32).map(move |a| LidarSample {
                        t_s: f64::from(rev) * 0.2 + f64::from(a) * 0.2 / 360.0,
                        rev: rev.into(),
                        angle_deg: f64::from(a),
                        range_m: 1.0 + f64::from(a) / 100.0,
                        strength: 100,
                        invalid: a % 7 == 0,
                        warning: false,
                        true_range_m: None,
                    })
                })
                .collect(),
        );
        rec.commands = (0..5)
            .map(|i| CommandSample {
                t_s: f64::from(i) * 0.1,
                left_mps: 0.1,
                right_mps: 0.12,
            })
            .collect();
        rec
    }

    /// The streamed export of a directory writes the very bytes of the export of the same
    /// recording held in memory (with the calibrated scans too).
    #[test]
    fn a_directory_exports_the_bytes_of_its_recording_in_memory() {
        let dir = tempfile::tempdir().unwrap();
        let rec = full();
        let path = dir.path().join("run");
        rec.write_dir(&path).unwrap();
        let calibrated = |s: &LidarSample| if s.invalid { f64::NAN } else { 0.9 * s.range_m };
        let world = World {
            walls: vec![[[0.0, 0.0], [1.0, 0.0]]],
            ..World::default()
        };
        let options = ExportOptions {
            world: Some(&world),
            calibrated: Some(&calibrated),
            ..ExportOptions::default()
        };
        let (held, streamed) = (
            dir.path().join("held.mcap"),
            dir.path().join("streamed.mcap"),
        );
        let report = export_with(&rec, &options, &held).unwrap();
        let run = RecordingDir::open(&path).unwrap();
        assert_eq!(export_dir(&run, &options, &streamed).unwrap(), report);
        assert_eq!(report.messages["/scan"], 3);
        assert_eq!(
            std::fs::read(&held).unwrap(),
            std::fs::read(&streamed).unwrap()
        );
    }

    /// A table's stream that counts the rows taken from it.
    fn counted<'a, T: Copy + 'a>(rows: &'a [T], taken: &'a Cell<usize>) -> Stream<'a, T> {
        Box::new(rows.iter().map(move |&row| {
            taken.set(taken.get() + 1);
            Ok(row)
        }))
    }

    /// Merging the tables by time holds one row of each table ahead of the messages given
    /// out (of the lidar, a revolution and a row), in time order: what an export holds does not
    /// grow with the tables.
    #[test]
    fn the_merge_holds_one_row_of_each_table_ahead() {
        let rec = full();
        let taken: [Cell<usize>; 5] = Default::default();
        let mut given = [0usize; 5];
        let mut merge = Merge::new(
            counted(rec.lidar.as_deref().unwrap(), &taken[0]),
            counted(&rec.commands, &taken[1]),
            counted(rec.odometry.as_deref().unwrap(), &taken[2]),
            counted(rec.sonar.as_deref().unwrap(), &taken[3]),
            counted(rec.truth.as_deref().unwrap(), &taken[4]),
        )
        .unwrap();
        let mut last = f64::NEG_INFINITY;
        while let Some((t_s, next)) = merge.next().unwrap() {
            assert!(t_s >= last, "{t_s} after {last}");
            last = t_s;
            match next {
                Next::Scan => given[0] += merge.revolution().len(),
                Next::Command(_) => given[1] += 1,
                Next::Odometry(_) => given[2] += 1,
                Next::Sonar(_) => given[3] += 1,
                Next::Truth(_) => given[4] += 1,
            }
            // A revolution held besides the row after it.
            let ahead = [360 + 1, 1, 1, 1, 1];
            for ((taken, given), ahead) in taken.iter().zip(given).zip(ahead) {
                let taken = taken.get();
                assert!(taken <= given + ahead, "{taken} taken, {given} given");
            }
        }
        let rows = [360 * 3, 5, 41, 1, 41];
        assert_eq!(given, rows);
    }

    /// A revolution longer than [`MAX_SCAN_READINGS`] is sent as several scans, so what is held
    /// for one is bounded whatever the file says.
    #[test]
    fn a_revolution_longer_than_the_bound_is_sent_as_several_scans() {
        let taken = Cell::new(0);
        let rows = 2 * MAX_SCAN_READINGS + 5;
        let lidar = (0..rows).map(|i| {
            taken.set(taken.get() + 1);
            Ok(LidarSample {
                t_s: i as f64 * 1e-6,
                rev: 0,
                angle_deg: (i % 360) as f64,
                range_m: 1.0,
                strength: 1,
                invalid: false,
                warning: false,
                true_range_m: None,
            })
        });
        let mut revolutions = Revolutions::new(Box::new(lidar)).unwrap();
        let mut sizes = Vec::new();
        while !revolutions.current.is_empty() {
            assert!(taken.get() <= sizes.iter().sum::<usize>() + MAX_SCAN_READINGS + 1);
            sizes.push(revolutions.current.len());
            revolutions.advance().unwrap();
        }
        assert_eq!(sizes, [MAX_SCAN_READINGS, MAX_SCAN_READINGS, 5]);
    }

    /// A malformed table stops a streamed export before anything is written, with the error a
    /// reader of the whole recording gives (a row of the wrong width before an earlier bad
    /// value), not the first the merge would meet.
    #[test]
    fn a_malformed_table_is_read_dirs_error_and_nothing_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run");
        full().write_dir(&path).unwrap();
        let sonar = "t_s,range_m\n0,1\n0.1,abc\n0.2\n";
        std::fs::write(path.join("sonar.csv"), sonar).unwrap();
        let whole = Recording::read_dir(&path).unwrap_err().to_string();
        assert!(whole.ends_with("sonar.csv:4: expected 2 fields (t_s,range_m), found 1"));
        let out = dir.path().join("run.mcap");
        let run = RecordingDir::open(&path).unwrap();
        let err = export_dir(&run, &ExportOptions::default(), &out).unwrap_err();
        assert_eq!(err.to_string(), whole);
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "only the recording"
        );
    }
}
