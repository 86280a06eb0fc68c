//! `meta.toml`: what a calibrator must know about the robot and the world besides the samples.

use crate::pose::Pose;
use serde::{Deserialize, Serialize};

/// The format tag every `meta.toml` carries.
pub const FORMAT: &str = "hilsim-recording/1";

/// The contents of `meta.toml`.
///
/// Unknown keys are ignored when reading, so that other tools may add their own.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Meta {
    /// Always [`FORMAT`].
    pub format: String,
    /// The robot's geometry.
    pub robot: RobotMeta,
    /// The lidar's mount pose; absent when the robot has no lidar.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lidar: Option<Mount>,
    /// The sonar's mount and beam; absent when the robot has no sonar.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sonar: Option<SonarMount>,
    /// What is known of the environment.
    #[serde(default, skip_serializing_if = "WorldMeta::is_empty")]
    pub world: WorldMeta,
    /// Where the recording came from (hilsim's own addition; optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<SourceMeta>,
}

impl Default for Meta {
    fn default() -> Self {
        Self {
            format: FORMAT.to_string(),
            robot: RobotMeta {
                wheel_base_m: 0.23,
                wheel_radius_m: None,
            },
            lidar: None,
            sonar: None,
            world: WorldMeta::default(),
            source: None,
        }
    }
}

/// `[robot]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotMeta {
    /// Distance between the wheels, metres.
    pub wheel_base_m: f64,
    /// The wheels' nominal radius, metres: what the encoders' turns were multiplied by to give
    /// `odometry.csv`'s travel. Absent when not known (a bag's `/odom`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wheel_radius_m: Option<f64>,
}

/// A sensor's mount pose in the robot frame (x forward, y left), as files write it: `meta.toml`'s
/// `[lidar]` table, a scenario's `mount`. The one mount type of the sensor models.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Mount {
    /// Forward offset, metres.
    #[serde(default)]
    pub x_m: f64,
    /// Leftward offset, metres.
    #[serde(default)]
    pub y_m: f64,
    /// Yaw of the sensor's 0° axis relative to the robot's forward axis, degrees.
    #[serde(default)]
    pub yaw_deg: f64,
}

impl Mount {
    /// The yaw in radians.
    #[must_use]
    pub fn yaw_rad(&self) -> f64 {
        self.yaw_deg.to_radians()
    }

    /// The sensor's pose in the world when the robot is at `robot`.
    #[must_use]
    pub fn in_world(&self, robot: &Pose) -> Pose {
        robot.compose(self.x_m, self.y_m, self.yaw_rad())
    }
}

/// `[sonar]`: the mount and the beam.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SonarMount {
    /// Forward offset, metres (hilsim addition; default 0).
    #[serde(default)]
    pub x_m: f64,
    /// Leftward offset, metres (hilsim addition; default 0).
    #[serde(default)]
    pub y_m: f64,
    /// Yaw of the beam axis relative to the robot's forward axis, degrees.
    #[serde(default)]
    pub yaw_deg: f64,
    /// Half of the beam cone, degrees.
    pub half_angle_deg: f64,
}

/// `[world]`: what is known of the environment; every key optional.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct WorldMeta {
    /// The cylinders' radius, when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub landmark_radius_m: Option<f64>,
    /// Lidar-to-frontal-target distance at t = 0, when known (EM needs it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_start_distance_m: Option<f64>,
}

impl WorldMeta {
    fn is_empty(&self) -> bool {
        self.landmark_radius_m.is_none() && self.target_start_distance_m.is_none()
    }
}

/// `[source]`: which scenario and seed produced a simulated recording.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SourceMeta {
    /// What wrote the recording, e.g. `hilsim 0.1.0`.
    pub generator: String,
    /// The scenario's name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scenario: Option<String>,
    /// The seed of the run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

