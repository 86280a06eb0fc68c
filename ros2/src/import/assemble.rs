//! Choosing a bag's topics and assembling the recording: the topics for each role, the
//! `meta.toml` to write, the walk of the bag into the tables, and what the import did.

use std::collections::BTreeMap;
use std::path::Path;

use hilsim_recording::{printable, Meta, RecordingStream, Tables};

use crate::tf;
use crate::topics::{self, Chosen, Kind, Role, TopicTypes};
use crate::Error;

use super::bag_walk::Container;
use super::conversions::{Converter, ODOM_FRAME};
use super::mounts;

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
    let tf_topics = tf_topics(&topic_types);
    if chosen.is_empty() && !tf_topics.values().any(|s| *s == tf::Source::Dynamic) {
        return Err(no_readable_topic(bag, &topic_types));
    }
    let mut notes = Vec::new();
    let meta = meta_to_write(options, &chosen, &mut notes);
    choose_odometry(bag, options, &tf_topics, &mut chosen, &mut notes)?;
    container.check_message_encoding(bag, &chosen)?;
    let tables = Tables {
        odometry: chosen.contains_key(&Role::Odometry),
        lidar: chosen.contains_key(&Role::Lidar),
        sonar: chosen.contains_key(&Role::Sonar),
        truth: chosen.contains_key(&Role::Truth),
    };
    let mut stream = RecordingStream::create(out, meta.clone(), tables)?;
    let mut converter = Converter::new(&chosen, meta.robot.wheel_base_m, options.wheel_radius_m)
        .with_wheel_joints(options.wheel_joints.clone())
        .with_encoding(container.encoding())
        .with_tf_topics(tf_topics.clone());
    let bytes = container.read(bag, &chosen, &mut converter, &mut stream, &mut notes)?;
    converter.finish(&mut stream)?;
    check_odometry_read(bag, options, &chosen, &converter, &mut notes)?;
    // What the bag says of the sensors, where meta.toml did not.
    mounts::fill_in(
        stream.meta_mut(),
        &chosen,
        &converter,
        &tf_topics,
        &mut notes,
    );
    stream.finish()?;
    notes.extend(converter.notes());
    Ok(ImportReport {
        chosen,
        rows: converter.rows,
        bytes,
        notes,
    })
}

/// The bag's TF topics: each topic of TFMessage, static when named so (`/tf_static`,
/// `/robot1/tf_static`).
fn tf_topics(topic_types: &TopicTypes) -> BTreeMap<String, tf::Source> {
    topic_types
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
        .collect()
}

/// The error of a bag with no topic hilsim reads, listing the topics it has.
fn no_readable_topic(bag: &Path, topic_types: &TopicTypes) -> Error {
    let all = if topic_types.is_empty() {
        "none".to_string()
    } else {
        topics::listing(
            topic_types.iter().map(|(t, ty)| format!("{t} ({ty})")),
            ", ",
        )
    };
    Error::bag(
        bag,
        format!(
            "no topic of a type hilsim reads (LaserScan, Odometry, JointState, Twist, \
             TwistStamped, Range, PoseStamped, TFMessage); topics: {all}"
        ),
    )
}

/// The `meta.toml` to write: the user's, else a minimal one (said in a note); with the wheel
/// radius given.
fn meta_to_write(options: &ImportOptions, chosen: &Chosen, notes: &mut Vec<String>) -> Meta {
    let mut meta = options.meta.clone().unwrap_or_else(|| {
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
    // Travel from joint angles is their angle times this radius: a calibration of the wheels
    // reads it back to give radii.
    if let Some(radius) = options.wheel_radius_m {
        meta.robot.wheel_radius_m = Some(radius);
    }
    meta
}

/// The odometry's topic: JointState only with a wheel radius, else TF's odom → base transforms
/// when the bag has no odometry topic. Each choice made is a note.
fn choose_odometry(
    bag: &Path,
    options: &ImportOptions,
    tf_topics: &BTreeMap<String, tf::Source>,
    chosen: &mut Chosen,
    notes: &mut Vec<String>,
) -> Result<(), Error> {
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
    Ok(())
}

/// Odometry chosen but not read: JointState messages without the wheels are an error, TF
/// without an odom → base transform a note.
fn check_odometry_read(
    bag: &Path,
    options: &ImportOptions,
    chosen: &Chosen,
    converter: &Converter,
    notes: &mut Vec<String>,
) -> Result<(), Error> {
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
    Ok(())
}
