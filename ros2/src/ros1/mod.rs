//! ROS 1 bags: the container (rosbag format 2.0, `bag.rs`) and the messages' serialisation
//! (`message.rs`), read into the same message types as a ROS 2 bag's.

mod bag;
mod message;

pub use bag::{connections, is_ros1_bag, Connection, Damage, CHUNK_LIMIT};
pub(crate) use bag::{stream_while, Item};
pub(crate) use message::{decode_prefix, decode_whole, FromRos1};
