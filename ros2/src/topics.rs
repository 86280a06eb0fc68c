//! Which topic feeds which table: by message type when a bag has one topic of that type, by the
//! user's choice otherwise.

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

use hilsim_recording::printable;

use crate::Error;

/// A table of the recording, fed by one topic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Role {
    /// `lidar.csv`.
    Lidar,
    /// `odometry.csv`.
    Odometry,
    /// `commands.csv`.
    Commands,
    /// `sonar.csv`.
    Sonar,
    /// `truth.csv`.
    Truth,
}

impl Role {
    /// Every role, in the order topics are chosen.
    pub const ALL: [Role; 5] = [
        Role::Lidar,
        Role::Truth,
        Role::Odometry,
        Role::Commands,
        Role::Sonar,
    ];

    /// The command-line flag that names its topic.
    #[must_use]
    pub fn flag(self) -> &'static str {
        match self {
            Self::Lidar => "--lidar",
            Self::Odometry => "--odom",
            Self::Commands => "--cmd",
            Self::Sonar => "--sonar",
            Self::Truth => "--truth",
        }
    }

    /// The message types it reads, by the names of their `.msg` (package/Type).
    fn accepts(self) -> &'static [Kind] {
        match self {
            Self::Lidar => &[Kind::LaserScan],
            Self::Odometry => &[Kind::Odometry, Kind::JointState, Kind::Tf],
            Self::Commands => &[Kind::Twist, Kind::TwistStamped],
            Self::Sonar => &[Kind::Range],
            Self::Truth => &[Kind::PoseStamped, Kind::Odometry],
        }
    }

    /// The types found by type alone, in order of preference (an `Odometry` is the odometer's
    /// unless named as the truth; wheel joints only when there is no `Odometry`; TF's odom →
    /// base transforms are the import's last resort, not found here).
    fn found_by_type(self) -> &'static [Kind] {
        match self {
            Self::Truth => &[Kind::PoseStamped],
            Self::Odometry => &[Kind::Odometry, Kind::JointState],
            other => other.accepts(),
        }
    }
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(match self {
            Self::Lidar => "lidar",
            Self::Odometry => "odometry",
            Self::Commands => "commands",
            Self::Sonar => "sonar",
            Self::Truth => "truth",
        })
    }
}

/// A message type hilsim reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `sensor_msgs/LaserScan`.
    LaserScan,
    /// `nav_msgs/Odometry`.
    Odometry,
    /// `sensor_msgs/JointState`.
    JointState,
    /// `geometry_msgs/Twist`.
    Twist,
    /// `geometry_msgs/TwistStamped`.
    TwistStamped,
    /// `sensor_msgs/Range`.
    Range,
    /// `geometry_msgs/PoseStamped`.
    PoseStamped,
    /// `tf2_msgs/TFMessage` (ROS 1's older `tf/tfMessage` has the same layout): odometry from
    /// its odom → base transforms, and the sensors' mounts.
    Tf,
}

