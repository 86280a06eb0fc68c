//! The host's side: descriptors, replies, nodes and capsules back into readings.

use super::express::{Capsule, CAPSULE_LEN};
use super::node::{Node, NODE_LEN};
use super::{answer, DESCRIPTOR_LEN, SYNC_BYTE, SYNC_BYTE2};
use crate::{DecodeStats, HostDecoder, Point};

/// The longest single reply whose descriptor is believed (the A1's longest is GET_INFO's 20
/// bytes; a longer one is taken for damage).
const MAX_REPLY_LEN: u32 = 255;

/// Which stream the bytes after a reply belong to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stream {
    Nodes,
    Capsules,
}

/// Decodes what an RPLIDAR A1 sends: response descriptors, single replies (skipped), the
/// standard scan's nodes and the express scan's capsules.
///
/// Before any descriptor the bytes are taken for nodes (a capture may start mid-scan). A
/// descriptor is recognised where a node or capsule would start: `A5 5A` there is never a
/// valid node (its second byte's check bit is 0), and a descriptor is believed only when its
/// length, mode and type are one the A1 sends. Nodes are checked by their `S`/`!S` and `C`
/// bits, capsules by their sync nibbles and checksum; a failed candidate costs one byte.
/// A capsule's readings come out when the next capsule arrives (their angles need its start
/// angle), as in Slamtec's SDK; a capsule with `S` set restarts that pairing. Express readings
/// start a revolution where their angle wraps past 0°.
#[derive(Debug, Clone)]
pub struct RplidarDecoder {
    pending: Vec<u8>,
    stream: Stream,
    /// Reply bytes still to skip.
    reply_left: u32,
    previous: Option<Capsule>,
    last_express_angle_q6: Option<u16>,
    stats: DecodeStats,
}

impl Default for RplidarDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl RplidarDecoder {
    /// A decoder that has seen nothing.
    #[must_use]
    pub fn new() -> Self {
        Self {
            pending: Vec::with_capacity(CAPSULE_LEN),
            stream: Stream::Nodes,
            reply_left: 0,
            previous: None,
            last_express_angle_q6: None,
            stats: DecodeStats::default(),
        }
    }

    /// Bytes held for a descriptor, node or capsule not complete yet.
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

    /// Decides on the bytes at the front, if there are enough; whether it consumed any.
    fn step(&mut self, out: &mut Vec<Point>) -> bool {
        let p = &self.pending;
        if p.is_empty() || self.reply_left > 0 {
            return false;
        }
        if p[0] == SYNC_BYTE && p.get(1).is_none_or(|&b| b == SYNC_BYTE2) {
            if p.len() < DESCRIPTOR_LEN {
                return false;
            }
            if self.descriptor() {
                return true;
            }
        }
        match self.stream {
            Stream::Nodes => self.node(out),
            Stream::Capsules => self.capsule(out),
        }
    }

    /// Takes a descriptor at the front; whether it was one.
    fn descriptor(&mut self) -> bool {
        let d = &self.pending[..DESCRIPTOR_LEN];
        let word = u32::from_le_bytes([d[2], d[3], d[4], d[5]]);
        let (len, multiple, data_type) = (word & 0x3FFF_FFFF, word >> 30 == 1, d[6]);
        match (multiple, len, data_type) {
            (true, 5, answer::MEASUREMENT) => self.stream = Stream::Nodes,
            (true, 84, answer::CAPSULED) => {
                self.stream = Stream::Capsules;
                self.previous = None;
            }
            (false, 1..=MAX_REPLY_LEN, _) if word >> 30 == 0 => self.reply_left = len,
            _ => return false,
        }
        self.pending.drain(..DESCRIPTOR_LEN);
        if self.reply_left == 0 {
            self.stats.packets += 1;
        }
        // Bytes after the descriptor that were already held belong to the reply.
        while self.reply_left > 0 && !self.pending.is_empty() {
            self.pending.remove(0);
            self.reply_left -= 1;
            if self.reply_left == 0 {
                self.stats.packets += 1;
            }
        }
        true
    }

    fn skip(&mut self, bad: bool) -> bool {
        self.pending.remove(0);
        // A lost capsule leaves the previous one without its successor's start angle.
        self.previous = None;
        self.stats.skipped_bytes += 1;
        if bad {
            self.stats.bad_checksum += 1;
        }
        true
    }

    fn node(&mut self, out: &mut Vec<Point>) -> bool {
        if self.pending.len() < NODE_LEN {
            return false;
        }
        let mut bytes = [0; NODE_LEN];
        bytes.copy_from_slice(&self.pending[..NODE_LEN]);
        let Some(node) = Node::decode(&bytes) else {
            return self.skip(true);
        };
        self.pending.drain(..NODE_LEN);
        self.stats.packets += 1;
        out.push(Point {
            angle_deg: node.angle_deg() % 360.0,
            distance_mm: node.distance_mm(),
            intensity: u16::from(node.quality),
            starts_revolution: node.start,
            rev_hz: None,
        });
        true
    }

    fn capsule(&mut self, out: &mut Vec<Point>) -> bool {
        if self.pending.len() >= 2 && !Capsule::is_sync(self.pending[0], self.pending[1]) {
            return self.skip(false);
        }
        if self.pending.len() < CAPSULE_LEN {
            return false;
        }
        let mut bytes = [0; CAPSULE_LEN];
        bytes.copy_from_slice(&self.pending[..CAPSULE_LEN]);
        let Some(capsule) = Capsule::decode(&bytes) else {
            return self.skip(true);
        };
        self.pending.drain(..CAPSULE_LEN);
        self.stats.packets += 1;
        if let Some(previous) = self.previous.filter(|_| !capsule.start) {
            let angles = previous.angles_q6(capsule.start_angle_q6);
            for (k, &angle) in angles.iter().enumerate() {
                let wrapped = self
                    .last_express_angle_q6
                    .is_some_and(|last| angle < last && last - angle > 180 * 64);
                self.last_express_angle_q6 = Some(angle);
                out.push(Point {
                    angle_deg: f64::from(angle) / 64.0,
                    distance_mm: u32::from(previous.cabins[k / 2].distance_mm[k % 2]),
                    intensity: 0,
                    starts_revolution: wrapped,
                    rev_hz: None,
                });
            }
        }
        self.previous = Some(capsule);
        true
    }
}

impl HostDecoder for RplidarDecoder {
    fn feed(&mut self, bytes: &[u8], out: &mut Vec<Point>) {
        for &byte in bytes {
            self.push(byte, out);
        }
    }

    fn stats(&self) -> DecodeStats {
        self.stats
    }
}
