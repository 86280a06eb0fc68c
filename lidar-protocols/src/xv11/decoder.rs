//! The streaming decoder: bytes in, checksummed packets out, resynchronising after any damage.

use super::packet::{
    is_index_byte, Packet, PacketError, PACKETS_PER_REVOLUTION, PACKET_LEN, START_BYTE,
};

/// What a [`Decoder`] has seen so far.
///
/// At any moment `bytes == 22 * packets + skipped_bytes + Decoder::pending_len()`; after
/// [`Decoder::finish`] the pending bytes are counted as skipped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct DecoderStats {
    /// Bytes pushed.
    pub bytes: u64,
    /// Packets accepted: start byte, index in `0xA0..=0xF9`, checksum good.
    pub packets: u64,
    /// Candidates (start byte followed by a valid index, 22 bytes available) whose checksum
    /// failed. Each offset is a candidate at most once.
    pub bad_checksum: u64,
    /// Bytes that are part of no accepted packet.
    pub skipped_bytes: u64,
    /// Accepted packets whose index is not the previous accepted one's plus 1 (mod 90); the
    /// first packet of the stream is never a gap.
    pub index_gaps: u64,
    /// Packets missing at those gaps, `(index - previous - 1) mod 90` summed: a lower bound,
    /// since a gap of a whole revolution or more cannot be told from a shorter one.
    pub missing_packets: u64,
}

