//! Gaussian priors on bias coefficients (`--prior SENSOR.COEF=VALUE±SD`), for what the user
//! knows that the data cannot tell: a constant speed-scale error of the commands folds into
//! every sensor's scale (docs/em-calibration.md, Sec. 7), but a sonar's scale follows from the
//! speed of sound at a known temperature and an odometer's from a measured wheel. With a prior
//! on one scale, EM estimates the commands' speed scale too ([`Priors::pins_a_scale`]).

use std::fmt;
use std::str::FromStr;

use crate::{CalibrationError, Sensor};

use super::model::{LIDAR, ODOMETER, SENSORS, SONAR};

/// The largest prior mean: a bias coefficient is an offset in metres, a scale or a per-metre
/// curvature, none of which is near 100 for a distance sensor.
pub const MAX_ABS_MEAN: f64 = 100.0;

/// A prior's sd: below a millionth its weight swamps the data's normal equations (they lose
/// every digit), above 100 it says nothing.
pub const SD_RANGE: std::ops::RangeInclusive<f64> = 1e-6..=100.0;

/// One coefficient's prior: `alpha_i ~ N(mean, sd²)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prior {
    /// The sensor.
    pub sensor: Sensor,
    /// Which bias coefficient (`alpha_i`).
    pub coefficient: usize,
    /// Its prior mean.
    pub mean: f64,
    /// Its prior standard deviation (> 0).
    pub sd: f64,
}

impl fmt::Display for Prior {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}.alpha{}={}±{}",
            self.sensor.name(),
            self.coefficient,
            self.mean,
            self.sd
        )
    }
}

impl FromStr for Prior {
    type Err = CalibrationError;

    /// `SENSOR.alphaI=VALUE±SD` (`+-` for `±`), e.g. `sonar.alpha1=1.028±0.003`.
    fn from_str(text: &str) -> Result<Self, CalibrationError> {
        let bad = |why: &str| {
            CalibrationError::Invalid(format!(
                "--prior {text}: {why} (expected SENSOR.alphaI=VALUE±SD, e.g. \
                 sonar.alpha1=1.028±0.003)"
            ))
        };
        let (name, value) = text.split_once('=').ok_or_else(|| bad("no '='"))?;
        let (sensor, coefficient) = name.split_once('.').ok_or_else(|| bad("no '.'"))?;
        let sensor = Sensor::ALL
            .into_iter()
            .find(|s| s.name() == sensor.trim())
            .ok_or_else(|| bad("the sensor is one of lidar, sonar, odometer"))?;
        let coefficient = coefficient.trim();
        if coefficient.starts_with("beta") {
            return Err(bad("priors are on the bias coefficients alpha only"));
        }
        let coefficient: usize = coefficient
            .strip_prefix("alpha")
            .and_then(|i| i.parse().ok())
            .ok_or_else(|| bad("the coefficient is alpha0, alpha1 or alpha2"))?;
        let max = if sensor == Sensor::Lidar { 2 } else { 1 };
        if coefficient > max {
            return Err(bad(&format!(
                "the {} model of EM has alpha0..alpha{max}",
                sensor.name()
            )));
        }
        let (mean, sd) = value
            .split_once('±')
            .or_else(|| value.split_once("+-"))
            .ok_or_else(|| bad("no '±' (or '+-') before the standard deviation"))?;
        let mean: f64 = mean
            .trim()
            .parse()
            .map_err(|_| bad("the value is not a number"))?;
        let sd: f64 = sd
            .trim()
            .parse()
            .map_err(|_| bad("the sd is not a number"))?;
        if !(mean.is_finite() && mean.abs() <= MAX_ABS_MEAN) {
            return Err(bad(&format!(
                "the value must be from -{MAX_ABS_MEAN} to {MAX_ABS_MEAN}"
            )));
        }
        if !SD_RANGE.contains(&sd) {
            return Err(bad(&format!(
                "the sd must be positive: from {:?} to {}",
                SD_RANGE.start(),
                SD_RANGE.end()
            )));
        }
        Ok(Self {
            sensor,
            coefficient,
            mean,
            sd,
        })
    }
}

/// The priors of one EM run, by sensor slot and coefficient (`Copy`, as the options are).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Priors {
    table: [[Option<(f64, f64)>; 3]; SENSORS],
}

