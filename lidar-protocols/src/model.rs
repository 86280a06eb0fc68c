//! The lidar models hilsim emulates and what each unit is: the numbers its datasheet gives.

use serde::{Deserialize, Serialize};

/// A lidar unit, as a scenario's `[sensors.lidar] model` names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum LidarModel {
    /// Neato XV-11 (the default).
    #[default]
    #[serde(rename = "xv11")]
    Xv11,
    /// Slamtec RPLIDAR A1.
    #[serde(rename = "rplidar-a1")]
    RplidarA1,
    /// Hitachi-LG HLS-LFCD2, sold as the TurtleBot3's LDS-01.
    #[serde(rename = "lds-01")]
    Lds01,
    /// Xiaomi LDS02RR (robot vacuum lidar).
    #[serde(rename = "lds-02rr")]
    Lds02rr,
    /// LDROBOT LD06.
    #[serde(rename = "ld06")]
    Ld06,
    /// YDLIDAR X4.
    #[serde(rename = "ydlidar-x4")]
    YdlidarX4,
    /// Hokuyo URG-04LX, speaking SCIP 2.0.
    #[serde(rename = "urg-04lx")]
    Urg04lx,
}

impl LidarModel {
    /// Every model, the default first.
    pub const ALL: [LidarModel; 7] = [
        LidarModel::Xv11,
        LidarModel::RplidarA1,
        LidarModel::Lds01,
        LidarModel::Lds02rr,
        LidarModel::Ld06,
        LidarModel::YdlidarX4,
        LidarModel::Urg04lx,
    ];

    /// The model's name in scenarios and on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        self.spec().name
    }

    /// The model named `name` (as a scenario writes it).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// What the unit is.
    #[must_use]
    pub fn spec(self) -> &'static UnitSpec {
        match self {
            LidarModel::Xv11 => &XV11,
            LidarModel::RplidarA1 => &RPLIDAR_A1,
            LidarModel::Lds01 => &LDS_01,
            LidarModel::Lds02rr => &LDS_02RR,
            LidarModel::Ld06 => &LD06,
            LidarModel::YdlidarX4 => &YDLIDAR_X4,
            LidarModel::Urg04lx => &URG_04LX,
        }
    }
}

impl std::fmt::Display for LidarModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for LidarModel {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s).ok_or_else(|| {
            let names: Vec<_> = Self::ALL.iter().map(|m| m.name()).collect();
            format!(
                "unknown lidar model {s:?}: expected one of {}",
                names.join(", ")
            )
        })
    }
}

/// Which way the head turns, seen from above; a unit's angles grow that way.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Angles grow counter-clockwise (hilsim's own frame, the XV-11's and the URG's).
    CounterClockwise,
    /// Angles grow clockwise.
    Clockwise,
}

/// Where a unit takes its readings in a revolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sampling {
    /// On a fixed grid of `steps_per_rev` equal steps, each at its own instant; steps
    /// `first..=last` are read (the others are blind), and step `zero` points forward.
    Grid {
        /// Steps in a whole revolution.
        steps_per_rev: u32,
        /// The first step read.
        first: u32,
        /// The last step read.
        last: u32,
        /// The step that looks along the unit's 0° (forward).
        zero: u32,
    },
    /// At a fixed sample rate while the head turns at its own speed: the readings' angles and
    /// their number change from revolution to revolution.
    FreeRunning {
        /// Readings per second.
        sample_rate_hz: f64,
    },
}

/// What a unit is: the numbers its datasheet gives, with the source beside each.
#[derive(Debug, Clone, PartialEq)]
pub struct UnitSpec {
    /// The model's name in scenarios (`rplidar-a1`).
    pub name: &'static str,
    /// The unit's maker and name, for people.
    pub title: &'static str,
    /// The serial speed its drivers open the port at, baud.
    pub baud: u32,
    /// Which way its angles grow.
    pub direction: Direction,
    /// Where it takes its readings.
    pub sampling: Sampling,
    /// Its nominal revolution rate, Hz.
    pub rev_hz: f64,
    /// The revolution rates it can run at, Hz.
    pub rev_hz_range: (f64, f64),
    /// Relative standard deviation of the rate from one revolution to the next (a free-running
    /// motor's speed loop; 0 for a unit that locks its rate). A modelling choice of a few tenths
    /// of a percent: no datasheet gives it.
    pub rev_hz_jitter: f64,
    /// Nearest range it reports, metres.
    pub min_range_m: f64,
    /// Farthest range it reports, metres.
    pub max_range_m: f64,
    /// The noise standard deviation polynomial in range its datasheet gives (`None`: it gives
    /// none, and the scenario's model applies), as a scenario's `noise` coefficients.
    pub noise: Option<&'static [f64]>,
    /// Whether it waits for a host's command before it sends readings.
    pub command_driven: bool,
}

