//! What a bag says of the sensors' mounts, for `meta.toml` when the user gave none: the lidar's
//! from TF (the scans' frame in the robot's, projected onto the ground), the sonar's
//! half-angle from its `Range` messages' field of view.

use std::collections::BTreeMap;

use hilsim_recording::{decimal_of_f32, printable, Meta, Mount, SonarMount};

use super::Converter;
use crate::tf::{self, Rigid};
use crate::topics::{Chosen, Role};

/// The robot's frame when no odometry names it: REP 105's `base_link`, else `base_footprint`.
const BASE_FRAMES: [&str; 2] = ["base_link", "base_footprint"];

/// A value to the nanounit (nanometres, nanodegrees), without a negative zero: what TF's
/// float64 composition gives, without its last-digit noise (`0.12`, not
/// `0.12000000000000001`).
fn to_nano(x: f64) -> f64 {
    (x * 1e9).round() / 1e9 + 0.0
}

/// The lidar's mount from the bag's TF: the scans' frame in the robot's, projected onto the
/// ground (x, y, yaw); the robot's centre facing forward when TF does not say. Each way it was
/// found, or not, is a note.
fn lidar_mount(
    converter: &Converter,
    tf_topics: &BTreeMap<String, tf::Source>,
    notes: &mut Vec<String>,
) -> Mount {
    let tree = &converter.tree;
    let assumed = "lidar mount assumed at the robot's centre, facing forward; give it with \
                   --meta FILE";
    let Some(sensor) = converter.scan_frame.as_deref() else {
        return Mount::default();
    };
    if tree.is_empty() {
        let why = if tf_topics.is_empty() {
            "no /tf_static or /tf"
        } else {
            "no usable transform in /tf_static or /tf"
        };
        notes.push(format!("{why}: {assumed}"));
        return Mount::default();
    }
    let (base, guessed) = match converter.odometry_frame.as_deref() {
        Some(base) => (base, false),
        None => match BASE_FRAMES.iter().find(|b| tree.has(b)) {
            Some(base) => (*base, true),
            None => {
                notes.push(format!(
                    "no robot frame in TF (base_link, base_footprint, or the odometry's child \
                     frame): {assumed}"
                ));
                return Mount::default();
            }
        },
    };
    let Some(found) = tree.mount(base, sensor) else {
        notes.push(format!(
            "TF has no chain of transforms from {} to the scans' frame {}: {assumed}",
            printable(base),
            printable(sensor)
        ));
        return Mount::default();
    };
    let Rigid {
        translation,
        rotation,
    } = found.rigid;
    let mount = Mount {
        x_m: to_nano(translation.x),
        y_m: to_nano(translation.y),
        yaw_deg: to_nano(rotation.yaw().to_degrees()),
    };
    let source = if found.all_static {
        "/tf_static"
    } else if tf_topics.values().any(|s| *s == tf::Source::Static) {
        "/tf_static and /tf"
    } else {
        "/tf (no /tf_static)"
    };
    notes.push(format!(
        "lidar mount from {source} {}→{}: x {} m, y {} m, yaw {}°{}",
        printable(base),
        printable(sensor),
        mount.x_m,
        mount.y_m,
        mount.yaw_deg,
        if guessed {
            format!(" (the robot's frame taken to be {base}: no odometry names it)")
        } else {
            String::new()
        }
    ));
    let tilt = found.rigid.tilt_deg();
    // A degree of tilt moves a 2-D scan's points by under 0.02 % of their range.
    if tilt > 1.0 {
        notes.push(format!(
            "the lidar's frame is tilted {tilt:.1}° from the robot's: its roll and pitch are \
             dropped (a 2-D mount has neither){}",
            if tilt > 90.0 {
                "; upside down, its scans turn the other way round, which the mount cannot say"
            } else {
                ""
            }
        ));
    }
    mount
}

/// A sonar's half-angle, degrees, of a `sensor_msgs/Range` `field_of_view` (radians): `None`
/// unless it is a number and the half-angle within [0°, 90°), as `meta.toml` requires.
pub(super) fn sonar_half_angle_deg(field_of_view_rad: f64) -> Option<f64> {
    let half_angle_deg = (0.5 * field_of_view_rad).to_degrees();
    (0.0..90.0)
        .contains(&half_angle_deg)
        .then_some(half_angle_deg)
}

/// Fills in what `meta` lacks of the chosen sensors' mounts from what the bag says: the
/// lidar's from TF, the sonar's half-angle from its field of view. Each is a note.
pub(super) fn fill_in(
    meta: &mut Meta,
    chosen: &Chosen,
    converter: &Converter,
    tf_topics: &BTreeMap<String, tf::Source>,
    notes: &mut Vec<String>,
) {
    if chosen.contains_key(&Role::Lidar) && meta.lidar.is_none() {
        meta.lidar = Some(lidar_mount(converter, tf_topics, notes));
    }
    if !chosen.contains_key(&Role::Sonar) || meta.sonar.is_some() {
        return;
    }
    let sonar_topic = chosen.get(&Role::Sonar).map_or("", |(t, _)| t.as_str());
    match converter.sonar_fov_rad.and_then(sonar_half_angle_deg) {
        Some(half_angle_deg) => {
            meta.sonar = Some(SonarMount {
                x_m: 0.0,
                y_m: 0.0,
                yaw_deg: 0.0,
                half_angle_deg: decimal_of_f32(half_angle_deg as f32),
            });
            if converter.sonar_fov_unusable > 0 {
                notes.push(format!(
                    "sonar half-angle from {}'s first usable field_of_view; {} before it \
                     not a number or not within 0..π radians",
                    printable(sonar_topic),
                    converter.sonar_fov_unusable
                ));
            }
        }
        None => notes.push(format!(
            "no [sonar] in meta.toml: no message of {} has a field_of_view within 0..π \
             radians to take the half-angle from; give it with --meta FILE",
            printable(sonar_topic)
        )),
    }
}
