//! A bag into a recording: each chosen topic's messages into its table as they are read, and
//! what the bag's TF says of the robot into `meta.toml` (see `docs/ros2.md` for what becomes of
//! each field). A ROS 2 bag (MCAP or SQLite3, CDR messages) and a ROS 1 bag (rosbag format
//! 2.0, ROS 1 messages) differ only in their container and serialisation: both feed the one
//! [`Converter`].
//!
//! One job a file: `assemble` chooses the topics and assembles the recording; `bag_walk` walks a
//! bag's container message by message into the converter; `clocks` puts each message on the
//! recording's clock; `conversions` turns messages into samples, `scan` a LaserScan into lidar
//! readings and `odometry` poses or wheel angles into wheel travel; `mounts` reads the sensors'
//! mounts from what the bag says; `wire` decodes a message in either serialisation.

mod assemble;
mod bag_walk;
mod clocks;
mod conversions;
mod flags;
mod mounts;
mod odometry;
mod scan;
mod wire;

pub use assemble::{import, ImportOptions, ImportReport};
pub use bag_walk::read_file;
pub(crate) use clocks::{ODOMETRY_START_KEYS, START_KEY, START_METADATA};
pub use conversions::{Converter, Fault};
pub use flags::{FlagError, ImportFlags};
pub use scan::angle_deg;
pub use wire::Encoding;
