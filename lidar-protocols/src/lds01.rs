//! The Hitachi-LG HLS-LFCD2's serial stream (the TurtleBot3's LDS-01), as described in
//! `docs/formats/lds-01.md`: 60 packets of 42 bytes a revolution, six whole degrees each.
//!
//! The unit takes two one-byte commands: ASCII `b` starts the motor and the stream, `e` stops
//! them (ROBOTIS `hls_lfcd_lds_driver`, `lfcd_laser` constructor and destructor). Since its
//! 2017.10 firmware it streams from power-on without `b` (the ROBOTIS driver's comment "not
//! required after firmware upgrade"), which [`Lds01Unit::new`] emulates;
//! [`Lds01Unit::awaiting_start`] is the older firmware that waits for `b`. It sends no replies.
//!
//! ```
//! use hilsim_lidar_protocols::lds01::{Lds01Decoder, Lds01Unit};
//! use hilsim_lidar_protocols::{HostDecoder, Output, Unit, UnitReading};
//!
//! let mut unit = Lds01Unit::new();
//! let mut out = Output::new();
//! for index in 0..360 {
//!     let reading = UnitReading {
//!         t_s: f64::from(index) / 1800.0,
//!         rev: 0,
//!         index,
//!         angle_deg: f64::from(index),
//!         distance_mm: 500 + index,
//!         intensity: 100,
//!         rev_hz: 5.0,
//!         starts_revolution: index == 0,
//!     };
//!     unit.push(&reading, &mut out);
//! }
//! assert_eq!(out.bytes.len(), 60 * 42);
//! let mut points = Vec::new();
//! Lds01Decoder::new().feed(&out.bytes, &mut points);
//! assert_eq!(points.len(), 360);
//! assert_eq!((points[90].angle_deg, points[90].distance_mm), (90.0, 590));
//! ```

use crate::framing::SyncFramer;
use crate::{DecodeStats, HostDecoder, Output, Point, Unit, UnitReading};

/// Bytes in one packet.
pub const PACKET_LEN: usize = 42;
/// The first byte of every packet.
pub const START_BYTE: u8 = 0xFA;
/// The index byte of the packet carrying degrees 0–5; the last of a revolution is `0xDB`.
pub const INDEX_BASE: u8 = 0xA0;
/// Packets in a revolution.
pub const PACKETS_PER_REVOLUTION: usize = 60;
/// Readings in a packet, one a degree.
pub const READINGS_PER_PACKET: usize = 6;
/// The speed field counts tenths of an rpm: the ROBOTIS driver publishes it divided by 10 as
/// `rpms` (`hlds_laser_publisher.cpp`), as do `hls_lfcd_lds_rs` and the `HLS_LFCD` Arduino
/// library ("3001 == 300.1"). `lds2d` reads the field as whole rpm, so it reports ten times the
/// real rate, from the real unit as from this one.
pub const RPM_SCALE: f64 = 10.0;
/// The distance word's *invalid* flag (bit 15) as `lds2d` reads it; the unit sets none of it
/// here, as a no return is a distance of 0 on the LDS-01.
pub const INVALID_FLAG: u16 = 0x8000;
/// The largest distance the word carries below its flag bits, millimetres.
pub const MAX_DISTANCE_MM: u16 = 0x3FFF;

/// The ASCII command that starts the motor and the stream.
pub const START_COMMAND: u8 = b'b';
/// The ASCII command that stops them.
pub const STOP_COMMAND: u8 = b'e';

const CHECKSUM_OFFSET: usize = PACKET_LEN - 2;

/// The checksum over a packet's first 40 bytes (its last two are the checksum itself): the
/// XV-11's shift-and-fold over twenty little-endian words, to 15 bits (`lds2d`
/// `hitachi_lg_hls_lfcd2.calc_checksum`, after kaiaai `LDS_HLS_LFCD2::calcChecksum`).
#[must_use]
pub fn checksum(packet: &[u8; PACKET_LEN]) -> u16 {
    // Twenty words shifted by at most 19 stay below 2^35: u64 cannot overflow.
    let acc = packet[..CHECKSUM_OFFSET]
        .chunks_exact(2)
        .fold(0u64, |acc, w| {
            (acc << 1) + u64::from(u16::from_le_bytes([w[0], w[1]]))
        });
    let folded = ((acc & 0x7FFF) + (acc >> 15)) & 0x7FFF;
    u16::try_from(folded).unwrap_or(0)
}

