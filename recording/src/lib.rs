//! The hilsim recording: a directory of plain CSV files plus `meta.toml`, as specified in
//! `interfaces.md`. A real robot's logger can write it as easily as the simulator, and the
//! calibrators read nothing else.
//!
//! [`Recording`] is also the in-process form: the simulator fills one in memory, the calibrators
//! consume it, and [`Recording::write_dir`] / [`Recording::read_dir`] move it to and from disk
//! without changing a sample.
//!
//! ```
//! use hilsim_recording::{Meta, Recording, TruthSample};
//! let mut rec = Recording::new(Meta::default());
//! rec.truth = Some(vec![TruthSample { t_s: 0.0, x_m: 0.5, y_m: 0.0, yaw_rad: 0.0 }]);
//! let dir = tempfile::tempdir().unwrap();
//! rec.write_dir(&dir.path().join("run")).unwrap();
//! let back = Recording::read_dir(&dir.path().join("run")).unwrap();
//! assert_eq!(back, rec);
//! ```
#![warn(missing_docs)]

mod atomic;
mod background;
mod csv;
mod decimal;
mod error;
mod farthest;
mod input;
mod meta;
mod names;
pub mod pose;
mod printable;
mod read;
mod rows;
mod samples;
mod stream;
mod thin;
mod timed_path;
mod write;

pub use atomic::{
    check_input_outside, check_output_file, check_replaceable_recording, is_same_file,
    replace_dir_atomically, replace_recording_dir, resolve_output_dir, tidy_after_killed_writers,
    write_file_atomically, write_owned_file_atomically, AtomicFile, FileKind, OutputTarget,
};
pub use background::BackgroundStream;
pub use decimal::{decimal_of_f32, round_half_away, short_decimal_of_f32};
pub use error::{Error, ErrorKind};
pub use input::{read_small_text, MAX_META_BYTES};
pub use meta::{Meta, Mount, RobotMeta, SonarMount, SourceMeta, WorldMeta, FORMAT};
pub use names::{Method, Sensor};
pub use pose::{body_travel, wrap_angle, DeadReckoning, Pose};
pub use printable::{printable, printable_cut, MAX_NAME_CHARS};
pub use rows::{RecordingDir, Rows};
pub use samples::{
    CommandSample, LidarDecimals, LidarSample, OdometrySample, SonarSample, TruthSample,
};
pub use stream::{RecordingStream, SampleSink, Tables};
pub use thin::{ThinnedSink, Thinning, MAX_ROWS_HELD};
pub use timed_path::{Ends, Place, TimedPath};

/// A whole recording: the metadata and one table per sensor.
///
/// A table that is `None` is absent from the directory (the robot lacks that sensor); an empty
/// `Vec` is written as a file with a header only.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Recording {
    /// `meta.toml`.
    pub meta: Meta,
    /// `commands.csv`: wheel speed commands as issued.
    pub commands: Vec<CommandSample>,
    /// `odometry.csv`: cumulative wheel travel as the encoders report it.
    pub odometry: Option<Vec<OdometrySample>>,
    /// `lidar.csv`: one row per lidar reading.
    pub lidar: Option<Vec<LidarSample>>,
    /// `sonar.csv`: one row per sonar ping.
    pub sonar: Option<Vec<SonarSample>>,
    /// `truth.csv`: the true pose, when known.
    pub truth: Option<Vec<TruthSample>>,
}

impl Recording {
    /// The files a recording directory may hold.
    pub const FILES: [&'static str; 6] = [
        "meta.toml",
        "commands.csv",
        "odometry.csv",
        "lidar.csv",
        "sonar.csv",
        "truth.csv",
    ];

    /// The paths of the files a recording directory `dir` may hold: a command that reads the
    /// recording must not write over any of them.
    #[must_use]
    pub fn files_in(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
        Self::FILES.iter().map(|name| dir.join(name)).collect()
    }

    /// An empty recording with the given metadata.
    #[must_use]
    pub fn new(meta: Meta) -> Self {
        Self {
            meta,
            ..Self::default()
        }
    }

    /// The recording's length in seconds: the latest timestamp of any table.
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        let last = |ts: Option<f64>| ts.unwrap_or(0.0);
        [
            last(self.commands.last().map(|s| s.t_s)),
            last(self.odometry.as_ref().and_then(|v| v.last()).map(|s| s.t_s)),
            last(self.lidar.as_ref().and_then(|v| v.last()).map(|s| s.t_s)),
            last(self.sonar.as_ref().and_then(|v| v.last()).map(|s| s.t_s)),
            last(self.truth.as_ref().and_then(|v| v.last()).map(|s| s.t_s)),
        ]
        .into_iter()
        .fold(0.0, f64::max)
    }
}
