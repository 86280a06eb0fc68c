//! A bag into a recording: each chosen topic's messages into its table as they are read, and
//! what the bag's TF says of the robot into `meta.toml` (see `docs/ros2.md` for what becomes of
//! each field). A ROS 2 bag (MCAP or SQLite3, CDR messages) and a ROS 1 bag (rosbag format
//! 2.0, ROS 1 messages) differ only in their container and serialisation: both feed the one
//! [`Converter`].

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use hilsim_recording::{
    printable, wrap_angle, CommandSample, LidarDecimals, LidarSample, Meta, Mount, OdometrySample,
    RecordingStream, SampleSink, SonarMount, SonarSample, Tables, TruthSample,
};
use serde::de::DeserializeOwned;

use crate::bag::{self, Item};
use crate::cdr::{decode, decode_whole};
use crate::msgs::{
    Header, JointState, LaserScan, Odometry, Pose, PoseStamped, Range, TfMessage, Time, Twist,
    TwistStamped,
};
use crate::ros1::{self, FromRos1};
use crate::tf::{self, Rigid};
use crate::topics::{self, Chosen, Kind, Role, TopicTypes};
use crate::Error;

/// The metadata record an exported file starts with: its `start_ns` is the recording's t = 0,
/// so that importing an export gives back the recording's times even when no message is at 0.
pub(crate) const START_METADATA: &str = "hilsim";
/// The key of the recording's t = 0 (nanoseconds, as the messages' stamps).
pub(crate) const START_KEY: &str = "start_ns";
/// The keys of the wheel travel at the first odometry row (an `Odometry` pose starts from
/// nothing; a recording's encoders may not).
pub(crate) const ODOMETRY_START_KEYS: [&str; 2] = ["odometry_left_m", "odometry_right_m"];

/// Above this difference between a stamp and its log time the two come from different clocks
/// (simulated time against the recorder's wall clock): unstamped messages (`Twist`) are then
/// put on the stamps' clock. Below it, the difference is transport delay and is left alone.
const OTHER_CLOCK_NS: i64 = 60_000_000_000;

/// Unstamped commands held until the first stamped message says which clock they are on.
const MAX_PENDING_COMMANDS: usize = 1 << 20;

/// The frame odometry is in (REP 105); a namespaced one (`robot1/odom`) counts too.
const ODOM_FRAME: &str = "odom";

/// The robot's frame when no odometry names it: REP 105's `base_link`, else `base_footprint`.
const BASE_FRAMES: [&str; 2] = ["base_link", "base_footprint"];

/// What `import` is told besides the bag.
#[derive(Debug, Clone, Default)]
pub struct ImportOptions {
    /// Topics named for roles (the rest are found by type).
    pub topics: BTreeMap<Role, String>,
    /// `meta.toml` to write (mounts, wheel base, world); `None`: a minimal one.
    pub meta: Option<Meta>,
    /// The wheels' radius, for odometry from `JointState` wheel angles.
    pub wheel_radius_m: Option<f64>,
    /// The left and right wheels' joint names in `JointState` (default: the joints named
    /// `…left…` and `…right…`).
    pub wheel_joints: Option<[String; 2]>,
}

/// What an import did.
#[derive(Debug, Clone, Default)]
pub struct ImportReport {
    /// The topic read into each table, and its type.
    pub chosen: Chosen,
    /// Rows written into each table.
    pub rows: BTreeMap<Role, u64>,
    /// Bytes of bag read.
    pub bytes: u64,
    /// Sentences for people: what was assumed, skipped or repaired.
    pub notes: Vec<String>,
}

/// How a message's bytes are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Encoding {
    /// ROS 2: CDR after a 4-byte encapsulation header.
    #[default]
    Cdr,
    /// ROS 1: packed little-endian, `std_msgs/Header` with its `seq`.
    Ros1,
}

/// A message type read in either serialisation.
trait Wire: DeserializeOwned + FromRos1 {}
impl<T: DeserializeOwned + FromRos1> Wire for T {}

/// Decodes a whole message of `encoding` (at most `appended` bytes of fields a newer ROS 2
/// distribution adds are allowed after it).
fn decode_as<T: Wire>(encoding: Encoding, data: &[u8], appended: usize) -> Result<T, String> {
    match encoding {
        Encoding::Cdr => decode_whole(data, appended),
        Encoding::Ros1 => ros1::decode_whole(data),
    }
}

/// The stamp of a message of `kind`: its header's, or a TF message's first transform's.
fn first_stamp(kind: Kind, encoding: Encoding, data: &[u8]) -> Option<Time> {
    match (kind, encoding) {
        (Kind::Tf, _) => decode_as::<TfMessage>(encoding, data, 0)
            .ok()?
            .transforms
            .first()
            .map(|t| t.header.stamp),
        (_, Encoding::Cdr) => decode::<Header>(data).ok().map(|h| h.stamp),
        (_, Encoding::Ros1) => ros1::decode_prefix::<Header>(data).ok().map(|h| h.stamp),
    }
}

/// A bag's container: a ROS 2 bag's files (MCAP or SQLite3) and their channels, or a ROS 1
/// bag's one file and its connections.
enum Container {
    Ros2 {
        files: Vec<PathBuf>,
        channels: Vec<bag::Channel>,
    },
    Ros1 {
        connections: Vec<ros1::Connection>,
    },
}

impl Container {
    fn open(path: &Path) -> Result<Self, Error> {
        if path.is_file() && ros1::is_ros1_bag(path) {
            return Ok(Self::Ros1 {
                connections: ros1::connections(path)?,
            });
        }
        let files = bag::bag_files(path)?;
        let mut channels = Vec::new();
        for file in &files {
            channels.extend(bag::channels(file)?);
        }
        Ok(Self::Ros2 { files, channels })
    }

    fn topic_types(&self, path: &Path) -> Result<TopicTypes, Error> {
        match self {
            Self::Ros2 { channels, .. } => topics::topic_types(
                path,
                channels
                    .iter()
                    .map(|c| (c.topic.as_str(), c.type_name.as_str())),
            ),
            Self::Ros1 { connections } => topics::topic_types(
                path,
                connections
                    .iter()
                    .map(|c| (c.topic.as_str(), c.type_name.as_str())),
            ),
        }
    }
}

