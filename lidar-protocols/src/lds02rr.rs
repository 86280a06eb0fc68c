//! The Xiaomi LDS02RR's serial stream, as described in `docs/formats/lds-02rr.md`: byte for byte
//! the Neato XV-11's 22-byte packets, so this module wraps [`crate::xv11`]'s codec.
//!
//! What differs from the XV-11 is not on the wire: the LDS02RR's degrees grow clockwise (the
//! drivers `lds2d` `xiaomi_lds02rr.py` and kaiaai `LDS` read its index unmirrored and the XV-11's
//! mirrored), and the unit has no commands. Its motor, like the XV-11's, is spun by the host's
//! PWM and it streams while it turns; the emulator cannot see a PWM pin, so the unit streams
//! always, at the rate the scenario gives.
//!
//! ```
//! use hilsim_lidar_protocols::lds02rr::{Lds02rrDecoder, Lds02rrUnit};
//! use hilsim_lidar_protocols::{HostDecoder, Output, Unit, UnitReading};
//!
//! let mut unit = Lds02rrUnit::new();
//! let mut out = Output::new();
//! for index in 0..360 {
//!     let reading = UnitReading {
//!         t_s: f64::from(index) / 1800.0,
//!         rev: 0,
//!         index,
//!         angle_deg: f64::from(index),
//!         distance_mm: if index == 7 { 0 } else { 400 + index },
//!         intensity: 60,
//!         rev_hz: 5.0,
//!         starts_revolution: index == 0,
//!     };
//!     unit.push(&reading, &mut out);
//! }
//! assert_eq!(out.bytes.len(), 1980);
//! let mut points = Vec::new();
//! Lds02rrDecoder::new().feed(&out.bytes, &mut points);
//! assert_eq!(points.len(), 360);
//! assert_eq!((points[7].distance_mm, points[8].distance_mm), (0, 408));
//! ```

use crate::lds01::{packet_timing, DegreePackets};
use crate::xv11::{self, rpm_to_fixed, Packet, Reading, MAX_DISTANCE_MM, READINGS_PER_PACKET};
use crate::{DecodeStats, HostDecoder, Output, Point, Unit, UnitReading};

/// The error code a no-return reading carries with its *invalid* flag: one of the codes real
/// XV-11-family units send (`docs/formats/neato-xv11.md`).
pub const NO_RETURN_CODE: u8 = 0x21;

/// The LDS02RR's side: four degrees a packet, always streaming.
#[derive(Debug, Clone, Default)]
pub struct Lds02rrUnit {
    pending: DegreePackets<READINGS_PER_PACKET>,
}

impl Lds02rrUnit {
    /// A unit whose motor the host spins.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// The wire reading of an emulated one: a no return is flagged invalid with
    /// [`NO_RETURN_CODE`], a distance clamped to 14 bits, the intensity kept as the strength.
    #[must_use]
    pub fn wire_reading(reading: Option<&UnitReading>) -> Reading {
        match reading {
            Some(r) if r.distance_mm > 0 => Reading::distance(
                u16::try_from(r.distance_mm)
                    .unwrap_or(u16::MAX)
                    .min(MAX_DISTANCE_MM),
                u16::from(r.intensity),
            ),
            _ => Reading::error(NO_RETURN_CODE),
        }
    }
}

impl Unit for Lds02rrUnit {
    fn host_wrote(&mut self, _bytes: &[u8], _now_s: f64, _out: &mut Output) {
        // The LDS02RR's serial line carries nothing from the host: its only input is the motor.
    }

    fn scanning(&self) -> bool {
        true
    }

    fn push(&mut self, reading: &UnitReading, out: &mut Output) {
        self.pending.push(reading, |index, slots| {
            let (due_s, rev_hz, starts_revolution) = packet_timing(slots);
            let packet = Packet {
                index: u8::try_from(index).unwrap_or(0),
                rpm_fixed: rpm_to_fixed(rev_hz * 60.0),
                readings: slots
                    .each_ref()
                    .map(|slot| Self::wire_reading(slot.as_ref())),
            };
            out.packet(due_s, 2, starts_revolution, |bytes| {
                bytes.extend_from_slice(&packet.encode());
            });
        });
    }
}

/// The host's side: the XV-11 decoder, its packets' degrees read unmirrored.
#[derive(Debug, Clone, Default)]
pub struct Lds02rrDecoder {
    inner: xv11::Decoder,
}

impl Lds02rrDecoder {
    /// A decoder that has seen nothing.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Bytes held for a packet not complete yet, 0..=21.
    #[must_use]
    pub fn pending_len(&self) -> usize {
        self.inner.pending_len()
    }
}

impl HostDecoder for Lds02rrDecoder {
    fn feed(&mut self, bytes: &[u8], out: &mut Vec<Point>) {
        for packet in self.inner.feed(bytes) {
            let rev_hz = packet.rpm() / 60.0;
            let first = packet.first_angle_deg();
            for (slot, r) in (0u16..).zip(&packet.readings) {
                let degree = first + slot;
                out.push(Point {
                    angle_deg: f64::from(degree),
                    distance_mm: if r.invalid {
                        0
                    } else {
                        u32::from(r.distance_mm)
                    },
                    intensity: r.strength,
                    starts_revolution: degree == 0,
                    rev_hz: Some(rev_hz),
                });
            }
        }
    }