/// One reading's three words, as on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Reading {
    /// The return's strength.
    pub intensity: u16,
    /// The distance word: millimetres, 0 for no return (bits 15 and 14 are flags to `lds2d`).
    pub distance: u16,
    /// Reserved, 0.
    pub reserved: u16,
}

/// One packet: six consecutive degrees and the motor speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Packet {
    /// Its place in the revolution, 0..60 (the index byte less `0xA0`): degrees `6 * index`
    /// onwards.
    pub index: u8,
    /// Motor speed, tenths of an rpm.
    pub rpm_tenths: u16,
    /// The readings of degrees `6 * index + slot`.
    pub readings: [Reading; READINGS_PER_PACKET],
}

impl Packet {
    /// The 42 bytes, checksum included (the index taken modulo 60).
    #[must_use]
    pub fn encode(&self) -> [u8; PACKET_LEN] {
        let mut bytes = [0; PACKET_LEN];
        bytes[0] = START_BYTE;
        bytes[1] = INDEX_BASE + self.index % PACKETS_PER_REVOLUTION as u8;
        bytes[2..4].copy_from_slice(&self.rpm_tenths.to_le_bytes());
        for (chunk, r) in bytes[4..CHECKSUM_OFFSET]
            .chunks_exact_mut(6)
            .zip(&self.readings)
        {
            chunk[0..2].copy_from_slice(&r.intensity.to_le_bytes());
            chunk[2..4].copy_from_slice(&r.distance.to_le_bytes());
            chunk[4..6].copy_from_slice(&r.reserved.to_le_bytes());
        }
        let sum = checksum(&bytes);
        bytes[CHECKSUM_OFFSET..].copy_from_slice(&sum.to_le_bytes());
        bytes
    }

    /// Parses 42 bytes; `None` unless the start byte, the index and the checksum hold.
    #[must_use]
    pub fn decode(bytes: &[u8; PACKET_LEN]) -> Option<Self> {
        let stored = u16::from_le_bytes([bytes[CHECKSUM_OFFSET], bytes[CHECKSUM_OFFSET + 1]]);
        if bytes[0] != START_BYTE || !is_index_byte(bytes[1]) || checksum(bytes) != stored {
            return None;
        }
        let word = |at: usize| u16::from_le_bytes([bytes[at], bytes[at + 1]]);
        Some(Self {
            index: bytes[1] - INDEX_BASE,
            rpm_tenths: word(2),
            readings: std::array::from_fn(|i| Reading {
                intensity: word(4 + 6 * i),
                distance: word(6 + 6 * i),
                reserved: word(8 + 6 * i),
            }),
        })
    }
}

fn is_index_byte(byte: u8) -> bool {
    (INDEX_BASE..INDEX_BASE + PACKETS_PER_REVOLUTION as u8).contains(&byte)
}

/// Collects a whole-degree unit's readings into packets of `N` consecutive degrees; shared with
/// the LDS02RR, whose packets are the XV-11's four degrees.
#[derive(Debug, Clone)]
pub(crate) struct DegreePackets<const N: usize> {
    packet: Option<u32>,
    slots: [Option<UnitReading>; N],
}

impl<const N: usize> Default for DegreePackets<N> {
    fn default() -> Self {
        Self {
            packet: None,
            slots: [None; N],
        }
    }
}

impl<const N: usize> DegreePackets<N> {
    /// Places `reading` by its degree (its index in the revolution); calls `emit` with a
    /// packet's number and slots when its last degree is in, or when a reading of another packet
    /// arrives first (the missing slots then `None`).
    pub(crate) fn push(
        &mut self,
        reading: &UnitReading,
        mut emit: impl FnMut(u32, &[Option<UnitReading>; N]),
    ) {
        // N is 4 or 6: the cast is exact.
        let n = N as u32;
        let degree = reading.index % 360;
        let (packet, slot) = (degree / n, (degree % n) as usize);
        if let Some(current) = self.packet.filter(|&current| current != packet) {
            emit(current, &self.slots);
            self.clear();
        }
        self.packet = Some(packet);
        self.slots[slot] = Some(*reading);
        if slot == N - 1 {
            emit(packet, &self.slots);
            self.clear();
        }
    }

    /// Forgets a packet in the making.
    pub(crate) fn clear(&mut self) {
        self.packet = None;
        self.slots = [None; N];
    }
}

