//! The names every part of hilsim shares: the sensors a recording holds tables of, and the
//! calibration methods that read them (a scenario's `[calibration] methods`, `hilsim calibrate
//! --method`, a calibration's JSON).

use serde::{Deserialize, Serialize};

/// A sensor with a table in a recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Sensor {
    /// The lidar (`lidar.csv`).
    Lidar,
    /// The sonar (`sonar.csv`).
    Sonar,
    /// The wheel odometer (`odometry.csv`).
    Odometer,
}

impl Sensor {
    /// Every sensor, in report order.
    pub const ALL: [Sensor; 3] = [Sensor::Lidar, Sensor::Sonar, Sensor::Odometer];

    /// The name used in files, reports and JSON.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Sensor::Lidar => "lidar",
            Sensor::Sonar => "sonar",
            Sensor::Odometer => "odometer",
        }
    }
}

/// A calibration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Ground-truth-less EM with a Kalman/RTS smoother (Alhashimi, Varagnolo, Gustafsson, IEEE
    /// Sensors J. 2017).
    Em,
    /// Landmarks in unknown positions (Alhashimi, Magnusson, Knorn, Varagnolo, Sensors 2021).
    Landmarks,
    /// Maximum-likelihood fit against the true pose (Alhashimi et al., ICINCO 2016).
    Groundtruth,
    /// The wheels' radii, the wheel base and the lidar's pose on the robot from an ordinary drive
    /// (Censi, Franchi, Marchionni, Oriolo, IEEE T-RO 29(2), 2013).
    Odometry,
}

impl Method {
    /// Every method.
    pub const ALL: [Method; 4] = [
        Method::Em,
        Method::Landmarks,
        Method::Groundtruth,
        Method::Odometry,
    ];

    /// The method's name as written in files and on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Method::Em => "em",
            Method::Landmarks => "landmarks",
            Method::Groundtruth => "groundtruth",
            Method::Odometry => "odometry",
        }
    }

    /// The method of a name.
    ///
    /// ```
    /// use hilsim_recording::Method;
    /// for m in Method::ALL {
    ///     assert_eq!(Method::from_name(m.name()), Some(m));
    /// }
    /// ```
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}
