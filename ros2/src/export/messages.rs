//! The ROS messages an export writes, each made from recording rows: a revolution as a
//! LaserScan, twists, poses and transforms, and the world as markers.

use hilsim_recording::LidarSample;

use super::options::{stamp_ns, World, START_NS};
use crate::msgs::{
    ColorRgba, Header, LaserScan, Marker, MarkerArray, Pose, Quaternion, Time, Transform,
    TransformStamped, Twist, Vector3,
};

pub(super) fn header(t_ns: i64, frame: &str) -> Header {
    Header {
        stamp: Time::from_ns(t_ns),
        frame_id: frame.to_string(),
    }
}

/// A revolution's angles unwrapped into one increasing turn from the first, degrees from it,
/// and the step between neighbouring slots (the smallest between the angles).
fn slots(rev: &[LidarSample]) -> (Vec<f64>, f64) {
    let first = rev[0].angle_deg;
    let mut turns = 0.0;
    let mut previous = first;
    let unwrapped: Vec<f64> = rev
        .iter()
        .map(|s| {
            if s.angle_deg < previous {
                turns += 360.0;
            }
            previous = s.angle_deg;
            s.angle_deg + turns - first
        })
        .collect();
    let step = unwrapped
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 1e-9)
        .fold(f64::INFINITY, f64::min);
    (unwrapped, if step.is_finite() { step } else { 1.0 })
}

/// A reading's slot: a revolution of wildly uneven angles is capped at 100,000 slots.
fn slot(a: f64, step: f64) -> usize {
    ((a / step).round() as usize).min(99_999)
}

/// A LaserScan's ranges for a revolution, `range(i)` for its row i, NaN where none.
pub(super) fn laser_scan_ranges(rev: &[LidarSample], range: impl Fn(usize) -> f32) -> Vec<f32> {
    let (unwrapped, step) = slots(rev);
    let slots = unwrapped.last().map_or(1, |&a| slot(a, step) + 1);
    let mut ranges = vec![f32::NAN; slots];
    for (i, &a) in unwrapped.iter().enumerate() {
        ranges[slot(a, step)] = range(i);
    }
    ranges
}

/// One revolution as a LaserScan: readings placed at `angle_min + i·angle_increment`, the
/// increment the smallest step between the revolution's angles (a reading lost leaves a NaN);
/// invalid readings are NaN, strengths the intensities.
pub(super) fn laser_scan(rev: &[LidarSample], range_max: f32) -> LaserScan {
    let first = rev[0].angle_deg;
    let (unwrapped, step) = slots(rev);
    let slot = |a: f64| slot(a, step);
    let slots = unwrapped.last().map_or(1, |&a| slot(a) + 1);
    let mut ranges = vec![f32::NAN; slots];
    let mut intensities = vec![0.0f32; slots];
    for (s, &a) in rev.iter().zip(&unwrapped) {
        let i = slot(a);
        ranges[i] = if s.invalid {
            f32::NAN
        } else {
            s.range_m as f32
        };
        intensities[i] = f32::from(s.strength);
    }
    let last_slot = slot(*unwrapped.last().unwrap_or(&0.0));
    let time_increment = if last_slot > 0 {
        (rev[rev.len() - 1].t_s - rev[0].t_s) / last_slot as f64
    } else {
        0.0
    };
    let angle_min = first.to_radians();
    let increment = step.to_radians();
    LaserScan {
        header: header(stamp_ns(rev[0].t_s), "laser"),
        angle_min: angle_min as f32,
        angle_max: (angle_min + (slots - 1) as f64 * increment) as f32,
        angle_increment: increment as f32,
        time_increment: time_increment as f32,
        scan_time: (time_increment * 360.0 / step) as f32,
        range_min: 0.0,
        range_max,
        ranges,
        intensities,
    }
}

pub(super) fn twist(v: f64, w: f64) -> Twist {
    Twist {
        linear: Vector3 {
            x: v,
            y: 0.0,
            z: 0.0,
        },
        angular: Vector3 {
            x: 0.0,
            y: 0.0,
            z: w,
        },
    }
}

pub(super) fn pose(x: f64, y: f64, yaw: f64) -> Pose {
    Pose {
        position: Vector3 { x, y, z: 0.0 },
        orientation: Quaternion::from_yaw(yaw),
    }
}

pub(super) fn transform(
    t_ns: i64,
    parent: &str,
    child: &str,
    x: f64,
    y: f64,
    yaw: f64,
) -> TransformStamped {
    TransformStamped {
        header: header(t_ns, parent),
        child_frame_id: child.to_string(),
        transform: Transform {
            translation: Vector3 { x, y, z: 0.0 },
            rotation: Quaternion::from_yaw(yaw),
        },
    }
}

/// An opaque colour of the world's markers.
const fn opaque(r: f32, g: f32, b: f32) -> ColorRgba {
    ColorRgba { r, g, b, a: 1.0 }
}

/// The world as markers: walls and boards as thin boxes 0.3 m high, cylinders as cylinders.
pub(super) fn markers(world: &World) -> MarkerArray {
    const HEIGHT_M: f64 = 0.3;
    let wall_colour = opaque(0.6, 0.6, 0.65);
    let board_colour = opaque(0.8, 0.6, 0.35);
    let cylinder_colour = opaque(0.2, 0.5, 0.9);
    let mut markers = Vec::new();
    let mut add = |ns: &str, kind: i32, pose: Pose, scale: Vector3, color: ColorRgba| {
        markers.push(Marker {
            header: header(START_NS, "map"),
            ns: ns.to_string(),
            id: i32::try_from(markers.len()).unwrap_or(i32::MAX),
            kind,
            action: 0,
            pose,
            scale,
            color,
            ..Marker::default()
        });
    };
    for [from, to] in &world.walls {
        let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
        let centre = [0.5 * (from[0] + to[0]), 0.5 * (from[1] + to[1])];
        let mut p = pose(centre[0], centre[1], dy.atan2(dx));
        p.position.z = 0.5 * HEIGHT_M;
        let scale = Vector3 {
            x: dx.hypot(dy),
            y: 0.02,
            z: HEIGHT_M,
        };
        add("walls", Marker::CUBE, p, scale, wall_colour);
    }
    for &(centre, length, thickness, yaw) in &world.boards {
        let mut p = pose(centre[0], centre[1], yaw);
        p.position.z = 0.5 * HEIGHT_M;
        let scale = Vector3 {
            x: length,
            y: thickness,
            z: HEIGHT_M,
        };
        add("boards", Marker::CUBE, p, scale, board_colour);
    }
    for &(centre, radius) in &world.cylinders {
        let mut p = pose(centre[0], centre[1], 0.0);
        p.position.z = 0.5 * HEIGHT_M;
        let scale = Vector3 {
            x: 2.0 * radius,
            y: 2.0 * radius,
            z: HEIGHT_M,
        };
        add("cylinders", Marker::CYLINDER, p, scale, cylinder_colour);
    }
    MarkerArray { markers }
}