/// Imports the bag at `bag` as a recording at `out`, written as it is read and put in place
/// when complete ([`RecordingStream`]). The bag is a ROS 2 bag (an MCAP or SQLite3 file, or a
/// bag directory) or a ROS 1 bag (a `.bag` file of rosbag format 2.0). The lidar's mount comes
/// from the bag's TF when `options.meta` has none; odometry from TF's odom → base transforms
/// when the bag has no odometry topic.
///
/// # Errors
/// The bag cannot be read (neither format, a ROS 2 bag truncated or of an unreadable
/// compression, a ROS 2 message that does not decode as its type: a ROS 1 bag's damage and
/// messages that do not decode are counted in the notes instead); the topics are ambiguous; the
/// output cannot be written.
pub fn import(bag: &Path, out: &Path, options: &ImportOptions) -> Result<ImportReport, Error> {
    if options.wheel_joints.is_some() && options.wheel_radius_m.is_none() {
        return Err(Error::bag(
            bag,
            "--wheel-joints names the wheels without a radius: its wheel angles need \
             --wheel-radius-m R to become wheel travel",
        ));
    }
    let container = Container::open(bag)?;
    let topic_types = container.topic_types(bag)?;
    let mut chosen = topics::choose(bag, &topic_types, &options.topics)?;
    // TF: each topic of TFMessage, static when named so (`/tf_static`, `/robot1/tf_static`).
    let tf_topics: BTreeMap<String, tf::Source> = topic_types
        .iter()
        .filter(|(_, ty)| Kind::of(ty) == Some(Kind::Tf))
        .map(|(topic, _)| {
            let source = if topic.ends_with("tf_static") {
                tf::Source::Static
            } else {
                tf::Source::Dynamic
            };
            (topic.clone(), source)
        })
        .collect();
    if chosen.is_empty() && !tf_topics.values().any(|s| *s == tf::Source::Dynamic) {
        let all = if topic_types.is_empty() {
            "none".to_string()
        } else {
            topics::listing(
                topic_types.iter().map(|(t, ty)| format!("{t} ({ty})")),
                ", ",
            )
        };
        return Err(Error::bag(
            bag,
            format!(
                "no topic of a type hilsim reads (LaserScan, Odometry, JointState, Twist, \
                 TwistStamped, Range, PoseStamped, TFMessage); topics: {all}"
            ),
        ));
    }
    let mut notes = Vec::new();
    let meta = options.meta.clone().unwrap_or_else(|| {
        let meta = Meta::default();
        let sonar = if chosen.contains_key(&Role::Sonar) {
            "; the sonar at the robot's centre, facing forward"
        } else {
            ""
        };
        notes.push(format!(
            "no --meta: a minimal meta.toml (wheel base {} m, a guess{sonar}); give your \
             robot's with --meta FILE",
            meta.robot.wheel_base_m
        ));
        meta
    });
    let mut meta = meta;
    // Travel from joint angles is their angle times this radius: a calibration of the wheels
    // reads it back to give radii.
    if let Some(radius) = options.wheel_radius_m {
        meta.robot.wheel_radius_m = Some(radius);
    }
    match chosen.get(&Role::Odometry) {
        Some((topic, Kind::JointState)) if options.wheel_radius_m.is_none() => {
            // Asked for (the topic or the joints named): an error. Found by type only (it may
            // be an arm's): skipped, and said so.
            if options.topics.contains_key(&Role::Odometry) || options.wheel_joints.is_some() {
                return Err(Error::bag(
                    bag,
                    format!(
                        "topic {} is sensor_msgs/msg/JointState: its wheel angles need \
                         --wheel-radius-m R to become wheel travel",
                        printable(topic)
                    ),
                ));
            }
            notes.push(format!(
                "{} (JointState) skipped: wheel angles need --wheel-radius-m to become wheel \
                 travel",
                printable(topic)
            ));
            chosen.remove(&Role::Odometry);
        }
        Some((topic, Kind::Odometry | Kind::Tf)) if options.wheel_radius_m.is_some() => {
            notes.push(format!(
                "--wheel-radius-m unused: the odometry is {}'s poses, not wheel angles",
                printable(topic)
            ));
        }
        _ => {}
    }
    if let std::collections::btree_map::Entry::Vacant(odometry) = chosen.entry(Role::Odometry) {
        let dynamic: Vec<&String> = tf_topics
            .iter()
            .filter(|(_, s)| **s == tf::Source::Dynamic)
            .map(|(t, _)| t)
            .collect();
        let topic = dynamic
            .iter()
            .find(|t| t.as_str() == "/tf")
            .or(dynamic.first().filter(|_| dynamic.len() == 1));
        if let Some(topic) = topic {
            notes.push(format!(
                "no Odometry topic: the odometry from {}'s {ODOM_FRAME} → base transforms",
                printable(topic)
            ));
            odometry.insert(((*topic).clone(), Kind::Tf));
        }
    }
    if let Container::Ros2 { channels, .. } = &container {
        for (topic, _) in chosen.values() {
            if let Some(c) = channels.iter().find(|c| &c.topic == topic) {
                if c.message_encoding != "cdr" {
                    return Err(Error::bag(
                        bag,
                        format!(
                            "topic {}: message encoding `{}`, not `cdr` (ROS 2)",
                            printable(topic),
                            printable(&c.message_encoding)
                        ),
                    ));
                }
            }
        }
    }
    let tables = Tables {
        odometry: chosen.contains_key(&Role::Odometry),
        lidar: chosen.contains_key(&Role::Lidar),
        sonar: chosen.contains_key(&Role::Sonar),
        truth: chosen.contains_key(&Role::Truth),
    };
    let mut stream = RecordingStream::create(out, meta.clone(), tables)?;
    let encoding = match container {
        Container::Ros2 { .. } => Encoding::Cdr,
        Container::Ros1 { .. } => Encoding::Ros1,
    };
    let mut converter = Converter::new(&chosen, meta.robot.wheel_base_m, options.wheel_radius_m)
        .with_wheel_joints(options.wheel_joints.clone())
        .with_encoding(encoding)
        .with_tf_topics(tf_topics.clone());
    let mut bytes = 0;
    match &container {
        Container::Ros2 { files, .. } => {
            (converter.t0_ns, converter.clock_offset_ns) = earliest_time(&files[0], &chosen)?;
            for file in files {
                bytes += std::fs::metadata(file).map_or(0, |m| m.len());
                read_file(file, &mut converter, &mut stream)?;
            }
        }
        Container::Ros1 { connections } => {
            (converter.t0_ns, converter.clock_offset_ns) =
                ros1_earliest_time(bag, connections, &chosen)?;
            bytes = std::fs::metadata(bag).map_or(0, |m| m.len());
            notes.extend(read_ros1(bag, connections, &mut converter, &mut stream)?);
        }
    }
    converter.finish(&mut stream)?;
    if let Some((topic, Kind::JointState)) = chosen.get(&Role::Odometry) {
        if !converter.rows.contains_key(&Role::Odometry) {
            let which = match &options.wheel_joints {
                Some([left, right]) => {
                    format!("joints {} and {}", printable(left), printable(right))
                }
                None => format!(
                    "joints named `left` and `right` (the first message's: {}); name the \
                     wheels with --wheel-joints LEFT,RIGHT",
                    topics::listing(&converter.joints_seen, ", ")
                ),
            };
            return Err(Error::bag(
                bag,
                format!(
                    "topic {}: no JointState message has positions for the {which}",
                    printable(topic)
                ),
            ));
        }
    }
    if let Some((topic, Kind::Tf)) = chosen.get(&Role::Odometry) {
        if !converter.rows.contains_key(&Role::Odometry) {
            notes.push(format!(
                "{} has no {ODOM_FRAME} → base transform: odometry.csv is empty",
                printable(topic)
            ));
        }
    }
    // What the bag says of the sensors, where meta.toml did not.
    let final_meta = stream.meta_mut();
    if tables.lidar && final_meta.lidar.is_none() {
        final_meta.lidar = Some(lidar_mount(&converter, &tf_topics, &mut notes));
    }
    if tables.sonar && final_meta.sonar.is_none() {
        let sonar_topic = chosen.get(&Role::Sonar).map_or("", |(t, _)| t.as_str());
        match converter.sonar_fov_rad.and_then(sonar_half_angle_deg) {
            Some(half_angle_deg) => {
                final_meta.sonar = Some(SonarMount {
                    x_m: 0.0,
                    y_m: 0.0,
                    yaw_deg: 0.0,
                    half_angle_deg: decimal_of_f32(half_angle_deg as f32),
                });
                if converter.sonar_fov_unusable > 0 {
                    notes.push(format!(
                        "sonar half-angle from {}'s first usable field_of_view; {} before it \
                         not a number or not within 0..π radians",
                        printable(sonar_topic),
                        converter.sonar_fov_unusable
                    ));
                }
            }
            None => notes.push(format!(
                "no [sonar] in meta.toml: no message of {} has a field_of_view within 0..π \
                 radians to take the half-angle from; give it with --meta FILE",
                printable(sonar_topic)
            )),
        }
    }
    stream.finish()?;
    notes.extend(converter.notes());
    Ok(ImportReport {
        chosen,
        rows: converter.rows,
        bytes,
        notes,
    })
}

/// A value to the nanounit (nanometres, nanodegrees), without a negative zero: what TF's
/// float64 composition gives, without its last-digit noise (`0.12`, not
/// `0.12000000000000001`).
fn to_nano(x: f64) -> f64 {
    (x * 1e9).round() / 1e9 + 0.0
}

/// The lidar's mount from the bag's TF: the scans' frame in the robot's, projected onto the
/// ground (x, y, yaw); the robot's centre facing forward when TF does not say. Each way it was
/// found, or not, is a note.
fn lidar_mount(
    converter: &Converter,
    tf_topics: &BTreeMap<String, tf::Source>,
    notes: &mut Vec<String>,
) -> Mount {
    let tree = &converter.tree;
    let assumed = "lidar mount assumed at the robot's centre, facing forward; give it with \
                   --meta FILE";
    let Some(sensor) = converter.scan_frame.as_deref() else {
        return Mount::default();
    };
    if tree.is_empty() {
        let why = if tf_topics.is_empty() {
            "no /tf_static or /tf"
        } else {
            "no usable transform in /tf_static or /tf"
        };
        notes.push(format!("{why}: {assumed}"));
        return Mount::default();
    }
    let (base, guessed) = match converter.odometry_frame.as_deref() {
        Some(base) => (base, false),
        None => match BASE_FRAMES.iter().find(|b| tree.has(b)) {
            Some(base) => (*base, true),
            None => {
                notes.push(format!(
                    "no robot frame in TF (base_link, base_footprint, or the odometry's child \
                     frame): {assumed}"
                ));
                return Mount::default();
            }
        },
    };
    let Some(found) = tree.mount(base, sensor) else {
        notes.push(format!(
            "TF has no chain of transforms from {} to the scans' frame {}: {assumed}",
            printable(base),
            printable(sensor)
        ));
        return Mount::default();
    };
    let Rigid {
        translation,
        rotation,
    } = found.rigid;
    let mount = Mount {
        x_m: to_nano(translation.x),
        y_m: to_nano(translation.y),
        yaw_deg: to_nano(rotation.yaw().to_degrees()),
    };
    let source = if found.all_static {
        "/tf_static"
    } else if tf_topics.values().any(|s| *s == tf::Source::Static) {
        "/tf_static and /tf"
    } else {
        "/tf (no /tf_static)"
    };
    notes.push(format!(
        "lidar mount from {source} {}→{}: x {} m, y {} m, yaw {}°{}",
        printable(base),
        printable(sensor),
        mount.x_m,
        mount.y_m,
        mount.yaw_deg,
        if guessed {
            format!(" (the robot's frame taken to be {base}: no odometry names it)")
        } else {
            String::new()
        }
    ));
    let tilt = found.rigid.tilt_deg();
    // A degree of tilt moves a 2-D scan's points by under 0.02 % of their range.
    if tilt > 1.0 {
        notes.push(format!(
            "the lidar's frame is tilted {tilt:.1}° from the robot's: its roll and pitch are \
             dropped (a 2-D mount has neither){}",
            if tilt > 90.0 {
                "; upside down, its scans turn the other way round, which the mount cannot say"
            } else {
                ""
            }
        ));
    }
    mount
}

