//! One 22-byte packet: four readings, the motor speed, the checksum; encoding and decoding.

/// Bytes in one packet on the wire.
pub const PACKET_LEN: usize = 22;
/// The first byte of every packet.
pub const START_BYTE: u8 = 0xFA;
/// The wire index byte of the packet covering angles 0..=3; the last packet of a revolution is
/// `INDEX_BASE + 89` (`0xF9`).
pub const INDEX_BASE: u8 = 0xA0;
/// Packets in one revolution (`0xA0..=0xF9`).
pub const PACKETS_PER_REVOLUTION: usize = 90;
/// Readings in one packet, one per degree.
pub const READINGS_PER_PACKET: usize = 4;
/// Readings in one revolution, one per degree.
pub const READINGS_PER_REVOLUTION: usize = PACKETS_PER_REVOLUTION * READINGS_PER_PACKET;
/// Bytes in one revolution sent back to back (1,980).
pub const REVOLUTION_LEN: usize = PACKETS_PER_REVOLUTION * PACKET_LEN;
/// The largest distance the 14-bit field carries, in millimetres.
pub const MAX_DISTANCE_MM: u16 = 0x3FFF;

const INVALID_FLAG: u8 = 0x80;
const STRENGTH_WARNING_FLAG: u8 = 0x40;
const DISTANCE_HIGH_BITS: u8 = 0x3F;
const CHECKSUM_MASK: u32 = 0x7FFF;
/// Offset of the checksum: it covers the 20 bytes before it.
const CHECKSUM_OFFSET: usize = 20;

/// Why 22 bytes are not a packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PacketError {
    /// Byte 0 is not [`START_BYTE`].
    #[error("start byte is {0:#04x}, expected 0xfa")]
    BadStartByte(u8),
    /// Byte 1 is outside `0xA0..=0xF9`.
    #[error("index byte is {0:#04x}, expected 0xa0..=0xf9")]
    BadIndex(u8),
    /// The checksum stored in bytes 20..22 differs from the one computed over bytes 0..20.
    #[error("checksum is {stored:#06x}, computed {computed:#06x}")]
    BadChecksum {
        /// What the packet carries.
        stored: u16,
        /// What its first 20 bytes sum to.
        computed: u16,
    },
}

/// One distance reading, one degree of a revolution.
///
/// When `invalid` is set the unit measured nothing: the low byte of `distance_mm` then carries
/// an error code instead of a distance (see [`Reading::error_code`]) and the strength is
/// usually 0. All 14 bits of the field are kept either way, so decoding and re-encoding a
/// reading reproduces its bytes exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Reading {
    /// Distance in millimetres, 14 bits (at most [`MAX_DISTANCE_MM`]); when `invalid`, its low
    /// byte is the error code.
    pub distance_mm: u16,
    /// The *invalid data* flag: no distance was measured.
    pub invalid: bool,
    /// The *strength warning* flag: the return was unusually weak or strong for its distance.
    pub strength_warning: bool,
    /// Signal strength, unitless.
    pub strength: u16,
}

impl Reading {
    /// A valid reading of `distance_mm` (more than 14 bits are clamped when encoded) with the
    /// given signal strength and no flags.
    #[must_use]
    pub const fn distance(distance_mm: u16, strength: u16) -> Self {
        Self {
            distance_mm,
            invalid: false,
            strength_warning: false,
            strength,
        }
    }

    /// An invalid reading carrying `error_code` (0x21, 0x35, 0x52… on real units), strength 0.
    #[must_use]
    pub const fn error(error_code: u8) -> Self {
        Self {
            distance_mm: error_code as u16,
            invalid: true,
            strength_warning: false,
            strength: 0,
        }
    }

    /// The error code when the reading is invalid (the low byte of the distance field).
    #[must_use]
    pub const fn error_code(&self) -> Option<u8> {
        if self.invalid {
            Some(self.distance_mm.to_le_bytes()[0])
        } else {
            None
        }
    }