impl Meta {
    /// A note for each key of the `meta.toml` in the recording directory `dir` that the format
    /// does not have, its name terminal-safe: a misspelt key reads as absent, so a result made
    /// from the recording says so. None when the file cannot be read (reading the recording
    /// reports that).
    #[must_use]
    pub fn unknown_key_notes(dir: &std::path::Path) -> Vec<String> {
        let meta = dir.join("meta.toml");
        let text = crate::input::read_small_text(&meta, crate::input::MAX_META_BYTES, "meta.toml");
        let keys = text
            .map(|text| Self::unknown_keys(&text))
            .unwrap_or_default();
        keys.iter()
            .map(|key| {
                format!(
                    "meta.toml: `{}` is not a key of the recording format; ignored",
                    crate::printable(key)
                )
            })
            .collect()
    }

    /// The keys of a `meta.toml` text that the format does not define, as dotted paths
    /// (`bogus`, `lidar.x_mm`). Reading ignores them, so that other tools may add their own; but
    /// a misspelt key reads as absent, so a calibration notes them. Empty for text that is not
    /// TOML (reading it reports that).
    #[must_use]
    pub fn unknown_keys(text: &str) -> Vec<String> {
        let Ok(given) = text.parse::<toml::Table>() else {
            return Vec::new();
        };
        // Every key the format defines: a `Meta` with every optional part present.
        let full = Meta {
            lidar: Some(Mount::default()),
            sonar: Some(SonarMount {
                x_m: 0.0,
                y_m: 0.0,
                yaw_deg: 0.0,
                half_angle_deg: 0.0,
            }),
            world: WorldMeta {
                landmark_radius_m: Some(0.0),
                target_start_distance_m: Some(0.0),
            },
            source: Some(SourceMeta {
                generator: String::new(),
                scenario: Some(String::new()),
                seed: Some(0),
            }),
            robot: RobotMeta {
                wheel_base_m: 0.0,
                wheel_radius_m: Some(0.0),
            },
            ..Meta::default()
        };
        let known = toml::Table::try_from(full).unwrap_or_default();
        let mut unknown = Vec::new();
        unknown_in(&given, &known, "", &mut unknown);
        unknown
    }
}

fn unknown_in(given: &toml::Table, known: &toml::Table, prefix: &str, out: &mut Vec<String>) {
    for (key, value) in given {
        match (value, known.get(key)) {
            (_, None) => out.push(format!("{prefix}{key}")),
            (toml::Value::Table(inner), Some(toml::Value::Table(defined))) => {
                unknown_in(inner, defined, &format!("{prefix}{key}."), out);
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_keys_of_a_directory_are_noted_terminal_safe() {
        let dir = tempfile::tempdir().unwrap();
        assert!(Meta::unknown_key_notes(dir.path()).is_empty());
        std::fs::write(
            dir.path().join("meta.toml"),
            "\"b\\u001b\" = 1\n[robot]\nwheel_base_m = 0.3\n",
        )
        .unwrap();
        let notes = Meta::unknown_key_notes(dir.path());
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(!notes[0].contains('\u{1b}'), "{notes:?}");
        assert!(notes[0].ends_with("is not a key of the recording format; ignored"));
    }

    #[test]
    fn keys_the_format_does_not_define_are_listed_as_paths() {
        let text = "format = \"hilsim-recording/1\"\n[robot]\nwheel_base_m = 0.23\n\
                    [lidar]\nx_mm = 5\n[world]\ntarget_start_distance_m = 0.5\n[bogus]\nx = 1\n";
        assert_eq!(Meta::unknown_keys(text), ["bogus", "lidar.x_mm"]);
    }

    #[test]
    fn every_key_hilsim_writes_is_known() {
        let meta = Meta {
            lidar: Some(Mount::default()),
            world: WorldMeta {
                landmark_radius_m: Some(0.12),
                target_start_distance_m: None,
            },
            source: Some(SourceMeta {
                generator: "hilsim".into(),
                scenario: Some("s".into()),
                seed: Some(7),
            }),
            ..Meta::default()
        };
        let text = toml::to_string(&meta).unwrap();
        assert!(Meta::unknown_keys(&text).is_empty(), "{text}");
        assert!(Meta::unknown_keys("not = = toml").is_empty());
    }
}
