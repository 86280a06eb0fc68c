//! Walking a bag: its container (a ROS 2 bag's MCAP or SQLite3 files and their channels, or a
//! ROS 1 bag's connections), its topics' types, and each message of a chosen topic handed to
//! the [`Converter`] as it is read, decoded in the bag's serialisation. Kept apart from the
//! conversions so that both kinds of bag feed one converter.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use hilsim_recording::{printable, SampleSink};

use super::clocks::{earliest_time, ros1_earliest_time};
use super::clocks::{ODOMETRY_START_KEYS, START_KEY, START_METADATA};
use super::wire::Encoding;
use super::{Converter, Fault};
use crate::bag::{self, Item};
use crate::ros1;
use crate::tf;
use crate::topics::{self, Chosen, Kind, Role, TopicTypes};
use crate::Error;

/// A bag's container: a ROS 2 bag's files (MCAP or SQLite3) and their channels, or a ROS 1
/// bag's one file and its connections.
pub(super) enum Container {
    Ros2 {
        files: Vec<PathBuf>,
        channels: Vec<bag::Channel>,
    },
    Ros1 {
        connections: Vec<ros1::Connection>,
    },
}

impl Container {
    pub(super) fn open(path: &Path) -> Result<Self, Error> {
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

    /// How the container's messages are laid out.
    pub(super) fn encoding(&self) -> Encoding {
        match self {
            Self::Ros2 { .. } => Encoding::Cdr,
            Self::Ros1 { .. } => Encoding::Ros1,
        }
    }

    /// Refuses a chosen ROS 2 topic whose messages are not CDR.
    pub(super) fn check_message_encoding(&self, bag: &Path, chosen: &Chosen) -> Result<(), Error> {
        let Self::Ros2 { channels, .. } = self else {
            return Ok(());
        };
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
        Ok(())
    }

    /// Streams the bag at `bag` through the converter into `sink`, its t = 0 and clock offset
    /// found first ([`earliest_time`]); returns the bytes of bag read. A ROS 1 bag's damage
    /// and undecoded messages are `notes`.
    pub(super) fn read<S>(
        &self,
        bag: &Path,
        chosen: &Chosen,
        converter: &mut Converter,
        sink: &mut S,
        notes: &mut Vec<String>,
    ) -> Result<u64, Error>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let mut bytes = 0;
        match self {
            Self::Ros2 { files, .. } => {
                (converter.t0_ns, converter.clock_offset_ns) = earliest_time(&files[0], chosen)?;
                for file in files {
                    bytes += std::fs::metadata(file).map_or(0, |m| m.len());
                    read_file(file, converter, sink)?;
                }
            }
            Self::Ros1 { connections } => {
                (converter.t0_ns, converter.clock_offset_ns) =
                    ros1_earliest_time(bag, connections, chosen)?;
                bytes = std::fs::metadata(bag).map_or(0, |m| m.len());
                notes.extend(read_ros1(bag, connections, converter, sink)?);
            }
        }
        Ok(bytes)
    }

    pub(super) fn topic_types(&self, path: &Path) -> Result<TopicTypes, Error> {
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