/// Streams one MCAP file through the converter.
///
/// The topics were chosen from the file's summary section when it has one: a channel of the
/// data section that the summary does not list as it is would have its messages lost, so it is
/// an error.
///
/// # Errors
/// As [`import`], and a data section that contradicts the file's summary.
pub fn read_file<S>(file: &Path, converter: &mut Converter, sink: &mut S) -> Result<(), Error>
where
    S: SampleSink<Error = hilsim_recording::Error>,
{
    let summary = bag::summary_channels(file)?;
    // Each chosen channel's role, kind, topic and count of messages so far.
    let mut roles: HashMap<u16, (Role, Kind, String, u64)> = HashMap::new();
    let mut tf_channels: HashMap<u16, tf::Source> = HashMap::new();
    bag::stream(file, |item| match item {
        Item::Channel(c) => {
            if let Some(listed) = &summary {
                check_listed(file, &c, listed)?;
            }
            if let Some((role, (_, kind))) = converter
                .chosen
                .iter()
                .find(|(_, (topic, _))| *topic == c.topic)
            {
                roles.insert(c.id, (*role, *kind, c.topic, 0));
            } else if let Some(source) = converter.tf_topics.get(&c.topic) {
                tf_channels.insert(c.id, *source);
            }
            Ok(())
        }
        Item::Metadata(m) => {
            if m.name == START_METADATA {
                let number = |key: &str| m.metadata.get(key).and_then(|v| v.parse::<f64>().ok());
                if converter.t0_ns.is_none() {
                    converter.t0_ns = m.metadata.get(START_KEY).and_then(|v| v.parse().ok());
                }
                if let [Some(l), Some(r)] = ODOMETRY_START_KEYS.map(number) {
                    converter.odometry_start_m = (l, r);
                }
            }
            Ok(())
        }
        Item::Message {
            channel_id,
            log_time,
            data,
        } => {
            if let Some(source) = tf_channels.get(&channel_id) {
                converter.tf(*source, data);
                return Ok(());
            }
            let Some((role, kind, topic, count)) = roles.get_mut(&channel_id) else {
                return Ok(());
            };
            *count += 1;
            let log_ns = i64::try_from(log_time).unwrap_or(i64::MAX);
            converter
                .message(*role, *kind, log_ns, data, sink)
                .map_err(|err| match err {
                    Fault::Message(message) => Error::bag(
                        file,
                        format!("topic {}, message {count}: {message}", printable(topic)),
                    ),
                    Fault::Sink(err) => Error::Recording(err),
                })
        }
    })
}

/// Where a ROS 1 connection's messages go.
enum Route {
    /// A table's topic: its role, kind and name.
    Table(Role, Kind, String),
    /// A TF topic that feeds no table.
    Tf(tf::Source),
}

fn route(converter: &Converter, topic: &str) -> Option<Route> {
    if let Some((role, (_, kind))) = converter.chosen.iter().find(|(_, (t, _))| t == topic) {
        return Some(Route::Table(*role, *kind, topic.to_string()));
    }
    converter.tf_topics.get(topic).map(|s| Route::Tf(*s))
}

/// Messages of a topic that did not decode: how many, of how many, and why the first did not.
#[derive(Default)]
struct Undecoded {
    bad: u64,
    seen: u64,
    first: String,
}

/// Streams a ROS 1 bag through the converter. Damage to the bag and messages that do not
/// decode are counted, and returned as notes.
///
/// # Errors
/// Not a ROS 1 bag, or the recording cannot be written.
fn read_ros1<S>(
    file: &Path,
    connections: &[ros1::Connection],
    converter: &mut Converter,
    sink: &mut S,
) -> Result<Vec<String>, Error>
where
    S: SampleSink<Error = hilsim_recording::Error>,
{
    let mut routes: HashMap<u32, Route> = HashMap::new();
    for c in connections {
        if let Some(r) = route(converter, &c.topic) {
            routes.insert(c.id, r);
        }
    }
    let mut undecoded: BTreeMap<String, Undecoded> = BTreeMap::new();
    let damage = ros1::stream_while(file, |item| {
        match item {
            ros1::Item::Connection(c) => {
                if let std::collections::hash_map::Entry::Vacant(e) = routes.entry(c.id) {
                    if let Some(r) = route(converter, &c.topic) {
                        e.insert(r);
                    }
                }
            }
            ros1::Item::Message {
                conn,
                time_ns,
                data,
            } => match routes.get(&conn) {
                Some(Route::Tf(source)) => converter.tf(*source, data),
                Some(Route::Table(role, kind, topic)) => {
                    let counted = undecoded.entry(topic.clone()).or_default();
                    counted.seen += 1;
                    match converter.message(*role, *kind, time_ns, data, sink) {
                        Ok(()) => {}
                        Err(Fault::Message(why)) => {
                            counted.bad += 1;
                            if counted.first.is_empty() {
                                counted.first = why;
                            }
                        }
                        Err(Fault::Sink(err)) => return Err(Error::Recording(err)),
                    }
                }
                None => {}
            },
        }
        Ok(true)
    })?;
    let mut notes = damage.notes();
    for (topic, u) in undecoded.iter().filter(|(_, u)| u.bad > 0) {
        notes.push(format!(
            "{} of {}'s {} messages skipped: {} (the first)",
            u.bad,
            printable(topic),
            u.seen,
            u.first
        ));
    }
    Ok(notes)
}

/// A data-section channel against the summary's list: the same id must be there with the same
/// topic, type and encoding.
fn check_listed(file: &Path, channel: &bag::Channel, listed: &[bag::Channel]) -> Result<(), Error> {
    let shown = |c: &bag::Channel| format!("{} ({})", printable(&c.topic), printable(&c.type_name));
    match listed.iter().find(|l| l.id == channel.id) {
        Some(l) if l == channel => Ok(()),
        Some(l) => Err(Error::bag(
            file,
            format!(
                "channel {} is {} in the data section but {} in the summary section: the file \
                 contradicts itself (altered or damaged)",
                channel.id,
                shown(channel),
                shown(l)
            ),
        )),
        None => Err(Error::bag(
            file,
            format!(
                "channel {} ({}) is in the data section but not in the summary section: the file \
                 contradicts itself (altered or damaged)",
                channel.id,
                shown(channel)
            ),
        )),
    }
}

/// How far into a bag (log time) the earliest message is looked for: a scan's stamp is its first
/// reading's, logged a revolution or more later, after other topics' messages.
const EARLIEST_WITHIN_NS: i64 = 10_000_000_000;

/// The earliest stamped and unstamped times among the first messages of the chosen topics, and
/// the stamps' clock against the log clock (see [`earliest_time`]).
#[derive(Default)]
struct Earliest {
    stamped: Option<i64>,
    unstamped: Option<i64>,
    first_log: Option<i64>,
    offset: Option<i64>,
}

impl Earliest {
    /// Sees a message of `kind` logged at `log_ns`; `false` once past the window.
    fn see(&mut self, kind: Kind, encoding: Encoding, log_ns: i64, data: &[u8]) -> bool {
        let first = *self.first_log.get_or_insert(log_ns);
        if log_ns.saturating_sub(first) > EARLIEST_WITHIN_NS {
            return false;
        }
        if kind == Kind::Twist {
            self.unstamped = Some(self.unstamped.map_or(log_ns, |t| t.min(log_ns)));
        } else if let Some(stamp) = first_stamp(kind, encoding, data).filter(|s| !s.is_zero()) {
            let ns = stamp.ns();
            self.stamped = Some(self.stamped.map_or(ns, |t| t.min(ns)));
            self.offset.get_or_insert(clock_offset(ns, log_ns));
        }
        true
    }