    /// The distance in metres, `None` when the reading is invalid.
    #[must_use]
    pub fn range_m(&self) -> Option<f64> {
        (!self.invalid).then(|| f64::from(self.distance_mm) / 1000.0)
    }

    /// Parses the four bytes of a reading.
    #[must_use]
    pub const fn from_bytes(bytes: [u8; 4]) -> Self {
        let [distance_low, flags, strength_low, strength_high] = bytes;
        Self {
            distance_mm: u16::from_le_bytes([distance_low, flags & DISTANCE_HIGH_BITS]),
            invalid: flags & INVALID_FLAG != 0,
            strength_warning: flags & STRENGTH_WARNING_FLAG != 0,
            strength: u16::from_le_bytes([strength_low, strength_high]),
        }
    }

    /// The four bytes of the reading.
    ///
    /// A valid distance above [`MAX_DISTANCE_MM`] is clamped (a far reading stays far rather
    /// than wrapping to a near one); an invalid reading's field is masked to 14 bits instead, so
    /// its error code byte always survives.
    #[must_use]
    pub const fn to_bytes(&self) -> [u8; 4] {
        let field = if self.invalid {
            self.distance_mm & MAX_DISTANCE_MM
        } else if self.distance_mm > MAX_DISTANCE_MM {
            MAX_DISTANCE_MM
        } else {
            self.distance_mm
        };
        let [distance_low, distance_high] = field.to_le_bytes();
        let mut flags = distance_high;
        if self.invalid {
            flags |= INVALID_FLAG;
        }
        if self.strength_warning {
            flags |= STRENGTH_WARNING_FLAG;
        }
        let [strength_low, strength_high] = self.strength.to_le_bytes();
        [distance_low, flags, strength_low, strength_high]
    }
}

/// One packet: four consecutive degrees of a revolution and the motor speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Packet {
    /// Position in the revolution, 0..=89 (the wire byte minus [`INDEX_BASE`]); packet `i`
    /// carries angles `4i..=4i+3`. The encoder takes it modulo 90.
    pub index: u8,
    /// Motor speed in rpm × 64 (6 fractional bits), as on the wire.
    pub rpm_fixed: u16,
    /// The readings of angles `first_angle_deg() + slot`, slot 0..=3.
    pub readings: [Reading; READINGS_PER_PACKET],
}

impl Packet {
    /// Motor speed in revolutions per minute.
    #[must_use]
    pub fn rpm(&self) -> f64 {
        f64::from(self.rpm_fixed) / 64.0
    }

    /// The angle of `readings[0]` in degrees, in the sensor frame: `4 * index`, increasing
    /// counter-clockwise as the ROS driver reads it.
    #[must_use]
    pub const fn first_angle_deg(&self) -> u16 {
        // u8 -> u16 widening; `From` is not const.
        (self.index % PACKETS_PER_REVOLUTION as u8) as u16 * READINGS_PER_PACKET as u16
    }

    /// The 22 bytes of the packet, checksum included.
    #[must_use]
    pub fn encode(&self) -> [u8; PACKET_LEN] {
        let mut bytes = [0; PACKET_LEN];
        bytes[0] = START_BYTE;
        // Modulo keeps the output a well-formed packet whatever `index` holds.
        bytes[1] = INDEX_BASE + self.index % PACKETS_PER_REVOLUTION as u8;
        bytes[2..4].copy_from_slice(&self.rpm_fixed.to_le_bytes());
        for (chunk, reading) in bytes[4..CHECKSUM_OFFSET]
            .chunks_exact_mut(4)
            .zip(&self.readings)
        {
            chunk.copy_from_slice(&reading.to_bytes());
        }
        let sum = checksum(&bytes);
        bytes[CHECKSUM_OFFSET..].copy_from_slice(&sum.to_le_bytes());
        bytes
    }

