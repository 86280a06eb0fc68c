//! A message's serialisation: ROS 2's CDR or ROS 1's packed fields, and decoding a whole
//! message in either. Shared by the bag walk, the clocks and the conversions.

use serde::de::DeserializeOwned;

use crate::cdr::decode_whole;
use crate::ros1::{self, FromRos1};

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
pub(super) trait Wire: DeserializeOwned + FromRos1 {}
impl<T: DeserializeOwned + FromRos1> Wire for T {}

/// Decodes a whole message of `encoding` (at most `appended` bytes of fields a newer ROS 2
/// distribution adds are allowed after it).
pub(super) fn decode_as<T: Wire>(
    encoding: Encoding,
    data: &[u8],
    appended: usize,
) -> Result<T, String> {
    match encoding {
        Encoding::Cdr => decode_whole(data, appended),
        Encoding::Ros1 => ros1::decode_whole(data),
    }
}
