//! A recording as an MCAP file of ROS 2 messages (profile `ros2`, schemas `ros2msg`, messages
//! CDR), what `ros2 bag play`, RViz and Foxglove read. Topics and frames:
//!
//! | topic | type | frame |
//! |---|---|---|
//! | `/scan` | `sensor_msgs/msg/LaserScan`, one per revolution | `laser` |
//! | `/scan_calibrated` | `sensor_msgs/msg/LaserScan` (with calibrated ranges) | `laser` |
//! | `/sonar` | `sensor_msgs/msg/Range` | `sonar` |
//! | `/odom` | `nav_msgs/msg/Odometry` (the wheel travel dead-reckoned) | `odom` → `base_link` |
//! | `/cmd_vel` | `geometry_msgs/msg/TwistStamped` | `base_link` |
//! | `/ground_truth/pose` | `geometry_msgs/msg/PoseStamped` | `map` |
//! | `/tf` | `tf2_msgs/msg/TFMessage`: `odom` → `base_link` (odometry), `map` → `odom` (truth) | |
//! | `/tf_static` | `tf2_msgs/msg/TFMessage`: `base_link` → `laser`, `base_link` → `sonar` | |
//! | `/world` | `visualization_msgs/msg/MarkerArray` (with a world) | `map` |
//!
//! The frames are one tree (REP 105): `map` → `odom` → `base_link` → `laser`, `sonar`.
//!
//! One job a file: `file` holds the entry points, `source` what they read and `options` what
//! they are told; `extent` what
//! the messages need from whole tables; `merge` the tables merged by time; `write` each row
//! as its messages, `messages` the messages themselves, `odometry` the odometry's poses; and
//! `mcap_file` the MCAP writing.

mod extent;
mod file;
mod mcap_file;
mod merge;
mod messages;
mod odometry;
mod options;
mod source;
mod write;

pub use file::{export, export_dir, export_with};
pub use merge::MAX_SCAN_READINGS;
pub use options::{ExportOptions, ExportReport, World, START_NS};
