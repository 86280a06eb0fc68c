//! A ROS 2 message's bytes: a 4-byte encapsulation header (the representation: plain CDR,
//! big- or little-endian) and the CDR body, whose alignment counts from the body's start.

use byteorder::{BigEndian, LittleEndian};
use serde::{Deserialize, Serialize};

/// The encapsulation header of little-endian plain CDR (`CDR_LE`), what ROS 2 writes on x86 and
/// ARM.
const CDR_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// The bytes a serializer may leave after a message's last field: the body is padded to a
/// multiple of 4.
const END_PADDING: usize = 3;

/// Decodes a whole message: its fields, then at most `appended` bytes of fields a newer
/// distribution adds (and the padding to 4). More left over is a message of another type that
/// happened to decode: an error, as any other.
pub(crate) fn decode_whole<'de, T: Deserialize<'de>>(
    data: &'de [u8],
    appended: usize,
) -> Result<T, String> {
    let (message, left) = decode_prefix(data)?;
    if left > appended + END_PADDING {
        return Err(format!(
            "{left} bytes after the message's last field: the bytes are laid out as another \
             type"
        ));
    }
    Ok(message)
}

/// Decodes the start of a message (e.g. the header every stamped message begins with).
pub(crate) fn decode<'de, T: Deserialize<'de>>(data: &'de [u8]) -> Result<T, String> {
    decode_prefix(data).map(|(message, _)| message)
}

/// A message decoded from the start of `data`, and the count of bytes left after it.
fn decode_prefix<'de, T: Deserialize<'de>>(data: &'de [u8]) -> Result<(T, usize), String> {
    let Some((head, body)) = data.split_first_chunk::<4>() else {
        return Err(format!(
            "a message of {} bytes, shorter than its CDR header",
            data.len()
        ));
    };
    let decoded = match (head[0], head[1]) {
        (0x00, 0x00) => cdr_encoding::from_bytes::<T, BigEndian>(body),
        (0x00, 0x01) => cdr_encoding::from_bytes::<T, LittleEndian>(body),
        (a, b) => {
            return Err(format!(
                "representation 0x{a:02x}{b:02x} is not plain CDR (XCDR1): not what ROS 2 writes"
            ))
        }
    };
    decoded
        .map(|(message, used)| (message, body.len().saturating_sub(used)))
        .map_err(|err| format!("malformed CDR ({err})"))
}

/// Encodes a message as little-endian plain CDR, into `out` (cleared first).
pub(crate) fn encode<T: Serialize>(message: &T, out: &mut Vec<u8>) {
    out.clear();
    out.extend_from_slice(&CDR_LE);
    // Writing into a Vec cannot fail, and every message type here serialises (no maps, no
    // untagged enums): an error would be a bug in this crate's types.
    cdr_encoding::to_writer::<T, LittleEndian, _>(&mut *out, message)
        .expect("a ROS 2 message serialises to CDR");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::{Header, LaserScan, Odometry, Time};

    /// A LaserScan as ROS 2 lays it out: the header's string, then the floats aligned to 4 from
    /// the body's start (not the buffer's).
    #[test]
    fn a_laser_scan_has_the_ros_layout() {
        let scan = LaserScan {
            header: Header {
                stamp: Time { sec: 1, nanosec: 2 },
                frame_id: "laser".into(),
            },
            angle_increment: 0.5,
            ranges: vec![1.0, 2.0],
            ..LaserScan::default()
        };
        let mut bytes = Vec::new();
        encode(&scan, &mut bytes);
        assert_eq!(&bytes[..4], &CDR_LE);
        // sec, nanosec, string length 6 ("laser\0"), then 2 bytes of padding to 4.
        assert_eq!(&bytes[4..12], &[1, 0, 0, 0, 2, 0, 0, 0]);
        assert_eq!(&bytes[12..16], &[6, 0, 0, 0]);
        assert_eq!(&bytes[16..22], b"laser\0");
        assert_eq!(&bytes[22..24], &[0, 0]);
        assert_eq!(decode::<LaserScan>(&bytes).unwrap(), scan);
        // Big-endian reads too.
        let mut be = vec![0, 0, 0, 0, 0, 0, 0, 7, 0, 0, 0, 9, 0, 0, 0, 1, 0];
        be.extend_from_slice(&[0; 3]);
        be.extend_from_slice(&[0; 28]);
        be.extend_from_slice(&[0, 0, 0, 1]);
        be.extend_from_slice(&2.5f32.to_be_bytes());
        be.extend_from_slice(&[0, 0, 0, 0]);
        let scan: LaserScan = decode(&be).unwrap();
        assert_eq!((scan.header.stamp.sec, scan.header.stamp.nanosec), (7, 9));
        assert_eq!(scan.ranges, vec![2.5]);
    }

    /// A message of one type read as another can decode without error and leave bytes over:
    /// a whole message must end where its fields do (but for padding and fields appended by
    /// a newer distribution).
    #[test]
    fn bytes_left_after_a_message_are_an_error() {
        let odometry = Odometry::default();
        let mut bytes = Vec::new();
        encode(&odometry, &mut bytes);
        assert!(decode::<LaserScan>(&bytes).is_ok(), "a prefix decodes");
        let err = decode_whole::<LaserScan>(&bytes, 0).unwrap_err();
        assert!(
            err.contains("bytes after the message's last field"),
            "{err}"
        );
        assert_eq!(decode_whole::<Odometry>(&bytes, 0).unwrap(), odometry);
        bytes.extend_from_slice(&[0; 3]);
        assert!(decode_whole::<Odometry>(&bytes, 0).is_ok(), "padding to 4");
        bytes.extend_from_slice(&[0; 4]);
        assert!(decode_whole::<Odometry>(&bytes, 0).is_err());
        assert!(
            decode_whole::<Odometry>(&bytes, 4).is_ok(),
            "an appended float32"
        );
    }

    #[test]
    fn bad_bytes_are_errors_not_panics() {
        assert!(decode::<LaserScan>(&[0, 1])
            .unwrap_err()
            .contains("shorter"));
        assert!(decode::<LaserScan>(&[0, 7, 0, 0, 1])
            .unwrap_err()
            .contains("XCDR1"));
        assert!(decode::<Odometry>(&[0, 1, 0, 0, 1, 2, 3])
            .unwrap_err()
            .contains("malformed"));
        // A sequence claiming 4 billion elements ends at the data's end, allocating little.
        let mut huge = CDR_LE.to_vec();
        huge.extend_from_slice(&[0; 8]);
        huge.extend_from_slice(&[1, 0, 0, 0, 0, 0, 0, 0]);
        huge.extend_from_slice(&[0; 28]);
        huge.extend_from_slice(&[0xff, 0xff, 0xff, 0xff]);
        assert!(decode::<LaserScan>(&huge).is_err());
    }
}
