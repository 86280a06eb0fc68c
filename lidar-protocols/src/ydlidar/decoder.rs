//! The host's side: reply headers and point cloud packets back into readings.

use super::packet::{Packet, HEADER_LEN, PH};
use super::{SYNC_BYTE, SYNC_BYTE2};
use crate::{DecodeStats, HostDecoder, Point};

/// The most samples a packet is believed to hold (the YDLIDAR SDK's `PackageSampleMaxLngth`).
const MAX_LSN: usize = 0x80;
/// Bytes in a reply header.
const HEADER_REPLY_LEN: usize = 7;
/// The longest single reply believed (the X4's longest is the device information's 20 bytes).
const MAX_REPLY_LEN: u32 = 255;

/// Decodes what a YDLIDAR X4 sends: reply headers (`A5 5A`, skipped with their replies) and
/// point cloud packets, with the angle arithmetic of the manual as `lds2d` and the YDLIDAR SDK
/// implement it (including the distance correction).
///
/// A packet is believed when it starts `AA 55`, its LSN is 1–128, FSA's and LSA's check bits
/// are set and its checksum holds; anything else costs one byte. A zero packet's reading starts
/// a revolution and carries the scan rate of its CT.
#[derive(Debug, Clone)]
pub struct YdlidarDecoder {
    pending: Vec<u8>,
    reply_left: u32,
    last_interval: f64,
    stats: DecodeStats,
}

impl Default for YdlidarDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl YdlidarDecoder {
    /// A decoder that has seen nothing.
    #[must_use]
    pub fn new() -> Self {
        Self {
            pending: Vec::with_capacity(HEADER_LEN + 2 * MAX_LSN),
            reply_left: 0,
            last_interval: 0.0,
            stats: DecodeStats::default(),
        }
    }

    /// Bytes held for a header or packet not complete yet.
    #[must_use]
    pub fn pending_len(&self) -> usize {
        self.pending.len()
    }

    fn push(&mut self, byte: u8, out: &mut Vec<Point>) {
        self.stats.bytes += 1;
        if self.reply_left > 0 {
            self.reply_left -= 1;
            if self.reply_left == 0 {
                self.stats.packets += 1;
            }
            return;
        }
        self.pending.push(byte);
        while self.step(out) {}
    }

    fn skip(&mut self, bad: bool) -> bool {
        self.pending.remove(0);
        self.stats.skipped_bytes += 1;
        if bad {
            self.stats.bad_checksum += 1;
        }
        true
    }

    /// Decides on the bytes at the front, if there are enough; whether it consumed any.
    fn step(&mut self, out: &mut Vec<Point>) -> bool {
        let p = &self.pending;
        if p.is_empty() || self.reply_left > 0 {
            return false;
        }
        if p[0] == SYNC_BYTE {
            if p.len() >= 2 && p[1] != SYNC_BYTE2 {
                return self.skip(false);
            }
            if p.len() < HEADER_REPLY_LEN {
                return false;
            }
            let word = u32::from_le_bytes([p[2], p[3], p[4], p[5]]);
            let (len, mode) = (word & 0x3FFF_FFFF, word >> 30);
            match (mode, len) {
                (1, 5) if p[6] == 0x81 => {}
                (0, 1..=MAX_REPLY_LEN) => self.reply_left = len,
                _ => return self.skip(false),
            }
            self.pending.drain(..HEADER_REPLY_LEN);
            if self.reply_left == 0 {
                self.stats.packets += 1;
            }
            return true;
        }
        if p[0] != PH.to_le_bytes()[0] || (p.len() >= 2 && p[1] != PH.to_le_bytes()[1]) {
            return self.skip(false);
        }
        if p.len() < HEADER_LEN {
            return false;
        }
        let (ct, lsn) = (p[2], usize::from(p[3]));
        if lsn == 0 || lsn > MAX_LSN || p[4] & 1 == 0 || p[6] & 1 == 0 {
            return self.skip(true);
        }
        let total = HEADER_LEN + 2 * lsn;
        if p.len() < total {
            return false;
        }
        let word = |i: usize| u16::from_le_bytes([p[i], p[i + 1]]);
        let (fsa, lsa, cs) = (word(4), word(6), word(8));
        let samples: Vec<u16> = (0..lsn).map(|i| word(HEADER_LEN + 2 * i)).collect();
        // LSN is 1..=128, so it fits its byte.
        if Packet::checksum(ct, lsn as u8, fsa, lsa, &samples) != cs {
            return self.skip(true);
        }
        self.pending.drain(..total);
        self.stats.packets += 1;
        let packet = Packet {
            ct,
            fsa_q6: fsa >> 1,
            lsa_q6: lsa >> 1,
            samples,
        };
        let zero = ct & 1 == 1;
        let angles = packet.angles_q6(&mut self.last_interval);
        for (&sample, angle) in packet.samples.iter().zip(angles) {
            out.push(Point {
                angle_deg: (angle / 64.0) % 360.0,
                distance_mm: u32::from(sample) / 4,
                intensity: 0,
                starts_revolution: zero,
                rev_hz: zero.then(|| f64::from(ct >> 1) / 10.0),
            });
        }
        true
    }
}

impl HostDecoder for YdlidarDecoder {
    fn feed(&mut self, bytes: &[u8], out: &mut Vec<Point>) {
        for &byte in bytes {
            self.push(byte, out);
        }
    }

    fn stats(&self) -> DecodeStats {
        self.stats
    }
}