    /// The recording's t = 0 and the clock offset.
    fn result(&self) -> (Option<i64>, Option<i64>) {
        let t0 = match (self.stamped, self.unstamped) {
            // Unstamped messages count when they are on the stamps' clock.
            (Some(s), Some(u)) if (s - u).abs() <= OTHER_CLOCK_NS => Some(s.min(u)),
            (Some(s), _) => Some(s),
            (None, u) => u,
        };
        (t0, self.offset)
    }
}

/// The recording's t = 0: an export's own start, else the earliest time among the first messages
/// of the chosen topics (each topic's first within the bag's first 10 s of log time): its header
/// stamp, or the log time of an unstamped one on the same clock. `None` when none is found
/// (the first message converted then sets it).
///
/// With it, the stamps' clock minus the log clock, as the first stamped message says (see
/// [`Converter::stamped`]): known before the first message is converted, a message stamped zero
/// at a simulator's start (time 0, or no stamp at all) is put on the stamps' clock too, not at
/// its wall-clock log time.
///
/// # Errors
/// As [`bag::stream`].
fn earliest_time(file: &Path, chosen: &Chosen) -> Result<(Option<i64>, Option<i64>), Error> {
    let mut roles: HashMap<u16, Kind> = HashMap::new();
    let mut earliest = Earliest::default();
    let mut start = None;
    bag::stream_while(file, |item| {
        match item {
            Item::Channel(c) => {
                if let Some((_, kind)) = chosen.values().find(|(topic, _)| *topic == c.topic) {
                    roles.insert(c.id, *kind);
                }
            }
            Item::Metadata(m) if m.name == START_METADATA => {
                start = m
                    .metadata
                    .get(START_KEY)
                    .and_then(|v| v.parse::<i64>().ok());
                return Ok(start.is_none());
            }
            Item::Metadata(_) => {}
            Item::Message {
                channel_id,
                log_time,
                data,
            } => {
                let log_ns = i64::try_from(log_time).unwrap_or(i64::MAX);
                return Ok(match roles.get(&channel_id) {
                    Some(kind) => earliest.see(*kind, Encoding::Cdr, log_ns, data),
                    None => {
                        log_ns.saturating_sub(*earliest.first_log.get_or_insert(log_ns))
                            <= EARLIEST_WITHIN_NS
                    }
                });
            }
        }
        Ok(true)
    })?;
    if start.is_some() {
        return Ok((start, None));
    }
    Ok(earliest.result())
}

/// [`earliest_time`] of a ROS 1 bag (which has no export's start).
///
/// # Errors
/// Not a ROS 1 bag.
fn ros1_earliest_time(
    file: &Path,
    connections: &[ros1::Connection],
    chosen: &Chosen,
) -> Result<(Option<i64>, Option<i64>), Error> {
    let kind_of = |topic: &str| {
        chosen
            .values()
            .find(|(t, _)| t == topic)
            .map(|(_, kind)| *kind)
    };
    let mut kinds: HashMap<u32, Kind> = connections
        .iter()
        .filter_map(|c| Some((c.id, kind_of(&c.topic)?)))
        .collect();
    let mut earliest = Earliest::default();
    ros1::stream_while(file, |item| {
        Ok(match item {
            ros1::Item::Connection(c) => {
                if let Some(kind) = kind_of(&c.topic) {
                    kinds.insert(c.id, kind);
                }
                true
            }
            ros1::Item::Message {
                conn,
                time_ns,
                data,
            } => match kinds.get(&conn) {
                Some(kind) => earliest.see(*kind, Encoding::Ros1, time_ns, data),
                None => {
                    time_ns.saturating_sub(*earliest.first_log.get_or_insert(time_ns))
                        <= EARLIEST_WITHIN_NS
                }
            },
        })
    })?;
    Ok(earliest.result())
}

/// The stamps' clock minus the log clock from a message's stamp and log time: the difference
/// when it says the two are different clocks, else 0 (transport delay is left alone).
fn clock_offset(stamp_ns: i64, log_ns: i64) -> i64 {
    let offset = stamp_ns - log_ns;
    if offset.abs() > OTHER_CLOCK_NS {
        offset
    } else {
        0
    }
}

/// Why a message could not be converted.
pub enum Fault {
    /// The message is bad (what is wrong).
    Message(String),
    /// The recording could not take the sample.
    Sink(hilsim_recording::Error),
}

impl From<hilsim_recording::Error> for Fault {
    fn from(err: hilsim_recording::Error) -> Self {
        Self::Sink(err)
    }
}

/// Messages into samples: times, revolutions, wheel travel and the order of each table.
pub struct Converter {
    chosen: Chosen,
    wheel_base_m: f64,
    wheel_radius_m: Option<f64>,
    wheel_joints: Option<[String; 2]>,
    /// Messages skipped for a value that is not finite, by table.
    not_finite: BTreeMap<Role, u64>,
    /// `JointState` messages without the wheels' positions.
    joints_missing: u64,
    /// The joints of the first such message, for the error when no message has the wheels.
    joints_seen: Vec<String>,
    /// The recording's t = 0 on the stamps' clock, ns.
    t0_ns: Option<i64>,
    /// Stamp clock minus log clock, once a stamped message has said.
    clock_offset_ns: Option<i64>,
    pending_commands: Vec<(i64, Twist)>,
    /// Each table's time order.
    clocks: BTreeMap<Role, TableClock>,
    rows: BTreeMap<Role, u64>,
    rev: u64,
    odometry: Option<OdometryState>,
    /// The wheel travel at the first odometry message.
    odometry_start_m: (f64, f64),
    sonar_out_of_range: u64,
    /// The first usable `field_of_view`, and the count of unusable ones before it.
    sonar_fov_rad: Option<f64>,
    sonar_fov_unusable: u64,
    /// The last scan's reading angles: a lidar's scans share them.
    scan_angles: ScanAngles,
    /// How the messages' bytes are laid out.
    encoding: Encoding,
    /// The TF topics, and whether each is static.
    tf_topics: BTreeMap<String, tf::Source>,
    /// The bag's TF frames.
    tree: tf::Tree,
    /// TF messages that did not decode.
    tf_undecoded: u64,
    /// The first scan's frame.
    scan_frame: Option<String>,
    /// The robot's frame as the odometry names it (an `Odometry`'s child frame, or the child
    /// of TF's odom → base transforms).
    odometry_frame: Option<String>,
}

/// Each reading's angle of a scan's `angle_min` and `angle_increment`, computed once for the
/// scans that share them (every scan of a lidar, usually) rather than once a reading.
#[derive(Default)]
struct ScanAngles {
    /// The float32 fields' bits, as the message gave them.
    angle_min: u32,
    increment: u32,
    /// Ten-thousandths of a degree, [0, 3,600,000) ([`angle_e4_deg`]).
    e4_deg: Vec<u32>,
}

impl ScanAngles {
    /// The angles of the first `count` readings of a scan with these fields; `None` when either
    /// is not finite.
    fn of(&mut self, angle_min: f32, increment: f32, count: usize) -> Option<&[u32]> {
        if !(angle_min.is_finite() && increment.is_finite()) {
            return None;
        }
        let same = self.angle_min == angle_min.to_bits() && self.increment == increment.to_bits();
        if !same || self.e4_deg.len() < count {
            let (start, step) = (decimal_of_f32(angle_min), decimal_of_f32(increment));
            self.angle_min = angle_min.to_bits();
            self.increment = increment.to_bits();
            self.e4_deg.clear();
            self.e4_deg
                .extend((0..count).map(|i| angle_e4_deg(start + i as f64 * step)));
        }
        Some(&self.e4_deg[..count])
    }
}

/// A table's time order: the latest time written, and the rows that came earlier than it.
#[derive(Default)]
struct TableClock {
    last_us: u64,
    reordered: u64,
    worst_us: u64,
}

impl TableClock {
    /// `t_us`, or the latest time written when `t_us` is earlier (counted; a time before
    /// t = 0 is put at 0).
    fn order(&mut self, t_us: i64) -> u64 {
        match u64::try_from(t_us) {
            Ok(t) if t >= self.last_us => {
                self.last_us = t;
                t
            }
            _ => {
                self.reordered += 1;
                let early = i128::from(self.last_us) - i128::from(t_us);
                self.worst_us = self.worst_us.max(u64::try_from(early).unwrap_or(u64::MAX));
                self.last_us
            }
        }
    }
}

/// Microseconds of `ns` plus `extra_ns`, to the nearest (the difference from t = 0 taken in
/// integers first, as a stamp, ~1.7e18 ns, is finer than an f64 resolves).
fn microseconds(ns_from_start: i64, extra_ns: f64) -> i64 {
    round_half_away((ns_from_start as f64 + extra_ns) / 1e3) as i64
}

