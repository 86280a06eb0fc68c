//! The ROS 2 messages hilsim reads and writes, field for field in the order of their `.msg`
//! definitions (CDR has no field names: the order is the format). A message must end where its
//! fields do; the one field a newer distribution appends to a type read here
//! (`sensor_msgs/Range`'s `variance`) is allowed for, and ignored.

use serde::de::{self, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// `builtin_interfaces/Time` (also `Duration`, which has the same fields).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, 0..1e9.
    pub nanosec: u32,
}

impl Time {
    /// The time `ns` nanoseconds after the epoch (saturating at the type's range).
    #[must_use]
    pub fn from_ns(ns: i64) -> Self {
        let sec = ns.div_euclid(1_000_000_000);
        let nanosec = ns.rem_euclid(1_000_000_000);
        Self {
            sec: i32::try_from(sec).unwrap_or(if sec < 0 { i32::MIN } else { i32::MAX }),
            nanosec: u32::try_from(nanosec).unwrap_or(0),
        }
    }

    /// Nanoseconds since the epoch.
    #[must_use]
    pub fn ns(self) -> i64 {
        i64::from(self.sec) * 1_000_000_000 + i64::from(self.nanosec)
    }

    /// Whether this is the zero time, which drivers that set no stamp leave.
    #[must_use]
    pub fn is_zero(self) -> bool {
        self.sec == 0 && self.nanosec == 0
    }
}

/// `std_msgs/Header`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Header {
    /// When the data was taken.
    pub stamp: Time,
    /// The coordinate frame of the data.
    pub frame_id: String,
}

/// `sensor_msgs/LaserScan`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct LaserScan {
    /// Stamp: the first reading's time.
    pub header: Header,
    /// The first reading's angle, radians.
    pub angle_min: f32,
    /// The last reading's angle, radians.
    pub angle_max: f32,
    /// Between readings, radians.
    pub angle_increment: f32,
    /// Between readings, seconds.
    pub time_increment: f32,
    /// Between scans, seconds.
    pub scan_time: f32,
    /// Shortest valid range, metres.
    pub range_min: f32,
    /// Longest valid range, metres.
    pub range_max: f32,
    /// Metres; out of `range_min..=range_max` (or NaN, ±inf) is no reading.
    pub ranges: Vec<f32>,
    /// Device-specific strengths; empty when the device reports none.
    pub intensities: Vec<f32>,
}

/// `sensor_msgs/Range`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Range {
    /// Stamp: when the echo came back.
    pub header: Header,
    /// `ULTRASOUND` (0) or `INFRARED` (1).
    pub radiation_type: u8,
    /// The full cone, radians.
    pub field_of_view: f32,
    /// Shortest valid range, metres.
    pub min_range: f32,
    /// Longest valid range, metres.
    pub max_range: f32,
    /// Metres.
    pub range: f32,
}

/// `geometry_msgs/Vector3` and `geometry_msgs/Point` (the same fields).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/Quaternion`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Self::from_yaw(0.0)
    }
}

impl Quaternion {
    /// A rotation by `yaw` radians about z.
    #[must_use]
    pub fn from_yaw(yaw: f64) -> Self {
        let (s, c) = (0.5 * yaw).sin_cos();
        Self {
            x: 0.0,
            y: 0.0,
            z: s,
            w: c,
        }
    }

    /// The rotation's yaw about z, radians in (-π, π] (the z-y-x Euler angle; roll and pitch,
    /// which a ground robot has none of, are dropped).
    #[must_use]
    pub fn yaw(&self) -> f64 {
        let siny = 2.0 * (self.w * self.z + self.x * self.y);
        let cosy = 1.0 - 2.0 * (self.y * self.y + self.z * self.z);
        siny.atan2(cosy)
    }
}