/// When a packet of these slots is due, the speed it reports (Hz), and whether it starts a
/// revolution: its last reading's instant, its first reading's rate.
pub(crate) fn packet_timing<const N: usize>(slots: &[Option<UnitReading>; N]) -> (f64, f64, bool) {
    let mut present = slots.iter().flatten();
    let first = present.next();
    let last = present.next_back().or(first);
    (
        last.map_or(0.0, |r| r.t_s),
        first.map_or(0.0, |r| r.rev_hz),
        slots.iter().flatten().any(|r| r.starts_revolution),
    )
}

/// The LDS-01's side: six degrees a packet while its motor runs.
#[derive(Debug, Clone)]
pub struct Lds01Unit {
    scanning: bool,
    pending: DegreePackets<READINGS_PER_PACKET>,
}

impl Default for Lds01Unit {
    fn default() -> Self {
        Self::new()
    }
}

impl Lds01Unit {
    /// A unit of the current firmware: streaming from power-on, `e` stops it, `b` restarts it.
    #[must_use]
    pub fn new() -> Self {
        Self {
            scanning: true,
            pending: DegreePackets::default(),
        }
    }

    /// A unit of the firmware before 2017.10: silent until the host sends `b`.
    #[must_use]
    pub fn awaiting_start() -> Self {
        Self {
            scanning: false,
            ..Self::new()
        }
    }

    fn packet(index: u32, slots: &[Option<UnitReading>; READINGS_PER_PACKET]) -> Packet {
        let (_, rev_hz, _) = packet_timing(slots);
        Packet {
            index: u8::try_from(index).unwrap_or(0),
            // `as` from f64 saturates and maps NaN to 0: the field carries no more.
            rpm_tenths: (rev_hz * 60.0 * RPM_SCALE).round() as u16,
            readings: slots.map(|slot| {
                slot.map_or(Reading::default(), |r| Reading {
                    intensity: u16::from(r.intensity),
                    distance: u16::try_from(r.distance_mm)
                        .unwrap_or(u16::MAX)
                        .min(MAX_DISTANCE_MM),
                    reserved: 0,
                })
            }),
        }
    }
}

impl Unit for Lds01Unit {
    fn host_wrote(&mut self, bytes: &[u8], _now_s: f64, _out: &mut Output) {
        for &byte in bytes {
            match byte {
                START_COMMAND => self.scanning = true,
                STOP_COMMAND => {
                    self.scanning = false;
                    self.pending.clear();
                }
                // Anything else is no command; the unit ignores it.
                _ => {}
            }
        }
    }

    fn scanning(&self) -> bool {
        self.scanning
    }

    fn push(&mut self, reading: &UnitReading, out: &mut Output) {
        if !self.scanning {
            return;
        }
        self.pending.push(reading, |index, slots| {
            let (due_s, _, starts_revolution) = packet_timing(slots);
            let packet = Self::packet(index, slots);
            out.packet(due_s, 2, starts_revolution, |bytes| {
                bytes.extend_from_slice(&packet.encode());
            });
        });
    }
}

/// The host's side: bytes into points, resynchronising on the next `0xFA` + index after damage
/// (on a bad checksum only the start byte is dropped and the rest rescanned, as `lds2d` does).
#[derive(Debug, Clone)]
pub struct Lds01Decoder {
    framer: SyncFramer<PACKET_LEN>,
}

impl Default for Lds01Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Lds01Decoder {
    /// A decoder that has seen nothing.
    #[must_use]
    pub fn new() -> Self {
        Self {
            framer: SyncFramer::new(START_BYTE, is_index_byte),
        }
    }

    /// Takes one byte; returns the packet it completes, if any.
    pub fn push(&mut self, byte: u8) -> Option<Packet> {
        self.framer.push(byte, Packet::decode)
    }

    /// Bytes held for a packet not complete yet, 0..=41.
    #[must_use]
    pub fn pending_len(&self) -> usize {
        self.framer.pending_len()
    }
}

impl HostDecoder for Lds01Decoder {
    fn feed(&mut self, bytes: &[u8], out: &mut Vec<Point>) {
        for &byte in bytes {
            let Some(packet) = self.push(byte) else {
                continue;
            };
            let rev_hz = f64::from(packet.rpm_tenths) / RPM_SCALE / 60.0;
            for (slot, r) in packet.readings.iter().enumerate() {
                let degree = usize::from(packet.index) * READINGS_PER_PACKET + slot;
                out.push(Point {
                    angle_deg: degree as f64,
                    // A flagged word is no distance, as `lds2d` reads it.
                    distance_mm: if r.distance & INVALID_FLAG != 0 {
                        0
                    } else {
                        u32::from(r.distance & MAX_DISTANCE_MM)
                    },
                    intensity: r.intensity,
                    starts_revolution: degree == 0,
                    rev_hz: Some(rev_hz),
                });
            }
        }
    }

