//! The standard scan's 5-byte measurement node.

/// Bytes in one node.
pub const NODE_LEN: usize = 5;

/// One measurement node (protocol v2.1, "Response Data of SCAN"):
///
/// | byte | bits |
/// | --- | --- |
/// | 0 | quality (6 bits) << 2, `!S` << 1, `S` (S: the first node of a new 360° scan) |
/// | 1 | angle_q6 bits 6..0 << 1, check bit C = 1 |
/// | 2 | angle_q6 bits 14..7 |
/// | 3–4 | distance_q2, u16 LE (mm × 4; 0: no return) |
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Node {
    /// `S`: the node starts a new revolution.
    pub start: bool,
    /// Quality, 6 bits.
    pub quality: u8,
    /// Angle in 1/64 degrees, 15 bits, clockwise from the unit's 0°.
    pub angle_q6: u16,
    /// Distance in 1/4 mm.
    pub distance_q2: u16,
}

impl Node {
    /// The node's bytes (the quality and angle are cut to their 6 and 15 bits).
    #[must_use]
    pub fn encode(&self) -> [u8; NODE_LEN] {
        let flags = if self.start { 0b01 } else { 0b10 };
        let angle = self.angle_q6 & 0x7FFF;
        let [d0, d1] = self.distance_q2.to_le_bytes();
        [
            ((self.quality & 0x3F) << 2) | flags,
            // Masked to 7 bits, so the shift stays in the byte.
            (((angle & 0x7F) as u8) << 1) | 1,
            (angle >> 7) as u8,
            d0,
            d1,
        ]
    }

    /// Parses 5 bytes; `None` when the check bits fail (`S == !S`, or `C == 0`), as every
    /// driver read (`rplidar-roboticia` `_process_scan`, `lds2d` `node_ok`) rejects them.
    #[must_use]
    pub fn decode(bytes: &[u8; NODE_LEN]) -> Option<Self> {
        let [b0, b1, b2, d0, d1] = *bytes;
        if (b0 ^ (b0 >> 1)) & 1 == 0 || b1 & 1 == 0 {
            return None;
        }
        Some(Self {
            start: b0 & 1 == 1,
            quality: b0 >> 2,
            angle_q6: (u16::from(b1) >> 1) | (u16::from(b2) << 7),
            distance_q2: u16::from_le_bytes([d0, d1]),
        })
    }

    /// The angle, degrees.
    #[must_use]
    pub fn angle_deg(&self) -> f64 {
        f64::from(self.angle_q6) / 64.0
    }

    /// The distance, millimetres (rounded to the nearest).
    #[must_use]
    pub fn distance_mm(&self) -> u32 {
        (u32::from(self.distance_q2) + 2) / 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn node_layout_matches_the_protocol() {
        let node = Node {
            start: true,
            quality: 47,
            angle_q6: 90 * 64,
            distance_q2: 4000,
        };
        // 90° = 5760 = 0x1680: low 7 bits 0x00, high 0x2D.
        assert_eq!(node.encode(), [(47 << 2) | 1, 0x01, 0x2D, 0xA0, 0x0F]);
        assert_eq!(Node::decode(&node.encode()), Some(node));
        assert_eq!(Node::decode(&[0b11, 1, 0, 0, 0]), None);
        assert_eq!(Node::decode(&[0b00, 1, 0, 0, 0]), None);
        assert_eq!(Node::decode(&[0b01, 0, 0, 0, 0]), None);
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x5EED_0A01),
            ..ProptestConfig::default()
        })]

        #[test]
        fn node_decode_of_encode_is_the_identity(start in any::<bool>(), quality in 0u8..64, angle_q6 in 0u16..0x8000, distance_q2 in any::<u16>()) {
            let node = Node { start, quality, angle_q6, distance_q2 };
            prop_assert_eq!(Node::decode(&node.encode()), Some(node));
        }
    }
}