/// Turns a byte stream into packets, one byte at a time.
///
/// It keeps a window of at most 22 bytes that starts with `0xFA` and a valid index byte. When
/// 22 bytes are in and the checksum holds, the packet is returned and the window emptied. When
/// the checksum fails, only the start byte is dropped: the 21 bytes after it are rescanned for
/// the next `0xFA` + valid index, so a packet that begins inside a damaged one is still found.
/// The outcome is the same as trying every offset of the stream in order and jumping 22 bytes
/// past each packet accepted. A packet whose checksum fails is never returned.
///
/// ```
/// use hilsim_lidar_protocols::xv11::{Decoder, Packet};
///
/// let mut wire = vec![0xFA, 0xA3, 0x00]; // a torn packet
/// wire.extend_from_slice(&Packet { index: 4, ..Packet::default() }.encode());
/// let mut decoder = Decoder::new();
/// let packets: Vec<Packet> = decoder.feed(&wire).collect();
/// assert_eq!(packets.len(), 1);
/// assert_eq!(packets[0].index, 4);
/// let stats = decoder.finish();
/// assert_eq!((stats.packets, stats.skipped_bytes), (1, 3));
/// ```
#[derive(Debug, Clone)]
pub struct Decoder {
    /// `window[..len]` is a packet in the making: `window[0] == 0xFA` when `len >= 1` and
    /// `window[1]` is a valid index when `len >= 2`.
    window: [u8; PACKET_LEN],
    len: usize,
    previous_index: Option<u8>,
    stats: DecoderStats,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Decoder {
    /// A decoder that has seen nothing.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            window: [0; PACKET_LEN],
            len: 0,
            previous_index: None,
            stats: DecoderStats {
                bytes: 0,
                packets: 0,
                bad_checksum: 0,
                skipped_bytes: 0,
                index_gaps: 0,
                missing_packets: 0,
            },
        }
    }

    /// Takes the next byte of the stream; returns the packet it completes, if any.
    pub fn push(&mut self, byte: u8) -> Option<Packet> {
        self.stats.bytes += 1;
        match self.len {
            0 => self.start_or_skip(byte),
            1 if is_index_byte(byte) => {
                self.window[1] = byte;
                self.len = 2;
            }
            1 => {
                // A start byte without an index: drop it, but `byte` may itself start a packet.
                self.stats.skipped_bytes += 1;
                self.len = 0;
                self.start_or_skip(byte);
            }
            _ => {
                self.window[self.len] = byte;
                self.len += 1;
                if self.len == PACKET_LEN {
                    return self.check_window();
                }
            }
        }
        None
    }

    /// Pushes `bytes` and yields the packets they complete.
    ///
    /// Lazy: a byte is pushed only when the iterator is advanced that far, so consume it.
    pub fn feed<'a>(&'a mut self, bytes: &'a [u8]) -> impl Iterator<Item = Packet> + 'a {
        bytes.iter().filter_map(move |&byte| self.push(byte))
    }

    /// The counts so far (the bytes of an unfinished packet are in neither `packets` nor
    /// `skipped_bytes` yet).
    #[must_use]
    pub const fn stats(&self) -> &DecoderStats {
        &self.stats
    }

    /// Bytes held for a packet that is not complete yet, 0..=21.
    #[must_use]
    pub const fn pending_len(&self) -> usize {
        self.len
    }

    /// Ends the stream: the bytes of an unfinished packet are counted as skipped, so that
    /// `bytes == 22 * packets + skipped_bytes`.
    #[must_use]
    pub fn finish(mut self) -> DecoderStats {
        self.stats.skipped_bytes += self.len as u64;
        self.stats
    }

    fn start_or_skip(&mut self, byte: u8) {
        if byte == START_BYTE {
            self.window[0] = byte;
            self.len = 1;
        } else {
            self.stats.skipped_bytes += 1;
        }
    }

    fn check_window(&mut self) -> Option<Packet> {
        match Packet::decode(&self.window) {
            Ok(packet) => {
                self.len = 0;
                self.accept(&packet);
                Some(packet)
            }
            Err(err) => {
                // The window invariant leaves only the checksum to fail; count nothing else.
                if matches!(err, PacketError::BadChecksum { .. }) {
                    self.stats.bad_checksum += 1;
                }
                self.resync();
                None
            }
        }
    }

    /// Drops the failed candidate's start byte and whatever follows up to the next possible
    /// start (`0xFA` then a valid index, or a `0xFA` as the last byte, whose index is still to
    /// come); keeps the rest of the window.
    fn resync(&mut self) {
        let next_start = (1..PACKET_LEN)
            .find(|&at| {
                self.window[at] == START_BYTE
                    && self
                        .window
                        .get(at + 1)
                        .is_none_or(|&next| is_index_byte(next))
            })
            .unwrap_or(PACKET_LEN);
        self.stats.skipped_bytes += next_start as u64;
        self.window.copy_within(next_start.., 0);
        self.len = PACKET_LEN - next_start;
    }

    fn accept(&mut self, packet: &Packet) {
        self.stats.packets += 1;
        if let Some(previous) = self.previous_index {
            let expected = (previous + 1) % PACKETS_PER_REVOLUTION as u8;
            if packet.index != expected {
                self.stats.index_gaps += 1;
                let missing = (usize::from(packet.index) + PACKETS_PER_REVOLUTION
                    - usize::from(expected))
                    % PACKETS_PER_REVOLUTION;
                self.stats.missing_packets += missing as u64;
            }
        }
        self.previous_index = Some(packet.index);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::xv11::Reading;

    fn packet(index: u8, tag: u16) -> Packet {
        Packet {
            index,
            rpm_fixed: 300 * 64,
            readings: [Reading::distance(tag, 100); 4],
        }
    }

    fn decode_all(bytes: &[u8]) -> (Vec<Packet>, DecoderStats) {
        let mut decoder = Decoder::new();
        let packets = decoder.feed(bytes).collect();
        (packets, decoder.finish())
    }

    #[test]
    fn clean_stream_decodes_every_packet_and_skips_nothing() {
        let sent: Vec<Packet> = (0..200).map(|i| packet((i % 90) as u8, i)).collect();
        let wire: Vec<u8> = sent.iter().flat_map(Packet::encode).collect();
        let (packets, stats) = decode_all(&wire);
        assert_eq!(packets, sent);
        assert_eq!(
            stats,
            DecoderStats {
                bytes: wire.len() as u64,
                packets: 200,
                ..DecoderStats::default()
            }
        );
    }

    #[test]
    fn packet_starting_inside_a_failed_candidate_is_found() {
        // A truncated packet (start, index, 5 bytes) runs into a whole one: the candidate made
        // of both fails its checksum, and the real packet starts 7 bytes into that window.
        let good = packet(5, 1234);
        let mut wire = vec![0xFA, 0xA4, 1, 2, 3, 4, 5];
        wire.extend_from_slice(&good.encode());
        let (packets, stats) = decode_all(&wire);
        assert_eq!(packets, vec![good]);
        assert_eq!(stats.bad_checksum, 1);
        assert_eq!(stats.skipped_bytes, 7);
    }

    #[test]
    fn corrupted_checksum_is_rejected_and_counted() {
        let mut bytes = packet(0, 10).encode();
        bytes[21] ^= 0x40;
        let next = packet(1, 11);
        let mut wire = bytes.to_vec();
        wire.extend_from_slice(&next.encode());
        let (packets, stats) = decode_all(&wire);
        assert_eq!(packets, vec![next]);
        assert_eq!(stats.bad_checksum, 1);
        assert_eq!(stats.skipped_bytes, 22);
        assert_eq!(
            stats.index_gaps, 0,
            "the first accepted packet is never a gap"
        );
    }

    #[test]
    fn start_bytes_without_index_and_repeated_starts() {
        let good = packet(7, 77);
        let mut wire = vec![0xFA, 0x00, 0xFA, 0xFA, 0xFA];
        wire.extend_from_slice(&good.encode());
        let (packets, stats) = decode_all(&wire);
        assert_eq!(packets, vec![good]);
        assert_eq!(stats.skipped_bytes, 5);
        assert_eq!(stats.bad_checksum, 0);
    }

    #[test]
    fn index_gaps_count_jumps_and_missing_packets() {
        let sent = [
            packet(88, 0),
            packet(89, 0),
            packet(0, 0),
            packet(3, 0),
            packet(3, 0),
        ];
        let wire: Vec<u8> = sent.iter().flat_map(Packet::encode).collect();
        let (packets, stats) = decode_all(&wire);
        assert_eq!(packets.len(), 5);
        // 0 -> 3 misses 1 and 2; 3 -> 3 is a repeat, counted as 89 missing (a full turn less one).
        assert_eq!(stats.index_gaps, 2);
        assert_eq!(stats.missing_packets, 2 + 89);
    }

    #[test]
    fn unfinished_packet_at_the_end_is_skipped_on_finish() {
        let bytes = packet(2, 2).encode();
        let mut decoder = Decoder::new();
        assert_eq!(decoder.feed(&bytes[..15]).count(), 0);
        assert_eq!(decoder.pending_len(), 15);
        assert_eq!(decoder.stats().skipped_bytes, 0);
        let stats = decoder.finish();
        assert_eq!(
            (stats.bytes, stats.skipped_bytes, stats.bad_checksum),
            (15, 15, 0)
        );
    }

    #[test]
    fn split_feeds_equal_one_feed() {
        let wire: Vec<u8> = (0..30u16)
            .flat_map(|i| packet((i % 90) as u8, i).encode())
            .chain([0xFA, 0xA1, 0x33])
            .collect();
        let (whole, whole_stats) = decode_all(&wire);
        let mut decoder = Decoder::new();
        let mut pieces = Vec::new();
        for chunk in wire.chunks(7) {
            pieces.extend(decoder.feed(chunk));
        }
        assert_eq!(pieces, whole);
        assert_eq!(decoder.finish(), whole_stats);
    }
}