impl Priors {
    /// The priors given, one per coefficient.
    ///
    /// # Errors
    /// [`CalibrationError::Invalid`] when a coefficient has two.
    pub fn new(priors: &[Prior]) -> Result<Self, CalibrationError> {
        let mut table = [[None; 3]; SENSORS];
        for p in priors {
            let slot = slot_of(p.sensor);
            let cell = &mut table[slot][p.coefficient];
            if cell.is_some() {
                return Err(CalibrationError::Invalid(format!(
                    "--prior: two priors on {}.alpha{}",
                    p.sensor.name(),
                    p.coefficient
                )));
            }
            *cell = Some((p.mean, p.sd));
        }
        Ok(Self { table })
    }

    /// The prior `(mean, sd)` on `alpha_i` of the sensor in `slot`.
    pub(crate) fn get(&self, slot: usize, i: usize) -> Option<(f64, f64)> {
        self.table[slot][i]
    }

    /// Whether any coefficient has a prior.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.table.iter().flatten().all(Option::is_none)
    }

    /// Whether a prior pins a sensor's scale (`alpha1`): then the commands' speed scale is
    /// identifiable and EM estimates it.
    #[must_use]
    pub fn pins_a_scale(&self) -> bool {
        self.table.iter().any(|row| row[1].is_some())
    }

    /// The priors, for the notes.
    #[must_use]
    pub fn list(&self) -> Vec<Prior> {
        let mut out = Vec::new();
        for (slot, row) in self.table.iter().enumerate() {
            for (coefficient, cell) in row.iter().enumerate() {
                if let Some((mean, sd)) = cell {
                    out.push(Prior {
                        sensor: sensor_of(slot),
                        coefficient,
                        mean: *mean,
                        sd: *sd,
                    });
                }
            }
        }
        out
    }
}

fn slot_of(sensor: Sensor) -> usize {
    match sensor {
        Sensor::Lidar => LIDAR,
        Sensor::Odometer => ODOMETER,
        Sensor::Sonar => SONAR,
    }
}

fn sensor_of(slot: usize) -> Sensor {
    match slot {
        LIDAR => Sensor::Lidar,
        ODOMETER => Sensor::Odometer,
        _ => Sensor::Sonar,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn priors_parse_with_either_sign() {
        let p: Prior = "sonar.alpha1=1.028±0.003".parse().unwrap();
        assert_eq!(
            (p.sensor, p.coefficient, p.mean, p.sd),
            (Sensor::Sonar, 1, 1.028, 0.003)
        );
        let p: Prior = "lidar.alpha0=0.05+-0.01".parse().unwrap();
        assert_eq!((p.sensor, p.coefficient), (Sensor::Lidar, 0));
        assert_eq!(p.to_string(), "lidar.alpha0=0.05±0.01");
    }

    #[test]
    fn bad_priors_say_what_is_wrong() {
        for (text, why) in [
            ("sonar.alpha1", "no '='"),
            ("sonar.alpha1=1.0", "no '±'"),
            ("radar.alpha1=1±0.1", "the sensor"),
            ("sonar.beta0=1±0.1", "alpha only"),
            ("sonar.alpha2=1±0.1", "alpha0..alpha1"),
            ("sonar.alpha1=1±0", "positive"),
            ("sonar.alpha1=x±0.1", "not a number"),
            ("sonar.alpha1=1e300±0.1", "from -100 to 100"),
            ("sonar.alpha1=1±1e-300", "positive: from 1e-6 to 100"),
            ("sonar.alpha1=1±1e300", "positive: from 1e-6 to 100"),
        ] {
            let err = text.parse::<Prior>().unwrap_err().to_string();
            assert!(err.contains(why), "{text}: {err}");
        }
        let twice = ["sonar.alpha1=1±0.1", "sonar.alpha1=1.1±0.1"].map(|t| t.parse().unwrap());
        assert!(Priors::new(&twice).is_err());
    }

    #[test]
    fn only_a_scale_prior_pins_the_speed_scale() {
        let offset = Priors::new(&["lidar.alpha0=0.05±0.01".parse().unwrap()]).unwrap();
        assert!(!offset.is_empty() && !offset.pins_a_scale());
        let scale = Priors::new(&["sonar.alpha1=1.028±0.003".parse().unwrap()]).unwrap();
        assert!(scale.pins_a_scale());
        assert_eq!(scale.list().len(), 1);
    }
}
