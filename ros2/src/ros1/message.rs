//! ROS 1 serialisation of the messages hilsim reads, into the same types as the ROS 2 import
//! ([`crate::msgs`]): little-endian, packed (no alignment, no padding), `std_msgs/Header`
//! starting with a `uint32 seq`, a time as `uint32` seconds and `uint32` nanoseconds, a string
//! and a variable-length array as a `uint32` length and their elements (a string has no NUL),
//! a fixed-length array as its elements alone (<http://wiki.ros.org/msg>, "Serialization").

use crate::msgs::{
    Covariance, Header, JointState, LaserScan, Odometry, Pose, PoseStamped, PoseWithCovariance,
    Quaternion, Range, TfMessage, Time, Transform, TransformStamped, Twist, TwistStamped,
    TwistWithCovariance, Vector3,
};

/// The bytes of one message, read from the front.
pub(crate) struct Reader<'a> {
    data: &'a [u8],
}

impl<'a> Reader<'a> {
    pub(crate) fn new(data: &'a [u8]) -> Self {
        Self { data }
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        if n > self.data.len() {
            return Err(format!(
                "the message ends inside its {what} ({n} bytes wanted, {} left)",
                self.data.len()
            ));
        }
        let (head, rest) = self.data.split_at(n);
        self.data = rest;
        Ok(head)
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], String> {
        let bytes = self.take(N, what)?;
        let mut out = [0; N];
        out.copy_from_slice(bytes);
        Ok(out)
    }

    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.array::<1>("uint8")?[0])
    }

    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.array("uint32")?))
    }

    fn f32(&mut self) -> Result<f32, String> {
        Ok(f32::from_le_bytes(self.array("float32")?))
    }

    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.array("float64")?))
    }

    /// A length of a string or array whose elements take at least `element` bytes each: one
    /// that the bytes left cannot hold is an error before anything is allocated.
    fn length(&mut self, element: usize, what: &str) -> Result<usize, String> {
        let n = usize::try_from(self.u32()?).unwrap_or(usize::MAX);
        if n.saturating_mul(element) > self.data.len() {
            return Err(format!(
                "a {what} of {n} elements in the {} bytes left",
                self.data.len()
            ));
        }
        Ok(n)
    }

    /// A string (UTF-8 expected; a byte that is not is replaced, as names are only shown).
    fn string(&mut self) -> Result<String, String> {
        let n = self.length(1, "string")?;
        Ok(String::from_utf8_lossy(self.take(n, "string")?).into_owned())
    }

    fn vec<T>(
        &mut self,
        element: usize,
        what: &str,
        mut read: impl FnMut(&mut Self) -> Result<T, String>,
    ) -> Result<Vec<T>, String> {
        let n = self.length(element, what)?;
        (0..n).map(|_| read(self)).collect()
    }

    /// A `time`: `uint32` seconds (to 2106), kept as the ROS 2 type's `int32` (to 2038).
    fn time(&mut self) -> Result<Time, String> {
        let sec = self.u32()?;
        let nanosec = self.u32()?;
        let sec = i32::try_from(sec)
            .map_err(|_| format!("a stamp of {sec} s, after 2038 (beyond an int32 of seconds)"))?;
        Ok(Time { sec, nanosec })
    }

    /// Bytes not read.
    pub(crate) fn left(&self) -> usize {
        self.data.len()
    }
}

/// A message type in ROS 1's serialisation.
pub(crate) trait FromRos1: Sized {
    /// Reads the message's fields from the front of `r`.
    fn read(r: &mut Reader<'_>) -> Result<Self, String>;
}

/// Decodes a whole message: its fields, and nothing after them (ROS 1 has no padding; bytes
/// left over are a message of another type that happened to decode).
pub(crate) fn decode_whole<T: FromRos1>(data: &[u8]) -> Result<T, String> {
    let mut r = Reader::new(data);
    let message = T::read(&mut r)?;
    match r.left() {
        0 => Ok(message),
        left => Err(format!(
            "{left} bytes after the message's last field: the bytes are laid out as another type"
        )),
    }
}

/// Decodes the start of a message (the header every stamped message begins with).
pub(crate) fn decode_prefix<T: FromRos1>(data: &[u8]) -> Result<T, String> {
    T::read(&mut Reader::new(data))
}

impl FromRos1 for Header {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        let _seq = r.u32()?;
        Ok(Self {
            stamp: r.time()?,
            frame_id: r.string()?,
        })
    }
}