/// `geometry_msgs/Pose`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose {
    /// `geometry_msgs/Point`.
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/Twist`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Twist {
    /// m/s.
    pub linear: Vector3,
    /// rad/s.
    pub angular: Vector3,
}

/// A `float64[36]` covariance (serde derives arrays to 32 only).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Covariance(pub [f64; 36]);

impl Default for Covariance {
    fn default() -> Self {
        Self([0.0; 36])
    }
}

impl Serialize for Covariance {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut tuple = serializer.serialize_tuple(36)?;
        for x in &self.0 {
            tuple.serialize_element(x)?;
        }
        tuple.end()
    }
}

impl<'de> Deserialize<'de> for Covariance {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Elements;
        impl<'de> Visitor<'de> for Elements {
            type Value = Covariance;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("36 float64")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Covariance, A::Error> {
                let mut out = [0.0; 36];
                for (i, x) in out.iter_mut().enumerate() {
                    *x = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                Ok(Covariance(out))
            }
        }
        deserializer.deserialize_tuple(36, Elements)
    }
}

/// `geometry_msgs/PoseWithCovariance`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Row-major 6×6 (x, y, z, roll, pitch, yaw).
    pub covariance: Covariance,
}

/// `geometry_msgs/TwistWithCovariance`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct TwistWithCovariance {
    /// The twist.
    pub twist: Twist,
    /// Row-major 6×6.
    pub covariance: Covariance,
}

/// `nav_msgs/Odometry`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Odometry {
    /// Stamp, and the pose's frame (`odom`).
    pub header: Header,
    /// The twist's frame (`base_link`).
    pub child_frame_id: String,
    /// The robot's pose in `header.frame_id`.
    pub pose: PoseWithCovariance,
    /// The robot's velocity in `child_frame_id`.
    pub twist: TwistWithCovariance,
}

/// `geometry_msgs/TwistStamped`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TwistStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The velocity.
    pub twist: Twist,
}

/// `geometry_msgs/PoseStamped`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PoseStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The pose.
    pub pose: Pose,
}

/// `sensor_msgs/JointState`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointState {
    /// Stamp.
    pub header: Header,
    /// Joint names.
    pub name: Vec<String>,
    /// Radians (revolute joints).
    pub position: Vec<f64>,
    /// rad/s.
    pub velocity: Vec<f64>,
    /// N·m.
    pub effort: Vec<f64>,
}

/// `geometry_msgs/Transform`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Transform {
    /// Translation.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/TransformStamped`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TransformStamped {
    /// Stamp and parent frame.
    pub header: Header,
    /// Child frame.
    pub child_frame_id: String,
    /// Child in parent.
    pub transform: Transform,
}

/// `tf2_msgs/TFMessage`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

/// `std_msgs/ColorRGBA`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ColorRgba {
    /// Red, 0..1.
    pub r: f32,
    /// Green, 0..1.
    pub g: f32,
    /// Blue, 0..1.
    pub b: f32,
    /// Opacity, 0..1.
    pub a: f32,
}

/// `sensor_msgs/CompressedImage` (a marker's texture; hilsim sends none).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CompressedImage {
    /// Stamp and frame.
    pub header: Header,
    /// `jpeg`, `png`.
    pub format: String,
    /// The image.
    pub data: Vec<u8>,
}

/// `visualization_msgs/UVCoordinate`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct UvCoordinate {
    /// u.
    pub u: f32,
    /// v.
    pub v: f32,
}

/// `visualization_msgs/MeshFile`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MeshFile {
    /// Name.
    pub filename: String,
    /// Contents.
    pub data: Vec<u8>,
}

/// `visualization_msgs/Marker` (Humble and later).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[allow(missing_docs)]
pub struct Marker {
    pub header: Header,
    pub ns: String,
    pub id: i32,
    /// `CUBE` 1, `CYLINDER` 3, `LINE_LIST` 5, …
    #[serde(rename = "type")]
    pub kind: i32,
    /// `ADD` 0.
    pub action: i32,
    pub pose: Pose,
    pub scale: Vector3,
    pub color: ColorRgba,
    /// 0: forever.
    pub lifetime: Time,
    pub frame_locked: bool,
    pub points: Vec<Vector3>,
    pub colors: Vec<ColorRgba>,
    pub texture_resource: String,
    pub texture: CompressedImage,
    pub uv_coordinates: Vec<UvCoordinate>,
    pub text: String,
    pub mesh_resource: String,
    pub mesh_file: MeshFile,
    pub mesh_use_embedded_materials: bool,
}

impl Marker {
    /// `type` of a cube.
    pub const CUBE: i32 = 1;
    /// `type` of an upright cylinder.
    pub const CYLINDER: i32 = 3;
}

/// `visualization_msgs/MarkerArray`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MarkerArray {
    /// The markers.
    pub markers: Vec<Marker>,
}