    /// Parses 22 bytes, checking the start byte, the index range and the checksum.
    ///
    /// # Errors
    /// The first of those checks that fails.
    pub fn decode(bytes: &[u8; PACKET_LEN]) -> Result<Self, PacketError> {
        if bytes[0] != START_BYTE {
            return Err(PacketError::BadStartByte(bytes[0]));
        }
        if !is_index_byte(bytes[1]) {
            return Err(PacketError::BadIndex(bytes[1]));
        }
        let stored = u16::from_le_bytes([bytes[CHECKSUM_OFFSET], bytes[CHECKSUM_OFFSET + 1]]);
        let computed = checksum(bytes);
        if stored != computed {
            return Err(PacketError::BadChecksum { stored, computed });
        }
        let reading_at = |at: usize| {
            Reading::from_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
        };
        Ok(Self {
            index: bytes[1] - INDEX_BASE,
            rpm_fixed: u16::from_le_bytes([bytes[2], bytes[3]]),
            readings: [reading_at(4), reading_at(8), reading_at(12), reading_at(16)],
        })
    }
}

/// Whether `byte` is a wire index, `0xA0..=0xF9`.
pub(crate) const fn is_index_byte(byte: u8) -> bool {
    byte >= INDEX_BASE && byte < INDEX_BASE + PACKETS_PER_REVOLUTION as u8
}

/// The XV-11 checksum of a packet, computed over its first 20 bytes (bytes 20 and 21, where the
/// checksum itself goes, are ignored). Always at most `0x7FFF`.
///
/// The 20 bytes are ten little-endian words `w0..w9`; `acc = (acc << 1) + w` over them, then
/// `((acc & 0x7FFF) + (acc >> 15)) & 0x7FFF`, exactly as the firmware does (including losing the
/// carry of the final addition).
#[must_use]
pub fn checksum(packet: &[u8; PACKET_LEN]) -> u16 {
    // Ten words of at most 0xFFFF shifted by at most 9 stay below 2^26: u32 cannot overflow.
    let acc = packet[..CHECKSUM_OFFSET]
        .chunks_exact(2)
        .fold(0u32, |acc, word| {
            (acc << 1) + u32::from(u16::from_le_bytes([word[0], word[1]]))
        });
    let folded = ((acc & CHECKSUM_MASK) + (acc >> 15)) & CHECKSUM_MASK;
    // `folded` is masked to 15 bits, so the conversion never fails.
    u16::try_from(folded).unwrap_or(u16::MAX)
}

/// Motor speed in rpm to the wire's fixed point (rpm × 64), rounded to nearest, saturating at
/// 0 and `u16::MAX` (1023.98 rpm); NaN gives 0.
#[must_use]
pub fn rpm_to_fixed(rpm: f64) -> u16 {
    // `as` from f64 saturates and maps NaN to 0, which is the documented behaviour.
    (rpm * 64.0).round() as u16
}

