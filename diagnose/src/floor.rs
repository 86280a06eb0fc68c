//! The practical floors as a user types them: one sensor's (`SENSOR=MM`, `hilsim diagnose
//! --floor`) and the noise share (`--floor-noise-share`).

use std::fmt;
use std::str::FromStr;

use crate::Floors;

/// A sensor's floor: a mismatch smaller than this is not reported.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorFloor {
    sensor: FloorSensor,
    metres: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FloorSensor {
    Lidar,
    Sonar,
    Odometer,
    Drive,
}

/// Why a floor was refused: what was expected and what was found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParseFloorError(String);

impl fmt::Display for ParseFloorError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ParseFloorError {}

impl FromStr for SensorFloor {
    type Err = ParseFloorError;

    /// `SENSOR=MM`: SENSOR one of lidar, sonar, odometer, drive; MM a size in millimetres ≥ 0.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let Some((sensor, mm)) = s.split_once('=') else {
            return Err(ParseFloorError(format!("expected SENSOR=MM, found `{s}`")));
        };
        let metres = match mm.trim().parse::<f64>() {
            Ok(v) if v >= 0.0 && v.is_finite() => v / 1000.0,
            _ => {
                return Err(ParseFloorError(format!(
                    "expected a size in millimetres ≥ 0, found `{mm}`"
                )))
            }
        };
        let sensor = match sensor.trim() {
            "lidar" => FloorSensor::Lidar,
            "sonar" => FloorSensor::Sonar,
            "odometer" => FloorSensor::Odometer,
            "drive" => FloorSensor::Drive,
            other => {
                return Err(ParseFloorError(format!(
                    "expected a sensor (lidar, sonar, odometer, drive), found `{other}`"
                )))
            }
        };
        Ok(Self { sensor, metres })
    }
}

impl Floors {
    /// These floors with `floor`'s sensor's replaced.
    #[must_use]
    pub fn with(mut self, floor: SensorFloor) -> Self {
        let slot = match floor.sensor {
            FloorSensor::Lidar => &mut self.lidar_m,
            FloorSensor::Sonar => &mut self.sonar_m,
            FloorSensor::Odometer => &mut self.odometer_m,
            FloorSensor::Drive => &mut self.drive_m,
        };
        *slot = floor.metres;
        self
    }

    /// The default floors with each of `floors` (`SENSOR=MM`, `--floor`) and the share of the
    /// declared noise `noise_share` (`--floor-noise-share`, ≥ 0) when given.
    ///
    /// # Errors
    /// A floor or share that is not one, naming its flag.
    pub fn from_flags(
        floors: &[String],
        noise_share: Option<f64>,
    ) -> Result<Self, ParseFloorError> {
        let mut result = Self::default();
        for floor in floors {
            let floor: SensorFloor = floor
                .parse()
                .map_err(|e: ParseFloorError| ParseFloorError(format!("--floor: {}", e.0)))?;
            result = result.with(floor);
        }
        if let Some(x) = noise_share {
            if !(x.is_finite() && x >= 0.0) {
                return Err(ParseFloorError(format!(
                    "--floor-noise-share: expected a share ≥ 0, found {x}"
                )));
            }
            result.noise_share = x;
        }
        Ok(result)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_floor_replaces_its_sensors_only() {
        let floor: SensorFloor = " sonar = 12".parse().expect("a floor");
        let floors = Floors::default().with(floor);
        assert_eq!(floors.sonar_m, 0.012);
        assert_eq!(floors.lidar_m, Floors::default().lidar_m);
    }

    #[test]
    fn flags_name_themselves_in_errors() {
        let floors = Floors::from_flags(&["lidar=5".to_string()], Some(0.5)).expect("floors");
        assert_eq!(floors.lidar_m, 0.005);
        assert_eq!(floors.noise_share, 0.5);
        let err = Floors::from_flags(&["lidar".to_string()], None).expect_err("no size");
        assert_eq!(
            err.to_string(),
            "--floor: expected SENSOR=MM, found `lidar`"
        );
        let err = Floors::from_flags(&[], Some(f64::NAN)).expect_err("not a share");
        assert_eq!(
            err.to_string(),
            "--floor-noise-share: expected a share ≥ 0, found NaN"
        );
    }

    #[test]
    fn bad_floors_say_what_was_expected() {
        let err = |s: &str| s.parse::<SensorFloor>().expect_err(s).to_string();
        assert_eq!(err("lidar"), "expected SENSOR=MM, found `lidar`");
        assert_eq!(
            err("lidar=-1"),
            "expected a size in millimetres ≥ 0, found `-1`"
        );
        assert!(err("radar=1").contains("found `radar`"));
    }
}