/// Neato XV-11: 360 readings a revolution at 300 rpm (Konolige et al., ICRA 2008; the Neato
/// format notes in `docs/formats/neato-xv11.md`).
static XV11: UnitSpec = UnitSpec {
    name: "xv11",
    title: "Neato XV-11",
    baud: 115_200,
    direction: Direction::CounterClockwise,
    sampling: Sampling::Grid {
        steps_per_rev: 360,
        first: 0,
        last: 359,
        zero: 0,
    },
    rev_hz: 5.0,
    rev_hz_range: (1.0 / 64.0 / 60.0, 1023.98 / 60.0),
    rev_hz_jitter: 0.0,
    min_range_m: 0.2,
    max_range_m: 6.0,
    noise: None,
    command_driven: false,
};

/// Slamtec RPLIDAR A1 (A1M8 datasheet v2.x): 5.5 Hz typical (5–10 Hz), 2,000 samples a second
/// in the standard scan mode, 0.15–12 m, clockwise; accuracy "1 % of the range" up to 3 m,
/// taken here as the noise's standard deviation.
static RPLIDAR_A1: UnitSpec = UnitSpec {
    name: "rplidar-a1",
    title: "Slamtec RPLIDAR A1",
    baud: 115_200,
    direction: Direction::Clockwise,
    sampling: Sampling::FreeRunning {
        sample_rate_hz: 2_000.0,
    },
    rev_hz: 5.5,
    rev_hz_range: (5.0, 10.0),
    rev_hz_jitter: 0.002,
    min_range_m: 0.15,
    max_range_m: 12.0,
    noise: Some(&[0.0, 0.01]),
    command_driven: true,
};

/// Hitachi-LG HLS-LFCD2 (ROBOTIS e-manual, "LDS-01 specifications"): 300 ± 10 rpm, 1° angular
/// resolution, 120–3,500 mm; accuracy ±15 mm below 0.5 m and ±5 % to 3.5 m (read here as
/// σ = 15 mm + 2.5 % of the range: the ±5 % as two standard deviations). Its degrees grow
/// clockwise: the ROBOTIS `hls_lfcd_lds_driver` publishes them in chronological order with an
/// angle increment of −1° (`hlds_laser_publisher.cpp`, `chronological_order`). It streams from
/// power-on since its 2017.10 firmware (the same driver: its `b` start command "not required
/// after firmware upgrade"); `e` and `b` stop and restart it.
static LDS_01: UnitSpec = UnitSpec {
    name: "lds-01",
    title: "Hitachi-LG HLS-LFCD2 (LDS-01)",
    baud: 230_400,
    direction: Direction::Clockwise,
    sampling: Sampling::Grid {
        steps_per_rev: 360,
        first: 0,
        last: 359,
        zero: 0,
    },
    rev_hz: 5.0,
    rev_hz_range: (290.0 / 60.0, 310.0 / 60.0),
    rev_hz_jitter: 0.0,
    min_range_m: 0.12,
    max_range_m: 3.5,
    noise: Some(&[0.015, 0.025]),
    command_driven: false,
};

