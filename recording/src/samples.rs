//! One row of each CSV table. Units are SI; time is seconds from the recording's start.

/// A wheel speed command as issued (`commands.csv`). It holds until the next row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommandSample {
    /// When the command was issued.
    pub t_s: f64,
    /// Left wheel speed, m/s, positive forward.
    pub left_mps: f64,
    /// Right wheel speed, m/s, positive forward.
    pub right_mps: f64,
}

/// Cumulative wheel travel as the encoders report it (`odometry.csv`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometrySample {
    /// When the encoders were read.
    pub t_s: f64,
    /// Left wheel travel since the start, metres.
    pub left_m: f64,
    /// Right wheel travel since the start, metres.
    pub right_m: f64,
}

/// One lidar reading (`lidar.csv`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LidarSample {
    /// When this reading was taken (each reading has its own instant within a revolution).
    pub t_s: f64,
    /// Revolution counter, from 0.
    pub rev: u64,
    /// Beam angle in the lidar's own frame, degrees in [0, 360), counter-clockwise from its
    /// forward axis (ROS REP 103). The XV-11 gives the whole degrees 0..359; another lidar any
    /// number of readings per revolution at any spacing.
    pub angle_deg: f64,
    /// Range as reported, metres (millimetres / 1000); 0 when invalid.
    pub range_m: f64,
    /// Signal strength as reported (the XV-11's 16-bit field).
    pub strength: u16,
    /// The invalid-data flag.
    pub invalid: bool,
    /// The strength-warning flag.
    pub warning: bool,
    /// The true range along the beam, metres; only the simulator knows it.
    pub true_range_m: Option<f64>,
}

/// A lidar reading whose numbers are decimals already, as an importer reads them (times to
/// the microsecond, angles to 10⁻⁴°, ranges as the decimal a float32 field was written as):
/// [`SampleSink::lidar_decimals`](crate::SampleSink::lidar_decimals) writes their digits
/// without a round trip through `f64`, byte for byte what [`LidarDecimals::sample`] gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LidarDecimals {
    /// Microseconds from t = 0.
    pub t_us: u64,
    /// Revolution counter, from 0.
    pub rev: u64,
    /// The beam angle in ten-thousandths of a degree, [0, 3,600,000).
    pub angle_e4_deg: u32,
    /// The range is `range_digits` · 10^−`range_scale` metres (0 when invalid).
    pub range_digits: u64,
    /// See `range_digits`.
    pub range_scale: u32,
    /// Signal strength as reported.
    pub strength: u16,
    /// The invalid-data flag.
    pub invalid: bool,
    /// The strength-warning flag.
    pub warning: bool,
}

impl LidarDecimals {
    /// The reading as a [`LidarSample`]: each number the `f64` closest to its decimal.
    #[must_use]
    pub fn sample(&self) -> LidarSample {
        LidarSample {
            t_s: self.t_us as f64 / 1e6,
            rev: self.rev,
            angle_deg: f64::from(self.angle_e4_deg) / 1e4,
            range_m: self.range_digits as f64 / 10f64.powi(self.range_scale.min(300) as i32),
            strength: self.strength,
            invalid: self.invalid,
            warning: self.warning,
            true_range_m: None,
        }
    }
}

/// One sonar ping (`sonar.csv`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SonarSample {
    /// When the echo was received.
    pub t_s: f64,
    /// Range as reported, metres.
    pub range_m: f64,
    /// The true range to the nearest echo, metres; only the simulator knows it.
    pub true_range_m: Option<f64>,
}

/// The true pose of the robot (`truth.csv`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthSample {
    /// Time of the pose.
    pub t_s: f64,
    /// Position x, metres, world frame.
    pub x_m: f64,
    /// Position y, metres, world frame.
    pub y_m: f64,
    /// Heading, radians, counter-clockwise from the world x axis.
    pub yaw_rad: f64,
}
