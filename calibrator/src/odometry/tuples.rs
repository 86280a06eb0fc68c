//! The paper's "tuples": one interval of an ordinary drive each, the wheels' mean angular speeds
//! and the lidar's own displacement over it from scan matching. Censi et al.'s supplementary
//! material ships them as a stream of JSON objects (one a line, though a few lines hold two);
//! [`from_recording`](super::from_recording) makes the same from a hilsim recording.

use serde::Deserialize;

use crate::CalibrationError;

/// One interval of the drive.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub struct Tuple {
    /// The interval's length, seconds.
    #[serde(rename = "T")]
    pub duration_s: f64,
    /// The left wheel's mean angular speed over the interval, rad/s.
    #[serde(rename = "phi_l")]
    pub left_rad_s: f64,
    /// The right wheel's mean angular speed over the interval, rad/s.
    #[serde(rename = "phi_r")]
    pub right_rad_s: f64,
    /// The lidar's displacement over the interval in its own frame at the start (x, y metres,
    /// θ radians), from scan matching.
    #[serde(rename = "sm")]
    pub lidar_motion: [f64; 3],
}

impl Tuple {
    /// Whether every number is finite and the interval has a length.
    #[must_use]
    pub fn is_sound(&self) -> bool {
        self.duration_s > 0.0
            && self.duration_s.is_finite()
            && self.left_rad_s.is_finite()
            && self.right_rad_s.is_finite()
            && self.lidar_motion.iter().all(|v| v.is_finite())
    }
}

/// Most tuples a file may hold: a million, about 10 days of intervals of a second; 50 MB of
/// tuples in memory.
pub const MAX_TUPLES: usize = 1_000_000;

/// The tuples of a file's `text`, in order, with the number left out for a non-finite number or
/// an interval without a length. `origin` names the file in errors.
///
/// # Errors
/// [`CalibrationError::Invalid`] naming the line of the first object that is not a tuple, or
/// when there are more than [`MAX_TUPLES`].
pub fn parse_tuples(text: &str, origin: &str) -> Result<(Vec<Tuple>, usize), CalibrationError> {
    let mut tuples = Vec::new();
    let mut unsound = 0;
    let stream = serde_json::Deserializer::from_str(text).into_iter::<Tuple>();
    for item in stream {
        let tuple = item.map_err(|e| {
            CalibrationError::Invalid(format!(
                "{origin}:{}: not a tuple (an object with numbers T, phi_l, phi_r and sm: [x, \
                 y, theta]): {e}",
                e.line()
            ))
        })?;
        if tuples.len() == MAX_TUPLES {
            return Err(CalibrationError::Invalid(format!(
                "{origin}: more than {MAX_TUPLES} tuples"
            )));
        }
        if tuple.is_sound() {
            tuples.push(tuple);
        } else {
            unsound += 1;
        }
    }
    Ok((tuples, unsound))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_objects_on_a_line_are_two_tuples() {
        let text = "{\"T\": 1.0, \"phi_l\": 0.5, \"phi_r\": 0.4, \"sm\": [0.01, 0.0, -0.001]}\n\
                    {\"T\": 0.8, \"phi_l\": 0.1, \"phi_r\": 0.2, \"sm\": [0.0, 0.0, 0.0]} \
                    {\"T\": 0.9, \"phi_l\": 0.3, \"phi_r\": 0.3, \"sm\": [0.02, 0.0, 0.0]}\n";
        let (tuples, unsound) = parse_tuples(text, "t.tuple").unwrap();
        assert_eq!(tuples.len(), 3);
        assert_eq!(unsound, 0);
        assert_eq!(tuples[2].duration_s, 0.9);
        assert_eq!(tuples[0].lidar_motion, [0.01, 0.0, -0.001]);
    }

    #[test]
    fn a_broken_object_is_named_by_its_line() {
        let text = "{\"T\": 1.0, \"phi_l\": 0.5, \"phi_r\": 0.4, \"sm\": [0.01, 0.0, -0.001]}\n\
                    {\"T\": 1.0, \"phi_l\": 0.5, \"sm\": [0.01, 0.0]}\n";
        let err = parse_tuples(text, "t.tuple").unwrap_err().to_string();
        assert!(err.starts_with("t.tuple:2: not a tuple"), "{err}");
    }

    #[test]
    fn an_interval_without_a_length_is_counted_not_used() {
        let text = "{\"T\": 0.0, \"phi_l\": 0.5, \"phi_r\": 0.4, \"sm\": [0.01, 0.0, 0.0]}";
        assert_eq!(parse_tuples(text, "t").unwrap(), (vec![], 1));
    }
}
