//! An import as the command line asks for it: the flags, checked into [`ImportOptions`] before
//! the bag is opened.

use std::collections::BTreeMap;
use std::fmt;

use crate::import::ImportOptions;
use crate::topics::Role;

/// The import's flags as given, unchecked.
#[derive(Debug, Clone, Copy, Default)]
pub struct ImportFlags<'a> {
    /// `--lidar`: the lidar's topic.
    pub lidar: Option<&'a str>,
    /// `--odom`: the odometer's topic.
    pub odom: Option<&'a str>,
    /// `--cmd`: the commands' topic.
    pub cmd: Option<&'a str>,
    /// `--sonar`: the sonar's topic.
    pub sonar: Option<&'a str>,
    /// `--truth`: the true pose's topic.
    pub truth: Option<&'a str>,
    /// `--wheel-radius-m`: the wheels' radius, metres.
    pub wheel_radius_m: Option<f64>,
    /// `--wheel-joints`: `LEFT,RIGHT`, the wheels' joints in `JointState`.
    pub wheel_joints: Option<&'a str>,
}

/// A flag's value that makes no sense: the flag and what was expected, as one line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FlagError(String);

impl fmt::Display for FlagError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for FlagError {}

impl ImportFlags<'_> {
    /// The name of the first flag given that only a bag's import reads (a robot's log has no
    /// topics, and its wheels are in the log).
    #[must_use]
    pub fn first_given(&self) -> Option<&'static str> {
        let given = [
            ("--lidar", self.lidar.is_some()),
            ("--odom", self.odom.is_some()),
            ("--cmd", self.cmd.is_some()),
            ("--sonar", self.sonar.is_some()),
            ("--truth", self.truth.is_some()),
            ("--wheel-radius-m", self.wheel_radius_m.is_some()),
            ("--wheel-joints", self.wheel_joints.is_some()),
        ];
        given
            .iter()
            .find(|(_, given)| *given)
            .map(|(flag, _)| *flag)
    }

    /// The options the flags ask for, with no `meta.toml` (the caller reads it).
    ///
    /// # Errors
    /// A wheel radius that is not in (0, 10] m, or wheel joints that are not two different
    /// names.
    pub fn options(&self) -> Result<ImportOptions, FlagError> {
        if self
            .wheel_radius_m
            .is_some_and(|r| !(r.is_finite() && r > 0.0 && r <= 10.0))
        {
            return Err(FlagError(
                "--wheel-radius-m: expected a radius in metres, above 0 and at most 10".into(),
            ));
        }
        let wheel_joints = match self.wheel_joints.map(|j| j.split(',').collect::<Vec<_>>()) {
            None => None,
            Some(names) => match names.as_slice() {
                [left, right] if !left.is_empty() && !right.is_empty() && left != right => {
                    Some([(*left).to_string(), (*right).to_string()])
                }
                _ => {
                    return Err(FlagError(
                        "--wheel-joints: expected LEFT,RIGHT, two different joint names".into(),
                    ))
                }
            },
        };
        let topics: BTreeMap<Role, String> = [
            (Role::Lidar, self.lidar),
            (Role::Odometry, self.odom),
            (Role::Commands, self.cmd),
            (Role::Sonar, self.sonar),
            (Role::Truth, self.truth),
        ]
        .into_iter()
        .filter_map(|(role, topic)| Some((role, topic?.to_string())))
        .collect();
        Ok(ImportOptions {
            topics,
            meta: None,
            wheel_radius_m: self.wheel_radius_m,
            wheel_joints,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wheel_joints_are_two_different_names() {
        let flags = |j| ImportFlags {
            wheel_joints: Some(j),
            ..ImportFlags::default()
        };
        let joints = flags("l,r").options().unwrap().wheel_joints;
        assert_eq!(joints, Some(["l".to_string(), "r".to_string()]));
        for bad in ["l", "l,l", ",r", "l,r,x"] {
            assert!(flags(bad).options().is_err(), "{bad}");
        }
    }

    #[test]
    fn wheel_radius_is_checked_and_topics_named() {
        let flags = ImportFlags {
            wheel_radius_m: Some(0.0),
            ..ImportFlags::default()
        };
        assert!(flags.options().is_err());
        let flags = ImportFlags {
            lidar: Some("/scan"),
            wheel_radius_m: Some(0.05),
            ..ImportFlags::default()
        };
        assert_eq!(flags.first_given(), Some("--lidar"));
        let options = flags.options().unwrap();
        assert_eq!(
            options.topics.get(&Role::Lidar).map(String::as_str),
            Some("/scan")
        );
        assert_eq!(ImportFlags::default().first_given(), None);
    }
}