/// Xiaomi LDS02RR: an XV-11 descendant sending the XV-11's packets, 360 readings a revolution at
/// about 300 rpm (its motor driven by the host's PWM); no published datasheet, so the
/// scenario's range model applies. Range 0.15–6 m as for the XV-11 family. Its degrees grow
/// clockwise, unlike the XV-11's (`lds2d` `xiaomi_lds02rr.py` and kaiaai `LDS` read its index
/// unmirrored, the XV-11's mirrored).
static LDS_02RR: UnitSpec = UnitSpec {
    name: "lds-02rr",
    title: "Xiaomi LDS02RR",
    baud: 115_200,
    direction: Direction::Clockwise,
    sampling: Sampling::Grid {
        steps_per_rev: 360,
        first: 0,
        last: 359,
        zero: 0,
    },
    rev_hz: 5.0,
    rev_hz_range: (1.0, 10.0),
    rev_hz_jitter: 0.003,
    min_range_m: 0.15,
    max_range_m: 6.0,
    noise: None,
    command_driven: false,
};

/// LDROBOT LD06 (LD06 datasheet v1.x): 10 Hz (5–13 Hz), 4,500 samples a second, 0.02–12 m,
/// clockwise, 12 readings a packet; its accuracy figure is not given as a function of range,
/// so the scenario's range model applies.
static LD06: UnitSpec = UnitSpec {
    name: "ld06",
    title: "LDROBOT LD06",
    baud: 230_400,
    direction: Direction::Clockwise,
    sampling: Sampling::FreeRunning {
        sample_rate_hz: 4_500.0,
    },
    rev_hz: 10.0,
    rev_hz_range: (5.0, 13.0),
    rev_hz_jitter: 0.002,
    min_range_m: 0.02,
    max_range_m: 12.0,
    noise: None,
    command_driven: false,
};

/// YDLIDAR X4 (X4 datasheet v1.x): 7 Hz (6–12 Hz), 5,000 samples a second, 0.12–10 m,
/// clockwise; its range resolution figure is not an accuracy, so the scenario's range model
/// applies.
static YDLIDAR_X4: UnitSpec = UnitSpec {
    name: "ydlidar-x4",
    title: "YDLIDAR X4",
    baud: 128_000,
    direction: Direction::Clockwise,
    sampling: Sampling::FreeRunning {
        sample_rate_hz: 5_000.0,
    },
    rev_hz: 7.0,
    rev_hz_range: (6.0, 12.0),
    rev_hz_jitter: 0.003,
    min_range_m: 0.12,
    max_range_m: 10.0,
    noise: None,
    command_driven: true,
};

/// Hokuyo URG-04LX (URG-04LX specification, Hokuyo, and the SCIP 2.0 specification): 100 ms a
/// scan, 1,024 steps a revolution of which steps 44–725 are read (240°), step 384 forward,
/// counter-clockwise, 20–5,600 mm; accuracy ±10 mm to 1 m, then 1 % of the measurement (read
/// as σ = 1 % of the range, never under 10 mm at 1 m).
static URG_04LX: UnitSpec = UnitSpec {
    name: "urg-04lx",
    title: "Hokuyo URG-04LX (SCIP 2.0)",
    baud: 115_200,
    direction: Direction::CounterClockwise,
    sampling: Sampling::Grid {
        steps_per_rev: 1024,
        first: 44,
        last: 725,
        zero: 384,
    },
    rev_hz: 10.0,
    rev_hz_range: (10.0, 10.0),
    rev_hz_jitter: 0.0,
    min_range_m: 0.02,
    max_range_m: 5.6,
    noise: Some(&[0.0, 0.01]),
    command_driven: true,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_model_round_trips_its_name() {
        for model in LidarModel::ALL {
            assert_eq!(model.name().parse::<LidarModel>(), Ok(model));
        }
        assert!("lds-03"
            .parse::<LidarModel>()
            .unwrap_err()
            .contains("rplidar-a1"));
    }

    #[test]
    fn specs_are_consistent() {
        for model in LidarModel::ALL {
            let s = model.spec();
            assert!(
                s.rev_hz_range.0 <= s.rev_hz && s.rev_hz <= s.rev_hz_range.1,
                "{s:?}"
            );
            assert!(s.min_range_m < s.max_range_m, "{s:?}");
            if let Sampling::Grid {
                steps_per_rev,
                first,
                last,
                zero,
            } = s.sampling
            {
                assert!(
                    first <= zero && zero <= last && last < steps_per_rev,
                    "{s:?}"
                );
            }
        }
    }
}
