//! What an export is told and what it reports: the world to draw, the options, the clock the
//! messages are stamped on.

use std::collections::BTreeMap;

use hilsim_recording::LidarSample;

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
pub(super) fn stamp_ns(t_s: f64) -> i64 {
    START_NS + (t_s * 1e9).round() as i64
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