/// Seconds of a whole number of microseconds: the `f64` closest to the decimal.
fn seconds_of(us: u64) -> f64 {
    us as f64 / 1e6
}

/// `f64::round` (half away from zero) without its call into the C library, which the
/// baseline x86-64 target has no instruction for: it was a tenth of an import's time.
fn round_half_away(x: f64) -> f64 {
    // 2⁵²: from here on every f64 is whole (and NaN, ±inf pass through).
    if x.is_nan() || x.abs() >= 4_503_599_627_370_496.0 {
        return x;
    }
    // |x| < 2⁵²: the cast truncates exactly, and `x - whole` is exact.
    let whole = x as i64 as f64;
    let fraction = x - whole;
    if fraction >= 0.5 {
        whole + 1.0
    } else if fraction <= -0.5 {
        whole - 1.0
    } else {
        // Keeps the sign of a zero, as `round` does.
        whole.copysign(x)
    }
}

/// The last pose (or wheel angles) and the wheel travel so far.
enum OdometryState {
    Pose {
        x: f64,
        y: f64,
        yaw: f64,
        left_m: f64,
        right_m: f64,
    },
    Joints {
        /// The wheels' joint names, and their indices in the last message (a hint: messages
        /// may list different joints).
        names: [String; 2],
        at: [usize; 2],
        /// The angles at the first message, radians.
        start: [f64; 2],
    },
}

impl Converter {
    /// A converter of the `chosen` topics, for a robot of this wheel base (and wheel radius, for
    /// joint angles).
    #[must_use]
    pub fn new(chosen: &Chosen, wheel_base_m: f64, wheel_radius_m: Option<f64>) -> Self {
        Self {
            chosen: chosen.clone(),
            wheel_base_m,
            wheel_radius_m,
            wheel_joints: None,
            not_finite: BTreeMap::new(),
            joints_missing: 0,
            joints_seen: Vec::new(),
            t0_ns: None,
            clock_offset_ns: None,
            pending_commands: Vec::new(),
            clocks: BTreeMap::new(),
            rows: BTreeMap::new(),
            rev: 0,
            odometry: None,
            odometry_start_m: (0.0, 0.0),
            sonar_out_of_range: 0,
            sonar_fov_rad: None,
            sonar_fov_unusable: 0,
            scan_angles: ScanAngles::default(),
            encoding: Encoding::Cdr,
            tf_topics: BTreeMap::new(),
            tree: tf::Tree::default(),
            tf_undecoded: 0,
            scan_frame: None,
            odometry_frame: None,
        }
    }

    /// Messages laid out as `encoding` (default: ROS 2's CDR).
    #[must_use]
    pub fn with_encoding(mut self, encoding: Encoding) -> Self {
        self.encoding = encoding;
        self
    }

    /// The topics of `tf2_msgs/TFMessage`, each static (`/tf_static`) or not, whose messages
    /// [`Converter::tf`] takes.
    #[must_use]
    pub fn with_tf_topics(mut self, topics: BTreeMap<String, tf::Source>) -> Self {
        self.tf_topics = topics;
        self
    }

    /// Keeps a TF message's transforms (one that does not decode is counted).
    pub fn tf(&mut self, source: tf::Source, data: &[u8]) {
        match decode_as::<TfMessage>(self.encoding, data, 0) {
            Ok(message) => {
                for t in &message.transforms {
                    self.tree.add(source, t);
                }
            }
            Err(_) => self.tf_undecoded += 1,
        }
    }

    fn decode<T: Wire>(&self, data: &[u8], appended: usize) -> Result<T, String> {
        decode_as(self.encoding, data, appended)
    }

    /// The left and right wheels' joints by name (else the joints named `…left…` and
    /// `…right…`).
    #[must_use]
    pub fn with_wheel_joints(mut self, names: Option<[String; 2]>) -> Self {
        self.wheel_joints = names;
        self
    }

    /// The time of a stamped message on the stamps' clock (a zero stamp, which a driver that
    /// sets none leaves, is replaced by the log time).
    fn stamped(&mut self, stamp: Time, log_ns: i64) -> i64 {
        if stamp.is_zero() {
            return log_ns + self.clock_offset_ns.unwrap_or(0);
        }
        let ns = stamp.ns();
        if self.clock_offset_ns.is_none() {
            let offset = clock_offset(ns, log_ns);
            self.clock_offset_ns = Some(offset);
            let first_pending = self.pending_commands.first().map(|(log, _)| log + offset);
            if self.t0_ns.is_none() {
                self.t0_ns = Some(first_pending.map_or(ns, |p| p.min(ns)));
            }
        }
        ns
    }

    /// Seconds from t = 0, to the microsecond (what a recording keeps: `0.15`, not
    /// `0.15000000000000002`; far below any sensor's timing), in the table's order.
    /// `ns` on the stamps' clock plus `extra_ns` (a reading's offset within its scan): the
    /// difference from t = 0 is taken in integers first, as a stamp (~1.7e18 ns) is finer than
    /// an f64 resolves.
    fn seconds(&mut self, role: Role, ns: i64, extra_ns: f64) -> f64 {
        let t0 = *self.t0_ns.get_or_insert(ns);
        let t_us = microseconds(ns - t0, extra_ns);
        seconds_of(self.clocks.entry(role).or_default().order(t_us))
    }

    /// Counts a message skipped for a NaN or infinite value (a driver's "unknown").
    fn not_finite(&mut self, role: Role) {
        *self.not_finite.entry(role).or_insert(0) += 1;
    }

    fn count(&mut self, role: Role, n: u64) {
        *self.rows.entry(role).or_insert(0) += n;
    }

