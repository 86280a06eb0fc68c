//! The file's messages in order: the start's metadata, the fixed frames (`/tf_static`), the
//! world, then each row of the tables merged by time as its messages. Each kind of row has its
//! own writer here; the messages themselves are made in `messages.rs`.

use std::collections::BTreeMap;
use std::io::Write;

use hilsim_recording::{
    CommandSample, LidarSample, Meta, OdometrySample, SonarSample, Tables, TruthSample,
};
use mcap::records::Metadata;

use super::extent::Extent;
use super::mcap_file::Bag;
use super::merge::{Merge, Next};
use super::messages::{header, laser_scan, laser_scan_ranges, markers, pose, transform, twist};
use super::odometry::{Odometer, OdometryPath};
use super::options::{stamp_ns, ExportOptions, START_NS};
use super::source::Source;
use crate::import::{ODOMETRY_START_KEYS, START_KEY, START_METADATA};
use crate::msgs::{Odometry, PoseStamped, Range, TfMessage, TwistStamped};
use crate::Error;

pub(super) fn write_all<W: Write>(
    bag: &mut Bag<'_, W>,
    source: Source<'_>,
    extent: &Extent,
    options: &ExportOptions<'_>,
) -> Result<(), Error> {
    write_start(bag, extent)?;
    write_fixed_frames(bag, source.meta, source.tables, extent)?;
    if let Some(world) = options.world {
        bag.write(
            "/world",
            "visualization_msgs/msg/MarkerArray",
            START_NS,
            &markers(world),
        )?;
    }
    let mut rows = RowWriter::new(source.meta, extent, options, source.odometry_again)?;
    let mut merge = Merge::new(
        source.lidar,
        source.commands,
        source.odometry,
        source.sonar,
        source.truth,
    )?;
    while let Some((t_s, next)) = merge.next()? {
        let t_ns = stamp_ns(t_s);
        match next {
            Next::Scan => rows.scan(bag, t_ns, merge.revolution())?,
            Next::Command(c) => rows.command(bag, t_ns, &c)?,
            Next::Odometry(o) => rows.odometry(bag, t_ns, &o)?,
            Next::Sonar(s) => rows.sonar(bag, t_ns, &s)?,
            Next::Truth(p) => rows.truth(bag, t_ns, &p)?,
        }
    }
    Ok(())
}

/// The metadata record the file starts with: the recording's t = 0, and the wheel travel at
/// the first odometry row (which an `Odometry` pose cannot carry).
fn write_start<W: Write>(bag: &mut Bag<'_, W>, extent: &Extent) -> Result<(), Error> {
    let mut metadata = BTreeMap::from([(START_KEY.to_string(), START_NS.to_string())]);
    if let Some(first) = extent.first_odometry {
        for (key, value) in ODOMETRY_START_KEYS
            .iter()
            .zip([first.left_m, first.right_m])
        {
            metadata.insert((*key).to_string(), value.to_string());
        }
    }
    bag.writer
        .write_metadata(&Metadata {
            name: START_METADATA.to_string(),
            metadata,
        })
        .map_err(|err| bag.fail(err))
}

/// The frames as REP 105 chains them, one tree that a viewer shows in `map`: map → odom
/// (where the odometry started, from the truth) → base_link (the odometry) → laser, sonar
/// (the mounts). Without odometry the truth places base_link in map; without truth, odom is
/// put at map's origin; with neither, base_link is. This writes the fixed ones.
fn write_fixed_frames<W: Write>(
    bag: &mut Bag<'_, W>,
    meta: &Meta,
    tables: Tables,
    extent: &Extent,
) -> Result<(), Error> {
    let mut fixed = Vec::new();
    match (!extent.truth, extent.first_odometry.is_none()) {
        (true, false) => fixed.push(transform(START_NS, "map", "odom", 0.0, 0.0, 0.0)),
        (true, true) => fixed.push(transform(START_NS, "map", "base_link", 0.0, 0.0, 0.0)),
        (false, _) => {}
    }
    if tables.lidar {
        let lidar = meta.lidar.unwrap_or_default();
        let (x, y, yaw) = (lidar.x_m, lidar.y_m, lidar.yaw_rad());
        fixed.push(transform(START_NS, "base_link", "laser", x, y, yaw));
    }
    if tables.sonar {
        // A sonar without a mount in meta.toml is at the robot's centre, facing forward.
        let (x, y, yaw_deg) = meta
            .sonar
            .as_ref()
            .map_or((0.0, 0.0, 0.0), |s| (s.x_m, s.y_m, s.yaw_deg));
        let yaw = yaw_deg.to_radians();
        fixed.push(transform(START_NS, "base_link", "sonar", x, y, yaw));
    }
    if fixed.is_empty() {
        return Ok(());
    }
    let message = TfMessage { transforms: fixed };
    bag.write("/tf_static", "tf2_msgs/msg/TFMessage", START_NS, &message)
}

/// What the rows' messages need besides the row: the whole tables' extent, the sonar's field of
/// view, the calibrated ranges, and the odometry's poses.
struct RowWriter<'a, 'o> {
    wheel_base: f64,
    range_max: f32,
    sonar_max: f32,
    sonar_fov: f32,
    calibrated: Option<&'o dyn Fn(&LidarSample) -> f64>,
    odometer: Odometer,
    odometry_path: OdometryPath<'a>,
}