    fn stats(&self) -> DecodeStats {
        let s = self.inner.stats();
        DecodeStats {
            bytes: s.bytes,
            packets: s.packets,
            bad_checksum: s.bad_checksum,
            skipped_bytes: s.skipped_bytes,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::xv11::PACKET_LEN;
    use proptest::prelude::*;

    fn revolution(rev: u64, rev_hz: f64, distance: impl Fn(u32) -> u32) -> Vec<UnitReading> {
        let t0 = rev as f64 / rev_hz;
        (0..360)
            .map(|index| UnitReading {
                t_s: t0 + f64::from(index) / 360.0 / rev_hz,
                rev,
                index,
                angle_deg: f64::from(index),
                distance_mm: distance(index),
                intensity: (index * 3 % 256) as u8,
                rev_hz,
                starts_revolution: index == 0,
            })
            .collect()
    }

    fn push_all(readings: &[UnitReading]) -> Output {
        let mut unit = Lds02rrUnit::new();
        let mut out = Output::new();
        for r in readings {
            unit.push(r, &mut out);
        }
        out
    }

    fn decode_all(bytes: &[u8]) -> (Vec<Point>, DecodeStats) {
        let mut decoder = Lds02rrDecoder::new();
        let mut points = Vec::new();
        decoder.feed(bytes, &mut points);
        (points, decoder.stats())
    }

    #[test]
    fn revolution_is_the_xv11s_90_packets() {
        let readings = revolution(2, 5.0, |i| if i % 5 == 0 { 0 } else { 150 + 11 * i });
        let out = push_all(&readings);
        assert_eq!(out.packets.len(), 90);
        assert_eq!(out.bytes.len(), xv11::REVOLUTION_LEN);
        for (k, (bytes, span)) in out.iter().enumerate() {
            let bytes: &[u8; PACKET_LEN] = bytes.try_into().expect("22 bytes");
            let packet = Packet::decode(bytes).expect("valid XV-11 packet");
            assert_eq!(usize::from(packet.index), k);
            assert_eq!(packet.rpm(), 300.0);
            assert_eq!(span.due_s, readings[4 * k + 3].t_s);
            assert_eq!(span.starts_revolution, k == 0);
        }
        // The first packet's first reading is a no return: invalid, with its code.
        assert_eq!(&out.bytes[4..6], &[NO_RETURN_CODE, 0x80]);
        let (points, stats) = decode_all(&out.bytes);
        assert_eq!(
            (stats.packets, stats.bad_checksum, stats.skipped_bytes),
            (90, 0, 0)
        );
        for (r, p) in readings.iter().zip(&points) {
            assert_eq!(p.angle_deg, r.angle_deg);
            assert_eq!(p.distance_mm, r.distance_mm);
            if r.distance_mm > 0 {
                assert_eq!(p.intensity, u16::from(r.intensity));
            }
            assert_eq!(p.starts_revolution, r.starts_revolution);
            assert_eq!(p.rev_hz, Some(5.0));
        }
    }

    #[test]
    fn host_bytes_are_ignored() {
        let mut unit = Lds02rrUnit::new();
        let mut out = Output::new();
        unit.host_wrote(b"b\xA5\x20e", 0.0, &mut out);
        assert!(out.is_empty());
        assert!(unit.scanning());
    }

    #[test]
    fn damaged_stream_resynchronises_and_counts() {
        let out = push_all(&revolution(0, 5.0, |i| 300 + i));
        let mut wire = out.bytes[..PACKET_LEN].to_vec();
        let mut bad = out.bytes[PACKET_LEN..2 * PACKET_LEN].to_vec();
        bad[9] ^= 0x04;
        wire.extend_from_slice(&bad);
        wire.extend_from_slice(&[0xFA, 0xFA]);
        wire.extend_from_slice(&out.bytes[2 * PACKET_LEN..3 * PACKET_LEN]);
        let (points, stats) = decode_all(&wire);
        assert_eq!(stats.packets, 2);
        assert_eq!(stats.bad_checksum, 1);
        assert_eq!(points[4].angle_deg, 8.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x01D5_0002),
            failure_persistence: None,
            cases: 256,
            ..ProptestConfig::default()
        })]

        #[test]
        fn random_readings_survive_the_round_trip(
            rev_hz in 1.0f64..10.0,
            values in proptest::collection::vec((0u32..=20_000, any::<u8>()), 360),
        ) {
            let mut readings = revolution(0, rev_hz, |_| 0);
            for (r, (d, i)) in readings.iter_mut().zip(&values) {
                r.distance_mm = *d;
                r.intensity = *i;
            }
            let (points, stats) = decode_all(&push_all(&readings).bytes);
            prop_assert_eq!(stats.packets, 90);
            for (r, p) in readings.iter().zip(&points) {
                prop_assert_eq!(p.angle_deg, r.angle_deg);
                prop_assert_eq!(p.distance_mm, r.distance_mm.min(u32::from(MAX_DISTANCE_MM)));
                prop_assert!((p.rev_hz.unwrap_or(0.0) - rev_hz).abs() < 1.0 / 64.0 / 60.0);
            }
        }

        #[test]
        fn random_bytes_never_panic_and_chunks_agree(
            bytes in proptest::collection::vec(any::<u8>(), 0..400),
            chunk in 1usize..40,
        ) {
            let (points, stats) = decode_all(&bytes);
            let mut decoder = Lds02rrDecoder::new();
            let mut chunked = Vec::new();
            for piece in bytes.chunks(chunk) {
                decoder.feed(piece, &mut chunked);
            }
            prop_assert_eq!(&chunked, &points);
            prop_assert_eq!(decoder.stats(), stats);
            prop_assert_eq!(
                stats.packets * PACKET_LEN as u64 + stats.skipped_bytes + decoder.pending_len() as u64,
                stats.bytes
            );
        }
    }
}