    /// Converts one message of `role`'s topic into samples for `sink`.
    ///
    /// # Errors
    /// The message does not decode as `kind`, or `sink` fails.
    pub fn message<S>(
        &mut self,
        role: Role,
        kind: Kind,
        log_ns: i64,
        data: &[u8],
        sink: &mut S,
    ) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        self.convert(role, kind, log_ns, data, sink)?;
        // Commands held for want of a clock go out as soon as a stamped message gives it,
        // before any later command.
        if let Some(offset) = self.clock_offset_ns {
            for (log_ns, twist) in std::mem::take(&mut self.pending_commands) {
                self.command(log_ns + offset, &twist, sink)?;
            }
        }
        Ok(())
    }

    fn convert<S>(
        &mut self,
        role: Role,
        kind: Kind,
        log_ns: i64,
        data: &[u8],
        sink: &mut S,
    ) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let bad = |err: String| Fault::Message(format!("not a {} ({err})", kind.ros_name()));
        match (role, kind) {
            (Role::Lidar, _) => {
                let scan: LaserScan = self.decode(data, 0).map_err(bad)?;
                if self.scan_frame.is_none() {
                    self.scan_frame = Some(tf::frame(&scan.header.frame_id).to_string());
                }
                self.scan(&scan, log_ns, sink)
            }
            (Role::Sonar, _) => {
                // Rolling appends `variance` (a float32) to Range.
                let range: Range = self.decode(data, 4).map_err(bad)?;
                let ns = self.stamped(range.header.stamp, log_ns);
                if self.sonar_fov_rad.is_none() {
                    let fov = f64::from(range.field_of_view);
                    if sonar_half_angle_deg(fov).is_some() {
                        self.sonar_fov_rad = Some(fov);
                    } else {
                        self.sonar_fov_unusable += 1;
                    }
                }
                let valid = range.range.is_finite()
                    && range.range > 0.0
                    && range.range >= range.min_range
                    && range.range <= range.max_range;
                if !valid {
                    self.sonar_out_of_range += 1;
                    return Ok(());
                }
                let t_s = self.seconds(role, ns, 0.0);
                self.count(role, 1);
                Ok(sink.sonar(&SonarSample {
                    t_s,
                    range_m: decimal_of_f32(range.range),
                    true_range_m: None,
                })?)
            }
            (Role::Commands, Kind::TwistStamped) => {
                let twist: TwistStamped = self.decode(data, 0).map_err(bad)?;
                let ns = self.stamped(twist.header.stamp, log_ns);
                self.command(ns, &twist.twist, sink)
            }
            (Role::Commands, _) => {
                let twist: Twist = self.decode(data, 0).map_err(bad)?;
                match self.clock_offset_ns {
                    Some(offset) => self.command(log_ns + offset, &twist, sink),
                    None if self.pending_commands.len() < MAX_PENDING_COMMANDS => {
                        self.pending_commands.push((log_ns, twist));
                        Ok(())
                    }
                    None => Err(Fault::Message(format!(
                        "{MAX_PENDING_COMMANDS} commands (unstamped Twist) before any stamped \
                         message: no clock to put them on; record them as TwistStamped"
                    ))),
                }
            }
            (Role::Truth, Kind::Odometry) => {
                let odometry: Odometry = self.decode(data, 0).map_err(bad)?;
                let ns = self.stamped(odometry.header.stamp, log_ns);
                self.truth(ns, &odometry.pose.pose, sink)
            }
            (Role::Truth, _) => {
                let pose: PoseStamped = self.decode(data, 0).map_err(bad)?;
                let ns = self.stamped(pose.header.stamp, log_ns);
                self.truth(ns, &pose.pose, sink)
            }
            (Role::Odometry, Kind::JointState) => {
                let joints: JointState = self.decode(data, 0).map_err(bad)?;
                let ns = self.stamped(joints.header.stamp, log_ns);
                self.joints(ns, &joints, sink)
            }
            (Role::Odometry, Kind::Tf) => {
                let message: TfMessage = self.decode(data, 0).map_err(bad)?;
                for t in &message.transforms {
                    self.tree.add(tf::Source::Dynamic, t);
                    let (parent, child) =
                        (tf::frame(&t.header.frame_id), tf::frame(&t.child_frame_id));
                    if parent.rsplit('/').next() != Some(ODOM_FRAME) {
                        continue;
                    }
                    // The first child of odom is the robot (odom → base_footprint when a
                    // robot has both: base_link is then below base_footprint).
                    let base = self.odometry_frame.get_or_insert_with(|| child.to_string());
                    if base != child {
                        continue;
                    }
                    let ns = self.stamped(t.header.stamp, log_ns);
                    let pose = Pose {
                        position: t.transform.translation,
                        orientation: t.transform.rotation,
                    };
                    self.odometry(ns, &pose, sink)?;
                }
                Ok(())
            }
            (Role::Odometry, _) => {
                let odometry: Odometry = self.decode(data, 0).map_err(bad)?;
                if self.odometry_frame.is_none() && !odometry.child_frame_id.is_empty() {
                    self.odometry_frame = Some(tf::frame(&odometry.child_frame_id).to_string());
                }
                let ns = self.stamped(odometry.header.stamp, log_ns);
                self.odometry(ns, &odometry.pose.pose, sink)
            }
        }
    }

    /// One revolution: reading i at `angle_min + i·angle_increment` (wrapped into [0, 360)),
    /// taken at the stamp plus `i·time_increment`.
    fn scan<S>(&mut self, scan: &LaserScan, log_ns: i64, sink: &mut S) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let ns = self.stamped(scan.header.stamp, log_ns);
        if scan.ranges.is_empty() {
            return Ok(());
        }
        let time_increment_ns = decimal_of_f32(scan.time_increment) * 1e9;
        let angles = self
            .scan_angles
            .of(scan.angle_min, scan.angle_increment, scan.ranges.len());
        let Some(angles) = angles.filter(|_| time_increment_ns.is_finite()) else {
            self.not_finite(Role::Lidar);
            return Ok(());
        };
        let (range_min, range_max) = (scan.range_min, scan.range_max);
        let from_start_ns = ns - *self.t0_ns.get_or_insert(ns);
        let clock = self.clocks.entry(Role::Lidar).or_default();
        for (i, (&range, &angle_e4_deg)) in scan.ranges.iter().zip(angles).enumerate() {
            let t_us = clock.order(microseconds(from_start_ns, i as f64 * time_increment_ns));
            // 0 is no echo too (drivers that leave range_min 0 send it for none).
            let valid =
                range.is_finite() && range > 0.0 && range >= range_min && range <= range_max;
            // The nearest whole strength (half away from zero, as `round`; exact in f64).
            let strength = scan
                .intensities
                .get(i)
                .filter(|s| s.is_finite())
                .map_or(0, |&s| (f64::from(s.clamp(0.0, 65_535.0)) + 0.5) as u16);
            let range_decimal = if valid {
                short_decimal_of_f32(range)
            } else {
                Some((0, 0))
            };
            if let Some((range_digits, range_scale)) = range_decimal {
                sink.lidar_decimals(&LidarDecimals {
                    t_us,
                    rev: self.rev,
                    angle_e4_deg,
                    range_digits,
                    range_scale,
                    strength,
                    invalid: !valid,
                    warning: false,
                })?;
            } else {
                // A range of more than 6 significant digits (a float lidar's noise).
                sink.lidar(&LidarSample {
                    t_s: seconds_of(t_us),
                    rev: self.rev,
                    angle_deg: f64::from(angle_e4_deg) / 1e4,
                    range_m: decimal_of_f32(range),
                    strength,
                    invalid: false,
                    warning: false,
                    true_range_m: None,
                })?;
            }
        }
        self.count(Role::Lidar, scan.ranges.len() as u64);
        self.rev += 1;
        Ok(())
    }

    /// A velocity command as the wheel speeds of a differential drive.
    fn command<S>(&mut self, ns: i64, twist: &Twist, sink: &mut S) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let (v, w) = (twist.linear.x, twist.angular.z);
        let half = 0.5 * self.wheel_base_m * w;
        // Speeds near f64's limit can sum beyond it.
        if ![v, w, v - half, v + half].iter().all(|x| x.is_finite()) {
            self.not_finite(Role::Commands);
            return Ok(());
        }
        let t_s = self.seconds(Role::Commands, ns, 0.0);
        self.count(Role::Commands, 1);
        Ok(sink.command(&CommandSample {
            t_s,
            left_mps: v - half,
            right_mps: v + half,
        })?)
    }

    fn truth<S>(&mut self, ns: i64, pose: &crate::msgs::Pose, sink: &mut S) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let (x_m, y_m, yaw_rad) = (pose.position.x, pose.position.y, pose.orientation.yaw());
        if ![x_m, y_m, yaw_rad].iter().all(|v| v.is_finite()) {
            self.not_finite(Role::Truth);
            return Ok(());
        }
        let t_s = self.seconds(Role::Truth, ns, 0.0);
        self.count(Role::Truth, 1);
        Ok(sink.truth(&TruthSample {
            t_s,
            x_m,
            y_m,
            yaw_rad,
        })?)
    }

    /// Wheel travel rebuilt from the pose increments: over a step the robot turns by dθ and
    /// moves ds along its mean heading (the midpoint rule of differential-drive odometry), so
    /// the wheels, b apart, travel ds ∓ dθ·b/2.
    fn odometry<S>(&mut self, ns: i64, pose: &Pose, sink: &mut S) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let (x, y, yaw) = (pose.position.x, pose.position.y, pose.orientation.yaw());
        if ![x, y, yaw].iter().all(|v| v.is_finite()) {
            self.not_finite(Role::Odometry);
            return Ok(());
        }
        let (left_m, right_m) = match &mut self.odometry {
            Some(OdometryState::Pose {
                x: x0,
                y: y0,
                yaw: yaw0,
                left_m,
                right_m,
            }) => {
                let turn = wrap_angle(yaw - *yaw0);
                let heading = *yaw0 + 0.5 * turn;
                let ds = (x - *x0) * heading.cos() + (y - *y0) * heading.sin();
                *left_m += ds - 0.5 * turn * self.wheel_base_m;
                *right_m += ds + 0.5 * turn * self.wheel_base_m;
                (*x0, *y0, *yaw0) = (x, y, yaw);
                // To the nanometre, far below any encoder's tick: the rounding error of the
                // sums (1e-17 m a step) does not show, and a millimetre stays `0.002`. (Beyond
                // 1e290 m there are no nanometres to round to.)
                let nm = |m: f64| {
                    let scaled = m * 1e9;
                    if scaled.is_finite() {
                        scaled.round() / 1e9
                    } else {
                        m
                    }
                };
                (nm(*left_m), nm(*right_m))
            }
            _ => {
                let (left_m, right_m) = self.odometry_start_m;
                self.odometry = Some(OdometryState::Pose {
                    x,
                    y,
                    yaw,
                    left_m,
                    right_m,
                });
                (left_m, right_m)
            }
        };
        if !(left_m.is_finite() && right_m.is_finite()) {
            // The poses are finite but so far apart that the travel between them is not a
            // number: the rows after it would all be wrong.
            return Err(Fault::Message(format!(
                "a pose at ({x:e}, {y:e}) m that puts the wheel travel beyond any number"
            )));
        }
        let t_s = self.seconds(Role::Odometry, ns, 0.0);
        self.count(Role::Odometry, 1);
        Ok(sink.odometry(&OdometrySample {
            t_s,
            left_m,
            right_m,
        })?)
    }

    /// Wheel travel from the wheel joints' angles: the angle turned since the first message
    /// times the radius. The wheels are the joints named with `--wheel-joints`, else the one
    /// joint whose name has `left` (`right`) in it, or the one of those with `wheel` too. A
    /// message without the wheels' positions (a driver may publish its joints in groups) is
    /// skipped and counted.
    fn joints<S>(&mut self, ns: i64, joints: &JointState, sink: &mut S) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let radius = self.wheel_radius_m.unwrap_or(0.0);
        if self.odometry.is_none() {
            let names = match &self.wheel_joints {
                Some(names) => names.clone(),
                None => match [
                    wheel_joint(&joints.name, "left")?,
                    wheel_joint(&joints.name, "right")?,
                ] {
                    [Some(left), Some(right)] => [left, right],
                    // Another group of joints (an arm's): the wheels may come in the next.
                    _ => {
                        self.joints_missing += 1;
                        if self.joints_seen.is_empty() {
                            self.joints_seen.clone_from(&joints.name);
                        }
                        return Ok(());
                    }
                },
            };
            self.odometry = Some(OdometryState::Joints {
                names,
                at: [0, 0],
                start: [f64::NAN; 2],
            });
        }
        let Some(OdometryState::Joints { names, at, start }) = &mut self.odometry else {
            return Ok(());
        };
        let mut angles = [0.0; 2];
        for side in 0..2 {
            let found = if joints.name.get(at[side]) == Some(&names[side]) {
                Some(at[side])
            } else {
                joints.name.iter().position(|n| *n == names[side])
            };
            match found.and_then(|i| Some((i, *joints.position.get(i)?))) {
                Some((i, angle)) if angle.is_finite() => {
                    at[side] = i;
                    angles[side] = angle;
                }
                _ => {
                    self.joints_missing += 1;
                    return Ok(());
                }
            }
        }
        if start[0].is_nan() {
            *start = angles;
        }
        let (left_m, right_m) = (
            (angles[0] - start[0]) * radius,
            (angles[1] - start[1]) * radius,
        );
        if !(left_m.is_finite() && right_m.is_finite()) {
            return Err(Fault::Message(format!(
                "wheel angles ({:e}, {:e}) rad so far from the first ones that the wheel travel \
                 is beyond any number",
                angles[0], angles[1]
            )));
        }
        let t_s = self.seconds(Role::Odometry, ns, 0.0);
        self.count(Role::Odometry, 1);
        Ok(sink.odometry(&OdometrySample {
            t_s,
            left_m,
            right_m,
        })?)
    }

    /// Writes what waits for the end: commands that never met a stamped message.
    ///
    /// # Errors
    /// `sink` fails.
    pub fn finish<S>(&mut self, sink: &mut S) -> Result<(), Error>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let offset = *self.clock_offset_ns.get_or_insert(0);
        for (log_ns, twist) in std::mem::take(&mut self.pending_commands) {
            self.command(log_ns + offset, &twist, sink)
                .map_err(|err| match err {
                    Fault::Sink(err) => Error::Recording(err),
                    Fault::Message(m) => Error::Bag {
                        path: "commands".into(),
                        message: m,
                    },
                })?;
        }
        Ok(())
    }

    /// Sentences on what was repaired or skipped.
    #[must_use]
    pub fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        for (role, clock) in self.clocks.iter().filter(|(_, c)| c.reordered > 0) {
            notes.push(format!(
                "{} {role} rows came before the row written ahead of them (by up to {:.3} ms) \
                 and were put at its time",
                clock.reordered,
                clock.worst_us as f64 / 1e3
            ));
        }
        for (role, count) in &self.not_finite {
            notes.push(format!(
                "{count} {role} messages with a value that is not finite (NaN, inf) skipped"
            ));
        }
        if self.joints_missing > 0 {
            let names = match &self.odometry {
                Some(OdometryState::Joints { names, .. }) => topics::listing(names, " and "),
                _ => "the wheels".to_string(),
            };
            notes.push(format!(
                "{} JointState messages without a position for {names} skipped",
                self.joints_missing
            ));
        }
        if self.tf_undecoded > 0 {
            notes.push(format!(
                "{} TF messages skipped: not a tf2_msgs/TFMessage",
                self.tf_undecoded
            ));
        }
        if self.tree.dropped > 0 {
            notes.push(format!(
                "{} TF transforms not kept (not a rotation, a frame its own parent, or beyond \
                 {} frames)",
                self.tree.dropped,
                tf::FRAME_LIMIT
            ));
        }
        if self.sonar_out_of_range > 0 {
            notes.push(format!(
                "{} sonar readings out of their min..max range (no echo) skipped",
                self.sonar_out_of_range
            ));
        }
        notes
    }
}

