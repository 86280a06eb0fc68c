//! Messages into samples: the [`Converter`] each message of a chosen topic goes through, its
//! state (clocks, counts, the TF tree, what was skipped), and the conversions of the
//! messages that become one row each (Range, Twist and TwistStamped, PoseStamped and
//! Odometry as truth). A scan's readings are in `scan.rs`, wheel travel in `odometry.rs`.

use std::collections::BTreeMap;

use hilsim_recording::{decimal_of_f32, CommandSample, SampleSink, SonarSample, TruthSample};

use super::clocks::TableClock;
use super::mounts::sonar_half_angle_deg;
use super::odometry::OdometryState;
use super::scan::ScanAngles;
use super::wire::{decode_as, Encoding, Wire};
use crate::msgs::{
    JointState, LaserScan, Odometry, Pose, PoseStamped, Range, TfMessage, Twist, TwistStamped,
};
use crate::tf;
use crate::topics::{self, Chosen, Kind, Role};
use crate::Error;

/// The frame odometry is in (REP 105); a namespaced one (`robot1/odom`) counts too.
pub(super) const ODOM_FRAME: &str = "odom";

/// Unstamped commands held until the first stamped message says which clock they are on.
const MAX_PENDING_COMMANDS: usize = 1 << 20;

/// Why a message could not be converted.
pub enum Fault {
    /// The message is bad (what is wrong).
    Message(String),
    /// The recording could not take the sample.
    Sink(hilsim_recording::Error),
}

impl From<hilsim_recording::Error> for Fault {
    fn from(err: hilsim_recording::Error) -> Self {
        Self::Sink(err)
    }
}

/// Messages into samples: times, revolutions, wheel travel and the order of each table.
pub struct Converter {
    pub(super) chosen: Chosen,
    pub(super) wheel_base_m: f64,
    pub(super) wheel_radius_m: Option<f64>,
    pub(super) wheel_joints: Option<[String; 2]>,
    /// Messages skipped for a value that is not finite, by table.
    pub(super) not_finite: BTreeMap<Role, u64>,
    /// `JointState` messages without the wheels' positions.
    pub(super) joints_missing: u64,
    /// The joints of the first such message, for the error when no message has the wheels.
    pub(super) joints_seen: Vec<String>,
    /// The recording's t = 0 on the stamps' clock, ns.
    pub(super) t0_ns: Option<i64>,
    /// Stamp clock minus log clock, once a stamped message has said.
    pub(super) clock_offset_ns: Option<i64>,
    pub(super) pending_commands: Vec<(i64, Twist)>,
    /// Each table's time order.
    pub(super) clocks: BTreeMap<Role, TableClock>,
    pub(super) rows: BTreeMap<Role, u64>,
    pub(super) rev: u64,
    pub(super) odometry: Option<OdometryState>,
    /// The wheel travel at the first odometry message.
    pub(super) odometry_start_m: (f64, f64),
    pub(super) sonar_out_of_range: u64,
    /// The first usable `field_of_view`, and the count of unusable ones before it.
    pub(super) sonar_fov_rad: Option<f64>,
    pub(super) sonar_fov_unusable: u64,
    /// The last scan's reading angles: a lidar's scans share them.
    pub(super) scan_angles: ScanAngles,
    /// How the messages' bytes are laid out.
    pub(super) encoding: Encoding,
    /// The TF topics, and whether each is static.
    pub(super) tf_topics: BTreeMap<String, tf::Source>,
    /// The bag's TF frames.
    pub(super) tree: tf::Tree,
    /// TF messages that did not decode.
    pub(super) tf_undecoded: u64,
    /// The first scan's frame.
    pub(super) scan_frame: Option<String>,
    /// The robot's frame as the odometry names it (an `Odometry`'s child frame, or the child
    /// of TF's odom → base transforms).
    pub(super) odometry_frame: Option<String>,
}