    fn stats(&self) -> DecodeStats {
        self.framer.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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
                intensity: (index % 256) as u8,
                rev_hz,
                starts_revolution: index == 0,
            })
            .collect()
    }

    fn push_all(unit: &mut Lds01Unit, readings: &[UnitReading]) -> Output {
        let mut out = Output::new();
        for r in readings {
            unit.push(r, &mut out);
        }
        out
    }

    fn decode_all(bytes: &[u8]) -> (Vec<Point>, DecodeStats) {
        let mut decoder = Lds01Decoder::new();
        let mut points = Vec::new();
        decoder.feed(bytes, &mut points);
        (points, decoder.stats())
    }

    #[test]
    fn packet_matches_the_checksum_lds2d_computes() {
        let packet = Packet {
            index: 15,
            rpm_tenths: 3000,
            readings: std::array::from_fn(|i| Reading {
                intensity: 100 + i as u16,
                distance: 1000 + i as u16,
                reserved: 0,
            }),
        };
        let bytes = packet.encode();
        assert_eq!(
            &bytes[..8],
            &[0xFA, 0xAF, 0xB8, 0x0B, 0x64, 0x00, 0xE8, 0x03]
        );
        // lds2d.drivers.hitachi_lg_hls_lfcd2.calc_checksum(bytes[:40]) of this packet.
        assert_eq!(checksum(&bytes), LDS2D_CHECKSUM_OF_VECTOR);
        assert_eq!(Packet::decode(&bytes), Some(packet));
    }
    const LDS2D_CHECKSUM_OF_VECTOR: u16 = 0x51D5;

    #[test]
    fn revolution_round_trips_as_60_packets() {
        let readings = revolution(3, 5.0, |i| if i % 7 == 0 { 0 } else { 120 + 9 * i });
        let mut unit = Lds01Unit::new();
        let out = push_all(&mut unit, &readings);
        assert_eq!(out.packets.len(), PACKETS_PER_REVOLUTION);
        for (k, (bytes, span)) in out.iter().enumerate() {
            assert_eq!(bytes[1], INDEX_BASE + k as u8);
            assert_eq!(span.due_s, readings[6 * k + 5].t_s);
            assert_eq!(span.starts_revolution, k == 0);
            assert_eq!(span.sync_len, 2);
        }
        let (points, stats) = decode_all(&out.bytes);
        assert_eq!(
            (stats.packets, stats.bad_checksum, stats.skipped_bytes),
            (60, 0, 0)
        );
        for (r, p) in readings.iter().zip(&points) {
            assert_eq!(p.angle_deg, r.angle_deg);
            assert_eq!(p.distance_mm, r.distance_mm);
            assert_eq!(p.intensity, u16::from(r.intensity));
            assert_eq!(p.starts_revolution, r.starts_revolution);
            assert_eq!(p.rev_hz, Some(5.0));
        }
    }

    #[test]
    fn speed_field_is_tenths_of_an_rpm() {
        let readings = revolution(0, 5.01, |_| 1000);
        let out = push_all(&mut Lds01Unit::new(), &readings[..6]);
        assert_eq!(u16::from_le_bytes([out.bytes[2], out.bytes[3]]), 3006);
    }

    #[test]
    fn e_stops_and_b_restarts_the_stream() {
        let readings = revolution(0, 5.0, |_| 800);
        let mut unit = Lds01Unit::new();
        assert!(unit.scanning());
        let mut out = push_all(&mut unit, &readings[..9]);
        assert_eq!(out.packets.len(), 1);
        // Garbage around the command, and a half-made packet dropped when it stops.
        unit.host_wrote(b"xx\ne", 0.1, &mut out);
        assert!(!unit.scanning());
        assert_eq!(out.packets.len(), 1, "no reply");
        out.bytes
            .extend(push_all(&mut unit, &readings[9..120]).bytes);
        assert_eq!(out.bytes.len(), PACKET_LEN);
        unit.host_wrote(b"b", 0.2, &mut out);
        assert!(unit.scanning());
        let resumed = push_all(&mut unit, &readings[120..]);
        assert_eq!(resumed.packets.len(), 40);
        assert_eq!(resumed.bytes[1], INDEX_BASE + 20);
    }

    #[test]
    fn older_firmware_waits_for_b() {
        let readings = revolution(0, 5.0, |_| 800);
        let mut unit = Lds01Unit::awaiting_start();
        assert!(push_all(&mut unit, &readings).is_empty());
        unit.host_wrote(b"b", 0.0, &mut Output::new());
        assert_eq!(push_all(&mut unit, &readings).packets.len(), 60);
    }

    #[test]
    fn missing_degrees_leave_no_returns_in_their_slots() {
        let mut readings = revolution(0, 5.0, |_| 900);
        readings.remove(8);
        let out = push_all(&mut Lds01Unit::new(), &readings[..12]);
        let (points, _) = decode_all(&out.bytes);
        assert_eq!(points.len(), 12);
        assert_eq!(points[8].distance_mm, 0);
        assert_eq!(points[9].distance_mm, 900);
    }

    #[test]
    fn distances_are_clamped_below_the_flag_bits() {
        let readings = revolution(0, 5.0, |_| 40_000);
        let out = push_all(&mut Lds01Unit::new(), &readings[..6]);
        let (points, _) = decode_all(&out.bytes);
        assert!(points
            .iter()
            .all(|p| p.distance_mm == u32::from(MAX_DISTANCE_MM)));
    }

    #[test]
    fn damaged_stream_resynchronises_and_counts() {
        let out = push_all(&mut Lds01Unit::new(), &revolution(0, 5.0, |i| 200 + i));
        let mut wire = vec![0xFA, 0xFA, 0xA1, 0x00];
        wire.extend_from_slice(&out.bytes[..PACKET_LEN]);
        let mut bad = out.bytes[PACKET_LEN..2 * PACKET_LEN].to_vec();
        bad[30] ^= 0x01;
        wire.extend_from_slice(&bad);
        wire.extend_from_slice(&out.bytes[2 * PACKET_LEN..3 * PACKET_LEN - 5]);
        wire.extend_from_slice(&out.bytes[3 * PACKET_LEN..4 * PACKET_LEN]);
        let (points, stats) = decode_all(&wire);
        assert_eq!(stats.packets, 2);
        assert!(stats.bad_checksum >= 2);
        assert_eq!(stats.bytes, 2 * PACKET_LEN as u64 + stats.skipped_bytes);
        let angles: Vec<f64> = points.iter().map(|p| p.angle_deg).collect();
        assert_eq!(&angles[..6], &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(angles[6], 18.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x01D5_0001),
            failure_persistence: None,
            cases: 256,
            ..ProptestConfig::default()
        })]

        #[test]
        fn random_readings_survive_the_round_trip(
            rev_hz in 4.8f64..5.2,
            values in proptest::collection::vec((0u32..=20_000, any::<u8>()), 360),
        ) {
            let mut readings = revolution(1, rev_hz, |_| 0);
            for (r, (d, i)) in readings.iter_mut().zip(&values) {
                r.distance_mm = *d;
                r.intensity = *i;
            }
            let out = push_all(&mut Lds01Unit::new(), &readings);
            let (points, stats) = decode_all(&out.bytes);
            prop_assert_eq!(stats.packets, 60);
            for (r, p) in readings.iter().zip(&points) {
                prop_assert_eq!(p.angle_deg, r.angle_deg);
                prop_assert_eq!(p.distance_mm, r.distance_mm.min(u32::from(MAX_DISTANCE_MM)));
                prop_assert_eq!(p.intensity, u16::from(r.intensity));
                prop_assert!((p.rev_hz.unwrap_or(0.0) - rev_hz).abs() < 0.1 / 60.0);
            }
        }

        #[test]
        fn random_bytes_never_panic_and_chunks_agree(
            bytes in proptest::collection::vec(any::<u8>(), 0..600),
            chunk in 1usize..64,
        ) {
            let (points, stats) = decode_all(&bytes);
            let mut decoder = Lds01Decoder::new();
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
            prop_assert_eq!(points.len() as u64, 6 * stats.packets);
        }

        #[test]
        fn random_host_bytes_keep_the_unit_bounded(
            writes in proptest::collection::vec(proptest::collection::vec(any::<u8>(), 0..32), 0..16),
        ) {
            let mut unit = Lds01Unit::new();
            let mut out = Output::new();
            let mut expected = true;
            for w in &writes {
                unit.host_wrote(w, 0.0, &mut out);
                if let Some(&last) = w.iter().rev().find(|&&b| b == b'b' || b == b'e') {
                    expected = last == b'b';
                }
                prop_assert_eq!(unit.scanning(), expected);
            }
            prop_assert!(out.is_empty());
        }
    }
}