impl FromRos1 for Vector3 {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            x: r.f64()?,
            y: r.f64()?,
            z: r.f64()?,
        })
    }
}

impl FromRos1 for Quaternion {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            x: r.f64()?,
            y: r.f64()?,
            z: r.f64()?,
            w: r.f64()?,
        })
    }
}

impl FromRos1 for Pose {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            position: Vector3::read(r)?,
            orientation: Quaternion::read(r)?,
        })
    }
}

impl FromRos1 for Twist {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            linear: Vector3::read(r)?,
            angular: Vector3::read(r)?,
        })
    }
}

impl FromRos1 for Covariance {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        let mut out = [0.0; 36];
        for x in &mut out {
            *x = r.f64()?;
        }
        Ok(Self(out))
    }
}

impl FromRos1 for LaserScan {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            header: Header::read(r)?,
            angle_min: r.f32()?,
            angle_max: r.f32()?,
            angle_increment: r.f32()?,
            time_increment: r.f32()?,
            scan_time: r.f32()?,
            range_min: r.f32()?,
            range_max: r.f32()?,
            ranges: r.vec(4, "ranges", Reader::f32)?,
            intensities: r.vec(4, "intensities", Reader::f32)?,
        })
    }
}

impl FromRos1 for Range {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            header: Header::read(r)?,
            radiation_type: r.u8()?,
            field_of_view: r.f32()?,
            min_range: r.f32()?,
            max_range: r.f32()?,
            range: r.f32()?,
        })
    }
}

impl FromRos1 for Odometry {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            header: Header::read(r)?,
            child_frame_id: r.string()?,
            pose: PoseWithCovariance {
                pose: Pose::read(r)?,
                covariance: Covariance::read(r)?,
            },
            twist: TwistWithCovariance {
                twist: Twist::read(r)?,
                covariance: Covariance::read(r)?,
            },
        })
    }
}

impl FromRos1 for TwistStamped {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            header: Header::read(r)?,
            twist: Twist::read(r)?,
        })
    }
}

impl FromRos1 for PoseStamped {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            header: Header::read(r)?,
            pose: Pose::read(r)?,
        })
    }
}

impl FromRos1 for JointState {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            header: Header::read(r)?,
            name: r.vec(4, "name", Reader::string)?,
            position: r.vec(8, "position", Reader::f64)?,
            velocity: r.vec(8, "velocity", Reader::f64)?,
            effort: r.vec(8, "effort", Reader::f64)?,
        })
    }
}

impl FromRos1 for TransformStamped {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        Ok(Self {
            header: Header::read(r)?,
            child_frame_id: r.string()?,
            transform: Transform {
                translation: Vector3::read(r)?,
                rotation: Quaternion::read(r)?,
            },
        })
    }
}