impl<'a, 'o> RowWriter<'a, 'o> {
    fn new(
        meta: &Meta,
        extent: &Extent,
        options: &ExportOptions<'o>,
        odometry: super::source::Stream<'a, OdometrySample>,
    ) -> Result<Self, Error> {
        let wheel_base = meta.robot.wheel_base_m;
        let sonar_fov = meta
            .sonar
            .as_ref()
            .map_or(0.0, |s| (2.0 * s.half_angle_deg).to_radians() as f32);
        Ok(Self {
            wheel_base,
            range_max: extent.range_max,
            sonar_max: extent.sonar_max,
            sonar_fov,
            calibrated: options.calibrated,
            odometer: Odometer::default(),
            odometry_path: OdometryPath::new(odometry, wheel_base)?,
        })
    }

    /// A revolution as `/scan`, and as `/scan_calibrated` with its calibrated ranges.
    fn scan<W: Write>(
        &self,
        bag: &mut Bag<'_, W>,
        t_ns: i64,
        rev: &[LidarSample],
    ) -> Result<(), Error> {
        let mut scan = laser_scan(rev, self.range_max);
        bag.write("/scan", "sensor_msgs/msg/LaserScan", t_ns, &scan)?;
        if let Some(calibrated) = self.calibrated {
            // The same revolution, each reading replaced by its calibrated range.
            let reported = laser_scan_ranges(rev, |i| {
                let d = calibrated(&rev[i]);
                if d.is_finite() {
                    d as f32
                } else {
                    f32::NAN
                }
            });
            scan.ranges = reported;
            scan.range_max = f32::MAX;
            bag.write("/scan_calibrated", "sensor_msgs/msg/LaserScan", t_ns, &scan)?;
        }
        Ok(())
    }

    /// A command's wheel speeds as the body's twist.
    fn command<W: Write>(
        &self,
        bag: &mut Bag<'_, W>,
        t_ns: i64,
        c: &CommandSample,
    ) -> Result<(), Error> {
        let twist = TwistStamped {
            header: header(t_ns, "base_link"),
            twist: twist(
                0.5 * (c.left_mps + c.right_mps),
                (c.right_mps - c.left_mps) / self.wheel_base,
            ),
        };
        bag.write("/cmd_vel", "geometry_msgs/msg/TwistStamped", t_ns, &twist)
    }

    /// The wheel travel dead-reckoned as `/odom`, and its odom → base_link transform.
    fn odometry<W: Write>(
        &mut self,
        bag: &mut Bag<'_, W>,
        t_ns: i64,
        o: &OdometrySample,
    ) -> Result<(), Error> {
        let (pose, velocity) = self
            .odometer
            .step(o.t_s, o.left_m, o.right_m, self.wheel_base);
        let mut message = Odometry {
            header: header(t_ns, "odom"),
            child_frame_id: "base_link".into(),
            ..Odometry::default()
        };
        message.pose.pose = pose;
        message.twist.twist = velocity;
        bag.write("/odom", "nav_msgs/msg/Odometry", t_ns, &message)?;
        let (x, y, yaw) = (pose.position.x, pose.position.y, pose.orientation.yaw());
        let tf = transform(t_ns, "odom", "base_link", x, y, yaw);
        let transforms = vec![tf];
        bag.write(
            "/tf",
            "tf2_msgs/msg/TFMessage",
            t_ns,
            &TfMessage { transforms },
        )
    }

    fn sonar<W: Write>(
        &self,
        bag: &mut Bag<'_, W>,
        t_ns: i64,
        s: &SonarSample,
    ) -> Result<(), Error> {
        let range = Range {
            header: header(t_ns, "sonar"),
            radiation_type: 0,
            field_of_view: self.sonar_fov,
            min_range: 0.0,
            max_range: self.sonar_max,
            range: s.range_m as f32,
        };
        bag.write("/sonar", "sensor_msgs/msg/Range", t_ns, &range)
    }

    /// The true pose, and the transform that puts base_link in map where it says.
    fn truth<W: Write>(
        &mut self,
        bag: &mut Bag<'_, W>,
        t_ns: i64,
        p: &TruthSample,
    ) -> Result<(), Error> {
        let pose = PoseStamped {
            header: header(t_ns, "map"),
            pose: pose(p.x_m, p.y_m, p.yaw_rad),
        };
        let type_name = "geometry_msgs/msg/PoseStamped";
        bag.write("/ground_truth/pose", type_name, t_ns, &pose)?;
        // base_link is in map where the truth says: through odom when there is odometry
        // (odom's place is the truth composed with the inverse of the odometry's pose at that
        // time, as tf2 interpolates it).
        let tf = match self.odometry_path.at(p.t_s)? {
            Some(odom_pose) => {
                // odom's origin in base_link, then in map through the truth.
                let origin = hilsim_recording::Pose::default().relative_to(&odom_pose);
                let odom = hilsim_recording::Pose::new(p.x_m, p.y_m, p.yaw_rad)
                    .compose(origin.x, origin.y, origin.yaw);
                transform(t_ns, "map", "odom", odom.x, odom.y, odom.yaw)
            }
            None => transform(t_ns, "map", "base_link", p.x_m, p.y_m, p.yaw_rad),
        };
        let transforms = vec![tf];
        bag.write(
            "/tf",
            "tf2_msgs/msg/TFMessage",
            t_ns,
            &TfMessage { transforms },
        )
    }
}
