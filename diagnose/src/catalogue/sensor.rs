//! Which sensor (or the drive) an effect shows in.

use std::fmt;

/// Which sensor (or the drive) an effect shows in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Sensor {
    /// The lidar's ranges.
    Lidar,
    /// The sonar's ranges.
    Sonar,
    /// The wheel encoders' travel.
    Odometer,
    /// The robot's motion under its commands (truth or the estimated trajectory).
    Drive,
}

impl Sensor {
    /// Every sensor, in report order.
    pub const ALL: [Sensor; 4] = [
        Sensor::Lidar,
        Sensor::Sonar,
        Sensor::Odometer,
        Sensor::Drive,
    ];

    /// The name used in reports and JSON.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Sensor::Lidar => "lidar",
            Sensor::Sonar => "sonar",
            Sensor::Odometer => "odometer",
            Sensor::Drive => "drive",
        }
    }
}

impl fmt::Display for Sensor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
