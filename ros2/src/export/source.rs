//! What an export reads: the recording's metadata and each of its tables as a stream.

use hilsim_recording::{
    CommandSample, LidarSample, Meta, OdometrySample, SonarSample, Tables, TruthSample,
};

/// A table's samples in time order.
pub(super) type Stream<'a, T> = Box<dyn Iterator<Item = Result<T, hilsim_recording::Error>> + 'a>;

/// What an export reads: the metadata, which tables there are, and each table as a stream (the
/// odometry twice: the messages, and the path the truth's transforms are placed on).
pub(super) struct Source<'a> {
    pub(super) meta: &'a Meta,
    pub(super) tables: Tables,
    pub(super) commands: Stream<'a, CommandSample>,
    pub(super) odometry: Stream<'a, OdometrySample>,
    pub(super) odometry_again: Stream<'a, OdometrySample>,
    pub(super) lidar: Stream<'a, LidarSample>,
    pub(super) sonar: Stream<'a, SonarSample>,
    pub(super) truth: Stream<'a, TruthSample>,
}