/// A sonar's half-angle, degrees, of a `sensor_msgs/Range` `field_of_view` (radians): `None`
/// unless it is a number and the half-angle within [0°, 90°), as `meta.toml` requires.
fn sonar_half_angle_deg(field_of_view_rad: f64) -> Option<f64> {
    let half_angle_deg = (0.5 * field_of_view_rad).to_degrees();
    (0.0..90.0)
        .contains(&half_angle_deg)
        .then_some(half_angle_deg)
}

/// The wheel joint of one `side` (`left`, `right`) among a JointState's names: the one whose
/// name has the side in it (any case), or, of several, the one that also has `wheel`.
/// `None` when no joint has the side in its name; an error when several do and not one of them
/// has `wheel`.
fn wheel_joint(names: &[String], side: &str) -> Result<Option<String>, Fault> {
    let has = |name: &str, word: &str| name.to_lowercase().contains(word);
    let sided: Vec<&String> = names.iter().filter(|n| has(n, side)).collect();
    let wheels: Vec<&String> = sided.iter().copied().filter(|n| has(n, "wheel")).collect();
    match (sided.as_slice(), wheels.as_slice()) {
        ([], _) => Ok(None),
        ([one], _) | (_, [one]) => Ok(Some((*one).clone())),
        _ => Err(Fault::Message(format!(
            "which joints are the wheels? several of the joints {} are named `{side}`; \
             name the wheels with --wheel-joints LEFT,RIGHT",
            topics::listing(names, ", ")
        ))),
    }
}

/// A float32 field as the decimal it was written as: the shortest decimal that reads back as
/// that float32 (`1.234`, not `1.2339999675750732`), so that millimetre ranges stay millimetres
/// and a recording exported and imported keeps its numbers.
#[must_use]
pub fn decimal_of_f32(x: f32) -> f64 {
    if !x.is_finite() {
        return f64::from(x);
    }
    if let Some((digits, scale)) = short_decimal_of_f32(x) {
        let decimal = digits as f64 / POWERS_OF_TEN[scale as usize];
        return if x < 0.0 { -decimal } else { decimal };
    }
    let mut buffer = zmij::Buffer::new();
    buffer
        .format_finite(x)
        .parse()
        .unwrap_or_else(|_| f64::from(x))
}

/// `x`'s decimal when it has at most 6 significant digits (millimetre ranges, `0.5`,
/// `12.25`), found without formatting; `None` otherwise (and outside 1e-10..1e6).
///
/// Two different decimals of at most 6 significant digits (`f32::DIGITS`) are never read as
/// the same normal `f32`, so one that reads as `x` is the only one as short: the shortest, the
/// one [`decimal_of_f32`] gives. The 6-digit decimals are 10⁻ˢ apart, 10 to 100 times the
/// float32's step, so only the one closest to `x` can read as `x`: n·10⁻ˢ for n the whole
/// number closest to |x|·10ˢ, with s such that n has 6 digits.
fn short_decimal_of_f32(x: f32) -> Option<(u64, u32)> {
    let magnitude = f64::from(x).abs();
    if !(1e-10..1e6).contains(&magnitude) {
        return None;
    }
    let bits = x.abs().to_bits();
    let e = i32::try_from(bits >> 23).unwrap_or(0) - 127;
    // Within half a step of `x` towards either neighbour, a decimal reads as `x`; the margin
    // of one part in 10⁶ is far above the f64 rounding of the products (10⁻¹⁶), so that no
    // double rounding decides. The step is 2^(e−23), and half that below a power of two.
    let step = f64::from_bits(u64::try_from(e - 23 + 1023).unwrap_or(0) << 52);
    let half_step = if bits & 0x007F_FFFF == 0 {
        0.25 * step
    } else {
        0.5 * step
    } * (1.0 - 1e-6);
    // Millimetres first (most lidars' and sonars' ranges): n·10⁻³ with n < 10⁶ has at most
    // 6 significant digits, so if it reads as `x` it is the one such decimal.
    let millimetres = magnitude * 1e3;
    let n = round_half_away(millimetres);
    if n < 1e6 && (n - millimetres).abs() < half_step * 1e3 {
        return Some((n as u64, 3));
    }
    let s = POWERS_OF_TEN.iter().position(|p| magnitude * p >= 1e5)?;
    let power = POWERS_OF_TEN[s];
    let scaled = round_half_away(magnitude * power);
    // n ≥ 10⁵ by the choice of s: n ≤ 10⁶ has at most 6 significant digits. (A power one
    // off at a boundary makes 7 digits, or a decimal that misses `x`: `None` either way.)
    if scaled > 1e6 {
        return None;
    }
    // The f64 closest to n·10⁻ˢ (n and 10ˢ are exact: one rounding), what parsing the
    // decimal gives.
    let decimal = scaled / power;
    // n ≤ 10⁶ and s ≤ 15: both exact in their integer types.
    ((decimal - magnitude).abs() < half_step).then_some((scaled as u64, s as u32))
}