/// Appends one whole revolution to `out`: packets `0xA0..=0xF9` back to back (1,980 bytes),
/// `readings[i]` at angle `i` degrees, every packet carrying `rpm` (see [`rpm_to_fixed`]).
///
/// Reserves once and writes packets in place; nothing is allocated per packet.
pub fn encode_revolution(
    readings: &[Reading; READINGS_PER_REVOLUTION],
    rpm: f64,
    out: &mut Vec<u8>,
) {
    out.reserve(REVOLUTION_LEN);
    let rpm_fixed = rpm_to_fixed(rpm);
    for (index, chunk) in (0u8..).zip(readings.chunks_exact(READINGS_PER_PACKET)) {
        let packet = Packet {
            index,
            rpm_fixed,
            readings: [chunk[0], chunk[1], chunk[2], chunk[3]],
        };
        out.extend_from_slice(&packet.encode());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The first worked example of the protocol note: index 0xA0, 300 rpm.
    const WORKED_A0: [u8; PACKET_LEN] = [
        0xFA, 0xA0, 0x00, 0x4B, 0xE8, 0x03, 0x23, 0x01, 0xDC, 0x05, 0xC8, 0x00, 0x35, 0x80, 0x00,
        0x00, 0xB8, 0x4B, 0x10, 0x00, 0x11, 0x15,
    ];
    /// The second worked example: index 0xB1, 295.55 rpm, from a public decoder.
    const WORKED_B1: [u8; PACKET_LEN] = [
        0xFA, 0xB1, 0xE3, 0x49, 0xE4, 0x00, 0xE1, 0x05, 0xE2, 0x00, 0x34, 0x06, 0xE0, 0x00, 0x25,
        0x06, 0xDF, 0x00, 0x84, 0x06, 0xF6, 0x6B,
    ];

    #[test]
    fn first_worked_example_decodes_to_the_stated_values() {
        let packet = Packet::decode(&WORKED_A0).expect("worked example is valid");
        assert_eq!(packet.index, 0);
        assert_eq!(packet.first_angle_deg(), 0);
        assert_eq!(packet.rpm(), 300.0);
        let [a, b, c, d] = packet.readings;
        assert_eq!(a, Reading::distance(1000, 291));
        assert_eq!(b, Reading::distance(1500, 200));
        assert_eq!(c, Reading::error(0x35));
        assert_eq!(c.error_code(), Some(0x35));
        assert_eq!(c.range_m(), None);
        assert_eq!(
            d,
            Reading {
                strength_warning: true,
                ..Reading::distance(3000, 16)
            }
        );
    }

    #[test]
    fn first_worked_example_re_encodes_byte_identically() {
        let packet = Packet {
            index: 0,
            rpm_fixed: rpm_to_fixed(300.0),
            readings: [
                Reading::distance(1000, 291),
                Reading::distance(1500, 200),
                Reading::error(0x35),
                Reading {
                    strength_warning: true,
                    ..Reading::distance(3000, 16)
                },
            ],
        };
        assert_eq!(packet.encode(), WORKED_A0);
        assert_eq!(
            Packet::decode(&WORKED_A0).map(|p| p.encode()),
            Ok(WORKED_A0)
        );
    }

    #[test]
    fn second_worked_example_decodes_to_the_stated_values() {
        let packet = Packet::decode(&WORKED_B1).expect("worked example is valid");
        assert_eq!(packet.index, 0xB1 - 0xA0);
        assert_eq!(packet.first_angle_deg(), 68);
        // 0x49E3 / 64 = 295.546875, "295.55 rpm" in the note.
        assert_eq!(packet.rpm(), 295.546875);
        let distances = packet.readings.map(|r| r.distance_mm);
        assert_eq!(distances, [228, 226, 224, 223]);
        assert!(packet
            .readings
            .iter()
            .all(|r| !r.invalid && !r.strength_warning));
        assert_eq!(packet.encode(), WORKED_B1);
    }

    #[test]
    fn decode_names_what_is_wrong() {
        let mut bytes = WORKED_A0;
        bytes[0] = 0xFB;
        assert_eq!(Packet::decode(&bytes), Err(PacketError::BadStartByte(0xFB)));
        let mut bytes = WORKED_A0;
        bytes[1] = 0xFA;
        assert_eq!(Packet::decode(&bytes), Err(PacketError::BadIndex(0xFA)));
        let mut bytes = WORKED_A0;
        bytes[5] ^= 0x01;
        assert!(matches!(
            Packet::decode(&bytes),
            Err(PacketError::BadChecksum { stored: 0x1511, .. })
        ));
    }

    #[test]
    fn encoder_clamps_distance_and_rpm() {
        let far = Reading::distance(20_000, 0);
        assert_eq!(
            Reading::from_bytes(far.to_bytes()).distance_mm,
            MAX_DISTANCE_MM
        );
        assert_eq!(rpm_to_fixed(295.55), 0x49E3);
        assert_eq!(rpm_to_fixed(-5.0), 0);
        assert_eq!(rpm_to_fixed(f64::NAN), 0);
        assert_eq!(rpm_to_fixed(1e9), u16::MAX);
        let wrapped = Packet {
            index: 90 + 7,
            ..Packet::default()
        };
        assert_eq!(wrapped.encode()[1], 0xA7);
    }

    #[test]
    fn revolution_is_90_packets_a0_to_f9_back_to_back() {
        let readings: [Reading; READINGS_PER_REVOLUTION] =
            std::array::from_fn(|angle| Reading::distance(angle as u16 * 10, 7));
        let mut out = vec![0x55]; // appended to, not overwritten
        encode_revolution(&readings, 301.3, &mut out);
        assert_eq!(out.len(), 1 + REVOLUTION_LEN);
        for (i, bytes) in out[1..].chunks_exact(PACKET_LEN).enumerate() {
            let bytes: &[u8; PACKET_LEN] = bytes.try_into().expect("chunk of 22");
            assert_eq!(bytes[1], INDEX_BASE + i as u8);
            let packet = Packet::decode(bytes).expect("encoder output is valid");
            assert_eq!(packet.rpm_fixed, rpm_to_fixed(301.3));
            for (slot, reading) in packet.readings.iter().enumerate() {
                let angle = usize::from(packet.first_angle_deg()) + slot;
                assert_eq!(*reading, readings[angle]);
            }
        }
    }

    fn any_reading() -> impl Strategy<Value = Reading> {
        (
            0..=MAX_DISTANCE_MM,
            any::<bool>(),
            any::<bool>(),
            any::<u16>(),
        )
            .prop_map(
                |(distance_mm, invalid, strength_warning, strength)| Reading {
                    distance_mm,
                    invalid,
                    strength_warning,
                    strength,
                },
            )
    }

    fn any_packet() -> impl Strategy<Value = Packet> {
        (
            0..PACKETS_PER_REVOLUTION as u8,
            any::<u16>(),
            [any_reading(), any_reading(), any_reading(), any_reading()],
        )
            .prop_map(|(index, rpm_fixed, readings)| Packet {
                index,
                rpm_fixed,
                readings,
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x5EED_0004),
            failure_persistence: None,
            cases: 2048,
            ..ProptestConfig::default()
        })]

        #[test]
        fn decode_of_encode_is_the_identity(packet in any_packet()) {
            prop_assert_eq!(Packet::decode(&packet.encode()), Ok(packet));
            for reading in &packet.readings {
                if reading.invalid {
                    prop_assert_eq!(reading.error_code(), Some(reading.distance_mm.to_le_bytes()[0]));
                }
            }
        }

        #[test]
        fn error_code_survives_any_distance_field(code in any::<u8>(), high in any::<u16>(), warn in any::<bool>()) {
            let reading = Reading {
                distance_mm: u16::from_le_bytes([code, high.to_le_bytes()[0]]),
                strength_warning: warn,
                ..Reading::error(code)
            };
            prop_assert_eq!(Reading::from_bytes(reading.to_bytes()).error_code(), Some(code));
        }

        #[test]
        fn encode_of_decode_is_the_identity_for_any_well_formed_bytes(mut bytes in any::<[u8; PACKET_LEN]>()) {
            // Arbitrary field bits, made into a packet: start byte, an index, the checksum.
            bytes[0] = START_BYTE;
            bytes[1] = INDEX_BASE + bytes[1] % PACKETS_PER_REVOLUTION as u8;
            let sum = checksum(&bytes);
            bytes[CHECKSUM_OFFSET..].copy_from_slice(&sum.to_le_bytes());
            let packet = Packet::decode(&bytes);
            prop_assert!(packet.is_ok());
            prop_assert_eq!(packet.map(|p| p.encode()), Ok(bytes));
        }

        #[test]
        fn checksum_high_byte_never_exceeds_0x7f(bytes in any::<[u8; PACKET_LEN]>()) {
            prop_assert!(checksum(&bytes).to_le_bytes()[1] <= 0x7F);
        }
    }

    #[test]
    fn checksum_high_byte_never_exceeds_0x7f_at_the_extremes() {
        for fill in [0x00, 0x7F, 0x80, 0xFF] {
            assert!(checksum(&[fill; PACKET_LEN]) <= 0x7FFF);
        }
    }
}