impl Converter {
    /// A converter of the `chosen` topics, for a robot of this wheel base (and wheel radius, for
    /// joint angles).
    #[must_use]
    pub fn new(chosen: &Chosen, wheel_base_m: f64, wheel_radius_m: Option<f64>) -> Self {
        Self {
            chosen: chosen.clone(),
            wheel_base_m,
            wheel_radius_m,
            wheel_joints: None,
            not_finite: BTreeMap::new(),
            joints_missing: 0,
            joints_seen: Vec::new(),
            t0_ns: None,
            clock_offset_ns: None,
            pending_commands: Vec::new(),
            clocks: BTreeMap::new(),
            rows: BTreeMap::new(),
            rev: 0,
            odometry: None,
            odometry_start_m: (0.0, 0.0),
            sonar_out_of_range: 0,
            sonar_fov_rad: None,
            sonar_fov_unusable: 0,
            scan_angles: ScanAngles::default(),
            encoding: Encoding::Cdr,
            tf_topics: BTreeMap::new(),
            tree: tf::Tree::default(),
            tf_undecoded: 0,
            scan_frame: None,
            odometry_frame: None,
        }
    }

    /// Messages laid out as `encoding` (default: ROS 2's CDR).
    #[must_use]
    pub fn with_encoding(mut self, encoding: Encoding) -> Self {
        self.encoding = encoding;
        self
    }

    /// The topics of `tf2_msgs/TFMessage`, each static (`/tf_static`) or not, whose messages
    /// [`Converter::tf`] takes.
    #[must_use]
    pub fn with_tf_topics(mut self, topics: BTreeMap<String, tf::Source>) -> Self {
        self.tf_topics = topics;
        self
    }

    /// Keeps a TF message's transforms (one that does not decode is counted).
    pub fn tf(&mut self, source: tf::Source, data: &[u8]) {
        match decode_as::<TfMessage>(self.encoding, data, 0) {
            Ok(message) => {
                for t in &message.transforms {
                    self.tree.add(source, t);
                }
            }
            Err(_) => self.tf_undecoded += 1,
        }
    }

    pub(super) fn decode<T: Wire>(&self, data: &[u8], appended: usize) -> Result<T, String> {
        decode_as(self.encoding, data, appended)
    }

    /// The left and right wheels' joints by name (else the joints named `…left…` and
    /// `…right…`).
    #[must_use]
    pub fn with_wheel_joints(mut self, names: Option<[String; 2]>) -> Self {
        self.wheel_joints = names;
        self
    }

    /// Counts a message skipped for a NaN or infinite value (a driver's "unknown").
    pub(super) fn not_finite(&mut self, role: Role) {
        *self.not_finite.entry(role).or_insert(0) += 1;
    }

    pub(super) fn count(&mut self, role: Role, n: u64) {
        *self.rows.entry(role).or_insert(0) += n;
    }