/// 10⁰ to 10¹⁵, each exact in an `f64`.
const POWERS_OF_TEN: [f64; 16] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
];

/// A LaserScan angle (radians, any turn) as a recording's degrees in [0, 360), to 1e-4°: the
/// float32 angle and increment put reading i of a 360-reading scan about 1e-5° off its nominal
/// angle, and no lidar resolves 1e-4°.
#[must_use]
pub fn angle_deg(angle_rad: f64) -> f64 {
    f64::from(angle_e4_deg(angle_rad)) / 1e4
}

/// [`angle_deg`] in ten-thousandths of a degree, [0, 3,600,000): the turn taken off in
/// integers, exactly (a float remainder leaves 269.99990000000003 for −90.0001); 0 for an
/// angle that is not finite.
fn angle_e4_deg(angle_rad: f64) -> u32 {
    const TURN: i64 = 3_600_000;
    let e4 = round_half_away(angle_rad.to_degrees() * 1e4);
    // Within ±2⁵³ every whole f64 is an exact i64.
    if e4.is_nan() || e4.abs() >= 9.0e15 {
        return 0;
    }
    u32::try_from((e4 as i64).rem_euclid(TURN)).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float32_fields_keep_their_decimals() {
        assert_eq!(decimal_of_f32(1.234), 1.234);
        assert_eq!(decimal_of_f32(0.5), 0.5);
        assert_eq!(decimal_of_f32(6.0), 6.0);
    }

    /// The short path gives what formatting the float32's shortest decimal and reading it does,
    /// for every float32 between 1e-11 and 1e7 in steps of a prime number of bit patterns.
    #[test]
    fn short_decimals_are_the_shortest() {
        let slow = |x: f32| -> f64 { zmij::Buffer::new().format_finite(x).parse().unwrap() };
        let (low, high) = (1e-11f32.to_bits(), 1e7f32.to_bits());
        let mut short = 0;
        for bits in (low..high).step_by(997) {
            for x in [f32::from_bits(bits), -f32::from_bits(bits)] {
                assert_eq!(decimal_of_f32(x), slow(x), "{x:e}");
                short += usize::from(short_decimal_of_f32(x).is_some());
            }
        }
        for text in [
            "1.234", "0.001", "65.535", "12.3456", "0.000123", "1000", "0.5", "99999.9", "10",
            "123456", "1e-9",
        ] {
            let x: f32 = text.parse().unwrap();
            let expected: f64 = text.parse().unwrap();
            for x in [x, -x] {
                let (digits, scale) = short_decimal_of_f32(x).unwrap();
                assert_eq!(digits as f64 / 10f64.powi(scale as i32), expected, "{text}");
                assert_eq!(decimal_of_f32(x), expected.copysign(f64::from(x)), "{text}");
            }
        }
        assert_eq!(short_decimal_of_f32(1.234_567_8), None);
        assert!(short > 0);
        // Every millimetre range to 100 m (the fast path of an import) is short.
        for mm in 1..100_000u32 {
            let x = mm as f32 / 1000.0;
            let (digits, scale) = short_decimal_of_f32(x).unwrap();
            assert_eq!(
                digits as f64 / 10f64.powi(scale as i32),
                f64::from(mm) / 1e3
            );
        }
    }

    #[test]
    fn rounding_is_round() {
        let mut x = 1e-3f64;
        for _ in 0..2000 {
            for v in [
                x,
                -x,
                x + 0.5,
                -x - 0.5,
                x.floor() + 0.5,
                -(x.floor() + 0.5),
            ] {
                assert_eq!(round_half_away(v).to_bits(), v.round().to_bits(), "{v:e}");
            }
            x *= 1.037;
        }
        for v in [
            0.0,
            -0.0,
            0.499_999_999_999_999_94,
            -0.499_999_999_999_999_94,
            4.5e15 + 0.5,
        ] {
            assert_eq!(round_half_away(v).to_bits(), v.round().to_bits(), "{v:e}");
        }
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300] {
            assert_eq!(round_half_away(v).to_bits(), v.round().to_bits(), "{v:e}");
        }
    }

    /// A scan whose angles or timing are not numbers is skipped and counted, not written as
    /// NaN; the readings of a good scan reach a sink as the decimals they were sent as.
    #[test]
    fn a_scan_of_nan_fields_is_skipped() {
        use crate::cdr::encode;
        use crate::msgs::Header;
        let chosen: Chosen = [(Role::Lidar, ("/scan".to_string(), Kind::LaserScan))].into();
        let mut converter = Converter::new(&chosen, 0.2, None);
        /// Keeps the lidar's readings (through `SampleSink::lidar_decimals`'s default).
        #[derive(Default)]
        struct Kept(Vec<LidarSample>);
        impl SampleSink for Kept {
            type Error = hilsim_recording::Error;
            fn command(&mut self, _: &CommandSample) -> Result<(), Self::Error> {
                Ok(())
            }
            fn odometry(&mut self, _: &OdometrySample) -> Result<(), Self::Error> {
                Ok(())
            }
            fn lidar(&mut self, r: &LidarSample) -> Result<(), Self::Error> {
                self.0.push(*r);
                Ok(())
            }
            fn sonar(&mut self, _: &SonarSample) -> Result<(), Self::Error> {
                Ok(())
            }
            fn truth(&mut self, _: &TruthSample) -> Result<(), Self::Error> {
                Ok(())
            }
        }
        let mut kept = Kept::default();
        let scan = |angle_min: f32, time_increment: f32| {
            let mut bytes = Vec::new();
            let message = LaserScan {
                header: Header {
                    stamp: Time { sec: 7, nanosec: 0 },
                    frame_id: "laser".into(),
                },
                angle_min,
                angle_increment: 0.5f32.to_radians(),
                time_increment,
                range_min: 0.1,
                range_max: 6.0,
                ranges: vec![1.234, 0.05, f32::NAN],
                ..LaserScan::default()
            };
            encode(&message, &mut bytes);
            bytes
        };
        for bytes in [scan(f32::NAN, 0.0), scan(0.0, f32::INFINITY)] {
            let converted = converter.message(Role::Lidar, Kind::LaserScan, 0, &bytes, &mut kept);
            assert!(converted.is_ok());
        }
        assert!(kept.0.is_empty());
        assert!(converter
            .notes()
            .iter()
            .any(|n| n.contains("2 lidar messages with a value that is not finite")));
        let good = scan(-0.5f32.to_radians(), 1e-4);
        let converted = converter.message(Role::Lidar, Kind::LaserScan, 0, &good, &mut kept);
        assert!(converted.is_ok());
        let row = |r: &LidarSample| (r.t_s, r.angle_deg, r.range_m, r.invalid);
        assert_eq!(
            kept.0.iter().map(row).collect::<Vec<_>>(),
            [
                (0.0, 359.5, 1.234, false),
                (0.0001, 0.0, 0.0, true),
                (0.0002, 0.5, 0.0, true)
            ]
        );
    }

    #[test]
    fn angles_wrap_and_round() {
        let step = (1.0f64.to_radians() as f32) as f64;
        assert_eq!(angle_deg(359.0 * step), 359.0);
        assert_eq!(angle_deg(-std::f64::consts::FRAC_PI_2), 270.0);
        assert_eq!(angle_deg(2.0 * std::f64::consts::PI), 0.0);
        assert_eq!(angle_deg(-1e-12).to_bits(), 0.0f64.to_bits());
        // The turn comes off exactly: on the 10⁻⁴° grid, not 269.99990000000003.
        assert_eq!(angle_deg((-90.0001f64).to_radians()), 269.9999);
        assert_eq!(angle_deg((725.5f64).to_radians()), 5.5);
        assert_eq!(angle_deg(f64::NAN), 0.0);
        let half = decimal_of_f32(0.5f64.to_radians() as f32);
        for i in 0..720 {
            assert_eq!(angle_deg(f64::from(i) * half), f64::from(i) * 0.5, "{i}");
        }
    }
}