/// `tf2_msgs/TFMessage`, and the older `tf/tfMessage` of the same layout.
impl FromRos1 for TfMessage {
    fn read(r: &mut Reader<'_>) -> Result<Self, String> {
        // A TransformStamped is at least 4 + 8 + 4 + 4 + 56 bytes.
        Ok(Self {
            transforms: r.vec(76, "transforms", TransformStamped::read)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn u32s(values: &[u32]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    fn header(seq: u32, sec: u32, nsec: u32, frame: &str) -> Vec<u8> {
        let mut out = u32s(&[seq, sec, nsec, frame.len() as u32]);
        out.extend_from_slice(frame.as_bytes());
        out
    }

    /// A LaserScan as ROS 1 lays it out: seq, the stamp, the frame without NUL, then the
    /// floats packed right after it (no alignment), each array with its length.
    #[test]
    fn a_laser_scan_reads_packed_with_the_header_seq() {
        let mut bytes = header(42, 7, 9, "laser");
        for x in [-1.5f32, 1.5, 0.5, 1e-4, 0.1, 0.12, 6.0] {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
        bytes.extend(u32s(&[2]));
        bytes.extend([1.25f32, f32::NAN].iter().flat_map(|x| x.to_le_bytes()));
        bytes.extend(u32s(&[0]));
        let scan: LaserScan = decode_whole(&bytes).unwrap();
        assert_eq!(scan.header.stamp, Time { sec: 7, nanosec: 9 });
        assert_eq!(scan.header.frame_id, "laser");
        assert_eq!((scan.angle_min, scan.angle_increment), (-1.5, 0.5));
        assert_eq!((scan.range_min, scan.range_max), (0.12, 6.0));
        assert_eq!(scan.ranges[0], 1.25);
        assert!(scan.ranges[1].is_nan());
        assert!(scan.intensities.is_empty());
        // One byte more is another type's layout; one less ends inside a field.
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(decode_whole::<LaserScan>(&longer)
            .unwrap_err()
            .contains("1 bytes after"));
        let err = decode_whole::<LaserScan>(&bytes[..bytes.len() - 1]).unwrap_err();
        assert!(err.contains("ends inside"), "{err}");
    }

    #[test]
    fn an_odometry_and_a_transform_read_as_the_ros2_types() {
        let mut bytes = header(1, 100, 5, "odom");
        bytes.extend(u32s(&[9]));
        bytes.extend_from_slice(b"base_link");
        let pose = [1.0f64, 2.0, 0.0, 0.0, 0.0, 0.5f64.sin(), 0.5f64.cos()];
        bytes.extend(pose.iter().flat_map(|x| x.to_le_bytes()));
        bytes.extend([0.0f64; 36].iter().flat_map(|x| x.to_le_bytes()));
        bytes.extend(
            [0.3f64, 0.0, 0.0, 0.0, 0.0, 0.1]
                .iter()
                .flat_map(|x| x.to_le_bytes()),
        );
        bytes.extend([0.0f64; 36].iter().flat_map(|x| x.to_le_bytes()));
        let odometry: Odometry = decode_whole(&bytes).unwrap();
        assert_eq!(odometry.child_frame_id, "base_link");
        assert_eq!(odometry.pose.pose.position.y, 2.0);
        assert!((odometry.pose.pose.orientation.yaw() - 1.0).abs() < 1e-12);
        assert_eq!(odometry.twist.twist.linear.x, 0.3);

        let mut tf = u32s(&[1]);
        tf.extend(header(0, 3, 0, "base_link"));
        tf.extend(u32s(&[5]));
        tf.extend_from_slice(b"laser");
        tf.extend(
            [0.12f64, 0.0, 0.2, 0.0, 0.0, 1.0, 0.0]
                .iter()
                .flat_map(|x| x.to_le_bytes()),
        );
        let message: TfMessage = decode_whole(&tf).unwrap();
        let t = &message.transforms[0];
        assert_eq!(
            (t.header.frame_id.as_str(), t.child_frame_id.as_str()),
            ("base_link", "laser")
        );
        assert_eq!(t.transform.translation.x, 0.12);
        assert_eq!(t.transform.rotation.z, 1.0);
    }

    /// An array claiming billions of elements is refused from its length, before anything is
    /// allocated; a stamp past 2038 is refused rather than wrapped.
    #[test]
    fn impossible_lengths_and_late_stamps_are_errors() {
        let mut bytes = header(0, 1, 0, "");
        bytes.extend([0u8; 28]);
        bytes.extend(u32s(&[u32::MAX]));
        let err = decode_whole::<LaserScan>(&bytes).unwrap_err();
        assert!(err.contains("4294967295 elements"), "{err}");
        let late = header(0, u32::MAX, 0, "");
        let err = decode_prefix::<Header>(&late).unwrap_err();
        assert!(err.contains("after 2038"), "{err}");
        assert!(decode_whole::<TfMessage>(&u32s(&[3])).is_err());
    }
}