    /// Converts one message of `role`'s topic into samples for `sink`.
    ///
    /// # Errors
    /// The message does not decode as `kind`, or `sink` fails.
    pub fn message<S>(
        &mut self,
        role: Role,
        kind: Kind,
        log_ns: i64,
        data: &[u8],
        sink: &mut S,
    ) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        self.convert(role, kind, log_ns, data, sink)?;
        // Commands held for want of a clock go out as soon as a stamped message gives it,
        // before any later command.
        if let Some(offset) = self.clock_offset_ns {
            for (log_ns, twist) in std::mem::take(&mut self.pending_commands) {
                self.command(log_ns + offset, &twist, sink)?;
            }
        }
        Ok(())
    }

    fn convert<S>(
        &mut self,
        role: Role,
        kind: Kind,
        log_ns: i64,
        data: &[u8],
        sink: &mut S,
    ) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let bad = |err: String| Fault::Message(format!("not a {} ({err})", kind.ros_name()));
        match (role, kind) {
            (Role::Lidar, _) => {
                let scan: LaserScan = self.decode(data, 0).map_err(bad)?;
                if self.scan_frame.is_none() {
                    self.scan_frame = Some(tf::frame(&scan.header.frame_id).to_string());
                }
                self.scan(&scan, log_ns, sink)
            }
            (Role::Sonar, _) => {
                // Rolling appends `variance` (a float32) to Range.
                let range: Range = self.decode(data, 4).map_err(bad)?;
                let ns = self.stamped(range.header.stamp, log_ns);
                if self.sonar_fov_rad.is_none() {
                    let fov = f64::from(range.field_of_view);
                    if sonar_half_angle_deg(fov).is_some() {
                        self.sonar_fov_rad = Some(fov);
                    } else {
                        self.sonar_fov_unusable += 1;
                    }
                }
                let valid = range.range.is_finite()
                    && range.range > 0.0
                    && range.range >= range.min_range
                    && range.range <= range.max_range;
                if !valid {
                    self.sonar_out_of_range += 1;
                    return Ok(());
                }
                let t_s = self.seconds(role, ns, 0.0);
                self.count(role, 1);
                Ok(sink.sonar(&SonarSample {
                    t_s,
                    range_m: decimal_of_f32(range.range),
                    true_range_m: None,
                })?)
            }
            (Role::Commands, Kind::TwistStamped) => {
                let twist: TwistStamped = self.decode(data, 0).map_err(bad)?;
                let ns = self.stamped(twist.header.stamp, log_ns);
                self.command(ns, &twist.twist, sink)
            }
            (Role::Commands, _) => {
                let twist: Twist = self.decode(data, 0).map_err(bad)?;
                match self.clock_offset_ns {
                    Some(offset) => self.command(log_ns + offset, &twist, sink),
                    None if self.pending_commands.len() < MAX_PENDING_COMMANDS => {
                        self.pending_commands.push((log_ns, twist));
                        Ok(())
                    }
                    None => Err(Fault::Message(format!(
                        "{MAX_PENDING_COMMANDS} commands (unstamped Twist) before any stamped \
                         message: no clock to put them on; record them as TwistStamped"
                    ))),
                }
            }
            (Role::Truth, Kind::Odometry) => {
                let odometry: Odometry = self.decode(data, 0).map_err(bad)?;
                let ns = self.stamped(odometry.header.stamp, log_ns);
                self.truth(ns, &odometry.pose.pose, sink)
            }
            (Role::Truth, _) => {
                let pose: PoseStamped = self.decode(data, 0).map_err(bad)?;
                let ns = self.stamped(pose.header.stamp, log_ns);
                self.truth(ns, &pose.pose, sink)
            }
            (Role::Odometry, Kind::JointState) => {
                let joints: JointState = self.decode(data, 0).map_err(bad)?;
                let ns = self.stamped(joints.header.stamp, log_ns);
                self.joints(ns, &joints, sink)
            }
            (Role::Odometry, Kind::Tf) => {
                let message: TfMessage = self.decode(data, 0).map_err(bad)?;
                for t in &message.transforms {
                    self.tree.add(tf::Source::Dynamic, t);
                    let (parent, child) =
                        (tf::frame(&t.header.frame_id), tf::frame(&t.child_frame_id));
                    if parent.rsplit('/').next() != Some(ODOM_FRAME) {
                        continue;
                    }
                    // The first child of odom is the robot (odom → base_footprint when a
                    // robot has both: base_link is then below base_footprint).
                    let base = self.odometry_frame.get_or_insert_with(|| child.to_string());
                    if base != child {
                        continue;
                    }
                    let ns = self.stamped(t.header.stamp, log_ns);
                    let pose = Pose {
                        position: t.transform.translation,
                        orientation: t.transform.rotation,
                    };
                    self.odometry(ns, &pose, sink)?;
                }
                Ok(())
            }
            (Role::Odometry, _) => {
                let odometry: Odometry = self.decode(data, 0).map_err(bad)?;
                if self.odometry_frame.is_none() && !odometry.child_frame_id.is_empty() {
                    self.odometry_frame = Some(tf::frame(&odometry.child_frame_id).to_string());
                }
                let ns = self.stamped(odometry.header.stamp, log_ns);
                self.odometry(ns, &odometry.pose.pose, sink)
            }
        }
    }

    /// A velocity command as the wheel speeds of a differential drive.
    pub(super) fn command<S>(&mut self, ns: i64, twist: &Twist, sink: &mut S) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let (v, w) = (twist.linear.x, twist.angular.z);
        let half = 0.5 * self.wheel_base_m * w;
        // Speeds near f64's limit can sum beyond it.
        if ![v, w, v - half, v + half].iter().all(|x| x.is_finite()) {
            self.not_finite(Role::Commands);
            return Ok(());
        }
        let t_s = self.seconds(Role::Commands, ns, 0.0);
        self.count(Role::Commands, 1);
        Ok(sink.command(&CommandSample {
            t_s,
            left_mps: v - half,
            right_mps: v + half,
        })?)
    }

    fn truth<S>(&mut self, ns: i64, pose: &crate::msgs::Pose, sink: &mut S) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let (x_m, y_m, yaw_rad) = (pose.position.x, pose.position.y, pose.orientation.yaw());
        if ![x_m, y_m, yaw_rad].iter().all(|v| v.is_finite()) {
            self.not_finite(Role::Truth);
            return Ok(());
        }
        let t_s = self.seconds(Role::Truth, ns, 0.0);
        self.count(Role::Truth, 1);
        Ok(sink.truth(&TruthSample {
            t_s,
            x_m,
            y_m,
            yaw_rad,
        })?)
    }

    /// Writes what waits for the end: commands that never met a stamped message.
    ///
    /// # Errors
    /// `sink` fails.
    pub fn finish<S>(&mut self, sink: &mut S) -> Result<(), Error>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let offset = *self.clock_offset_ns.get_or_insert(0);
        for (log_ns, twist) in std::mem::take(&mut self.pending_commands) {
            self.command(log_ns + offset, &twist, sink)
                .map_err(|err| match err {
                    Fault::Sink(err) => Error::Recording(err),
                    Fault::Message(m) => Error::Bag {
                        path: "commands".into(),
                        message: m,
                    },
                })?;
        }
        Ok(())
    }

    /// Sentences on what was repaired or skipped.
    #[must_use]
    pub fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        for (role, clock) in self.clocks.iter().filter(|(_, c)| c.reordered > 0) {
            notes.push(format!(
                "{} {role} rows came before the row written ahead of them (by up to {:.3} ms) \
                 and were put at its time",
                clock.reordered,
                clock.worst_us as f64 / 1e3
            ));
        }
        for (role, count) in &self.not_finite {
            notes.push(format!(
                "{count} {role} messages with a value that is not finite (NaN, inf) skipped"
            ));
        }
        if self.joints_missing > 0 {
            let names = match &self.odometry {
                Some(OdometryState::Joints { names, .. }) => topics::listing(names, " and "),
                _ => "the wheels".to_string(),
            };
            notes.push(format!(
                "{} JointState messages without a position for {names} skipped",
                self.joints_missing
            ));
        }
        if self.tf_undecoded > 0 {
            notes.push(format!(
                "{} TF messages skipped: not a tf2_msgs/TFMessage",
                self.tf_undecoded
            ));
        }
        if self.tree.dropped > 0 {
            notes.push(format!(
                "{} TF transforms not kept (not a rotation, a frame its own parent, or beyond \
                 {} frames)",
                self.tree.dropped,
                tf::FRAME_LIMIT
            ));
        }
        if self.sonar_out_of_range > 0 {
            notes.push(format!(
                "{} sonar readings out of their min..max range (no echo) skipped",
                self.sonar_out_of_range
            ));
        }
        notes
    }
}