impl Kind {
    const NAMES: [(Kind, &'static str); 8] = [
        (Kind::LaserScan, "sensor_msgs/LaserScan"),
        (Kind::Odometry, "nav_msgs/Odometry"),
        (Kind::JointState, "sensor_msgs/JointState"),
        (Kind::Twist, "geometry_msgs/Twist"),
        (Kind::TwistStamped, "geometry_msgs/TwistStamped"),
        (Kind::Range, "sensor_msgs/Range"),
        (Kind::PoseStamped, "geometry_msgs/PoseStamped"),
        (Kind::Tf, "tf2_msgs/TFMessage"),
    ];

    /// The kind of a schema name (`sensor_msgs/msg/LaserScan` or `sensor_msgs/LaserScan`).
    #[must_use]
    pub fn of(type_name: &str) -> Option<Self> {
        let name = type_name.replace("/msg/", "/");
        if name == "tf/tfMessage" {
            return Some(Self::Tf);
        }
        Self::NAMES
            .iter()
            .find(|(_, n)| *n == name)
            .map(|(k, _)| *k)
    }

    /// The full ROS 2 name, e.g. `sensor_msgs/msg/LaserScan`.
    #[must_use]
    pub fn ros_name(self) -> String {
        let name = Self::NAMES
            .iter()
            .find(|(k, _)| *k == self)
            .map_or("", |(_, n)| n);
        name.replacen('/', "/msg/", 1)
    }
}

/// How many names a one-line message lists before "and N more".
pub(crate) const LISTED: usize = 10;

/// Names read from a bag as one line: each made printable, at most ten of them, then how many
/// more there are (a bag can hold thousands).
pub(crate) fn listing<T: AsRef<str>>(
    names: impl IntoIterator<Item = T>,
    separator: &str,
) -> String {
    let mut shown = Vec::new();
    let mut more = 0;
    for name in names {
        if shown.len() < LISTED {
            shown.push(printable(name.as_ref()).into_owned());
        } else {
            more += 1;
        }
    }
    let mut line = shown.join(separator);
    if more > 0 {
        line.push_str(&format!("{separator}and {more} more"));
    }
    line
}

/// The topics of a bag (over all its files): name → type name.
pub type TopicTypes = BTreeMap<String, String>;

/// The topics chosen: role → (topic, kind).
pub type Chosen = BTreeMap<Role, (String, Kind)>;

/// Collects a bag's topics from its channels' (topic, type name) pairs (an MCAP file's
/// channels, a ROS 1 bag's connections).
///
/// # Errors
/// One topic with two types.
pub fn topic_types<'a>(
    bag: &Path,
    channels: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> Result<TopicTypes, Error> {
    let mut topics = TopicTypes::new();
    for (topic, type_name) in channels {
        if let Some(old) = topics.insert(topic.to_string(), type_name.to_string()) {
            if old != type_name {
                return Err(Error::bag(
                    bag,
                    format!(
                        "topic {} has two types, {} and {}",
                        printable(topic),
                        printable(&old),
                        printable(type_name)
                    ),
                ));
            }
        }
    }
    Ok(topics)
}

/// Chooses a topic for each role: the one named by its flag (which must exist and be of an
/// accepted type), else the only topic of its type, else none; two or more of a type is an
/// error listing them.
///
/// # Errors
/// A named topic absent or of the wrong type; two candidates for a role not named.
pub fn choose(
    bag: &Path,
    topics: &TopicTypes,
    named: &BTreeMap<Role, String>,
) -> Result<Chosen, Error> {
    let mut chosen = Chosen::new();
    for (&role, topic) in named {
        let Some(type_name) = topics.get(topic) else {
            return Err(Error::bag(
                bag,
                format!(
                    "no topic {} ({}); topics: {}",
                    printable(topic),
                    role.flag(),
                    listing(topics.keys().map(String::as_str), ", ")
                ),
            ));
        };
        let kind = Kind::of(type_name).filter(|k| role.accepts().contains(k));
        let Some(kind) = kind else {
            let wanted: Vec<_> = role.accepts().iter().map(|k| k.ros_name()).collect();
            return Err(Error::bag(
                bag,
                format!(
                    "topic {} is {}; {} takes {}",
                    printable(topic),
                    printable(type_name),
                    role.flag(),
                    wanted.join(" or ")
                ),
            ));
        };
        chosen.insert(role, (topic.clone(), kind));
    }
    for role in Role::ALL {
        if chosen.contains_key(&role) {
            continue;
        }
        for &kind in role.found_by_type() {
            let taken = |t: &str| chosen.values().any(|(c, _)| c == t);
            let candidates: Vec<&str> = topics
                .iter()
                .filter(|(t, ty)| Kind::of(ty) == Some(kind) && !taken(t))
                .map(|(t, _)| t.as_str())
                .collect();
            match candidates.as_slice() {
                [] => continue,
                [one] => {
                    chosen.insert(role, ((*one).to_string(), kind));
                }
                many => {
                    return Err(Error::bag(
                        bag,
                        format!(
                            "{} topics of type {}: {}; choose the {role}'s with {} TOPIC",
                            many.len(),
                            kind.ros_name(),
                            listing(many.iter().copied(), ", "),
                            role.flag()
                        ),
                    ))
                }
            }
            break;
        }
    }
    Ok(chosen)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn topics(list: &[(&str, &str)]) -> TopicTypes {
        list.iter()
            .map(|(t, ty)| ((*t).to_string(), (*ty).to_string()))
            .collect()
    }

    #[test]
    fn one_topic_of_a_type_is_found_two_need_a_flag() {
        let bag = Path::new("b.mcap");
        let t = topics(&[
            ("/scan", "sensor_msgs/msg/LaserScan"),
            ("/odom", "nav_msgs/msg/Odometry"),
            ("/mocap", "nav_msgs/msg/Odometry"),
            ("/cmd_vel", "geometry_msgs/msg/Twist"),
            ("/rosout", "rcl_interfaces/msg/Log"),
        ]);
        let err = choose(bag, &t, &BTreeMap::new()).unwrap_err().to_string();
        assert_eq!(
            err,
            "b.mcap: 2 topics of type nav_msgs/msg/Odometry: /mocap, /odom; choose the \
             odometry's with --odom TOPIC"
        );
        // Naming the truth leaves one Odometry for the odometer.
        let named = BTreeMap::from([(Role::Truth, "/mocap".to_string())]);
        let chosen = choose(bag, &t, &named).unwrap();
        assert_eq!(chosen[&Role::Odometry].0, "/odom");
        assert_eq!(chosen[&Role::Truth], ("/mocap".to_string(), Kind::Odometry));
        assert_eq!(chosen[&Role::Commands].1, Kind::Twist);
        assert!(!chosen.contains_key(&Role::Sonar));
        let named = BTreeMap::from([(Role::Lidar, "/odom".to_string())]);
        let err = choose(bag, &t, &named).unwrap_err().to_string();
        assert!(
            err.ends_with(
                "topic /odom is nav_msgs/msg/Odometry; --lidar takes sensor_msgs/msg/LaserScan"
            ),
            "{err}"
        );
        let named = BTreeMap::from([(Role::Lidar, "/nope".to_string())]);
        assert!(choose(bag, &t, &named)
            .unwrap_err()
            .to_string()
            .contains("no topic /nope"));
    }
}
