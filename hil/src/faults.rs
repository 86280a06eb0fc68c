//! The wire's faults of a scenario's `[link]` table, applied packet by packet as the stream
//! writes them (`serve` and `hil` alike), seeded from the run's seed so that a run's faults are
//! the same every time.

use hilsim_lidar_emulator::neato_packet::{checksum, PACKET_LEN};
use hilsim_sim::rng;
use hilsim_sim::scenario::{LinkFaults, SPARSE_BELOW_RPM};
use rand::Rng as _;

/// What the faults did, for the summaries (and `--json`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct FaultCounts {
    /// Packets sent with a flipped byte (their checksum fails).
    pub corrupted_packets: u64,
    /// Packets the unit did not send (at random, or every other one while spinning up slowly).
    pub dropped_packets: u64,
    /// Bytes lost on the wire.
    pub dropped_bytes: u64,
    /// Packets lost while the link was away.
    pub silenced_packets: u64,
}

impl FaultCounts {
    /// One line for people.
    #[must_use]
    pub fn describe(&self) -> String {
        format!(
            "link faults: {} packet(s) corrupted, {} dropped, {} byte(s) dropped, {} packet(s) \
             lost while the link was away",
            self.corrupted_packets, self.dropped_packets, self.dropped_bytes, self.silenced_packets
        )
    }
}

/// The wire's faults with their random stream.
pub struct WireFaults {
    faults: LinkFaults,
    rng: rng::Rng,
    counts: FaultCounts,
}

impl WireFaults {
    /// The faults of a scenario's `[link]` table on the run's `seed`; `None` when none touches
    /// the wire (the stream then goes out as it is, byte for byte).
    #[must_use]
    pub fn new(faults: &LinkFaults, seed: u64) -> Option<Self> {
        let on = faults.corrupt_packet_rate > 0.0
            || faults.dropped_byte_rate > 0.0
            || faults.dropped_packet_rate > 0.0
            || faults.spin_up_s > 0.0
            || faults.silent.is_some();
        on.then(|| Self {
            faults: *faults,
            rng: rng::stream(seed, "link"),
            counts: FaultCounts::default(),
        })
    }

    /// What the faults did so far.
    #[must_use]
    pub fn counts(&self) -> FaultCounts {
        self.counts
    }

    /// Appends to `out` a packet of any unit but the XV-11 (or a command's reply) as the wire
    /// delivers it, for a packet due at simulated time `t_s`: nothing while the link is away (a
    /// reply that never comes) or when the unit drops it, else perhaps with a bit flipped after
    /// its first `sync_len` bytes (whether the host notices is the protocol's business: an
    /// RPLIDAR node has only check bits) and bytes lost.
    pub fn apply_unit_packet(
        &mut self,
        packet: &[u8],
        sync_len: usize,
        t_s: f64,
        out: &mut Vec<u8>,
    ) {
        if self.silent_at(t_s) {
            self.counts.silenced_packets += 1;
            return;
        }
        if self.rng.random::<f64>() < self.faults.dropped_packet_rate {
            self.counts.dropped_packets += 1;
            return;
        }
        let start = out.len();
        out.extend_from_slice(packet);
        if packet.len() > sync_len && self.rng.random::<f64>() < self.faults.corrupt_packet_rate {
            let at = start + self.rng.random_range(sync_len..packet.len());
            out[at] ^= 1 << self.rng.random_range(0..8);
            self.counts.corrupted_packets += 1;
        }
        if self.faults.dropped_byte_rate > 0.0 {
            let mut k = start;
            for i in start..out.len() {
                if self.rng.random::<f64>() < self.faults.dropped_byte_rate {
                    self.counts.dropped_bytes += 1;
                } else {
                    out[k] = out[i];
                    k += 1;
                }
            }
            out.truncate(k);
        }
    }

    fn silent_at(&self, t_s: f64) -> bool {
        self.faults
            .silent
            .is_some_and(|(from, until)| (from..until).contains(&t_s))
    }

    /// Appends to `out` the bytes of `packet` as the wire delivers them, for a packet complete at
    /// simulated time `t_s`: nothing while the link is away or when the unit drops it, else
    /// perhaps with a byte flipped (so that its checksum fails) and bytes lost.
    pub fn apply(&mut self, packet: &[u8], t_s: f64, out: &mut Vec<u8>) {
        if self.silent_at(t_s) {
            self.counts.silenced_packets += 1;
            return;
        }
        if packet.len() != PACKET_LEN {
            out.extend_from_slice(packet);
            return;
        }
        // A unit spinning up too slowly sends every other packet (the odd indices go missing).
        let rpm = f64::from(u16::from_le_bytes([packet[2], packet[3]])) / 64.0;
        let slow = self.faults.spin_up_s > 0.0 && rpm < SPARSE_BELOW_RPM;
        if (slow && packet[1] % 2 == 1)
            || self.rng.random::<f64>() < self.faults.dropped_packet_rate
        {
            self.counts.dropped_packets += 1;
            return;
        }
        let mut bytes: [u8; PACKET_LEN] = [0; PACKET_LEN];
        bytes.copy_from_slice(packet);
        if self.rng.random::<f64>() < self.faults.corrupt_packet_rate {
            // A data byte (not the start byte or the index, which would make it no packet at
            // all); if the checksum happens to survive, its own low byte.
            let at = self.rng.random_range(2..PACKET_LEN - 2);
            bytes[at] ^= 1 << self.rng.random_range(0..8);
            let expected = checksum(&bytes).to_le_bytes();
            if bytes[PACKET_LEN - 2..] == expected {
                bytes[PACKET_LEN - 2] ^= 0x01;
            }
            self.counts.corrupted_packets += 1;
        }
        for &byte in &bytes {
            if self.faults.dropped_byte_rate > 0.0
                && self.rng.random::<f64>() < self.faults.dropped_byte_rate
            {
                self.counts.dropped_bytes += 1;
            } else {
                out.push(byte);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hilsim_lidar_emulator::neato_packet::{Decoder, Packet, Reading};

    fn packets(n: usize) -> Vec<[u8; PACKET_LEN]> {
        (0..n)
            .map(|i| {
                Packet {
                    index: (i % 90) as u8,
                    rpm_fixed: 300 * 64,
                    readings: [Reading::distance(1000 + i as u16, 50); 4],
                }
                .encode()
            })
            .collect()
    }

    #[test]
    fn no_fault_no_wrapper() {
        assert!(WireFaults::new(&LinkFaults::default(), 1).is_none());
    }

    /// 9,000 packets at a 2 % corruption rate: the decoder counts about 180 bad checksums (a
    /// binomial sd of 13: ±4 sd), and the same seed gives the same bytes.
    #[test]
    fn corrupted_packets_fail_their_checksum_at_the_rate_asked() {
        let faults = LinkFaults {
            corrupt_packet_rate: 0.02,
            ..LinkFaults::default()
        };
        let run = |seed| {
            let mut wire = WireFaults::new(&faults, seed).unwrap();
            let mut out = Vec::new();
            for p in packets(9_000) {
                wire.apply(&p, 0.0, &mut out);
            }
            (out, wire.counts())
        };
        let (bytes, counts) = run(7);
        assert_eq!(run(7).0, bytes);
        let mut decoder = Decoder::new();
        let good = decoder.feed(&bytes).count() as u64;
        assert_eq!(good + counts.corrupted_packets, 9_000);
        assert!(
            (128..=232).contains(&counts.corrupted_packets),
            "{counts:?}"
        );
    }

    #[test]
    fn the_link_is_silent_while_away_and_packets_and_bytes_go_missing() {
        let faults = LinkFaults {
            dropped_packet_rate: 0.1,
            dropped_byte_rate: 0.01,
            silent: Some((1.0, 2.0)),
            ..LinkFaults::default()
        };
        let mut wire = WireFaults::new(&faults, 3).unwrap();
        let mut out = Vec::new();
        for (i, p) in packets(3_000).iter().enumerate() {
            wire.apply(p, i as f64 / 1000.0, &mut out);
        }
        let c = wire.counts();
        assert_eq!(c.silenced_packets, 1_000);
        // 2,000 packets: about 200 dropped, and of the rest's 39,600 bytes about 396.
        assert!((140..=260).contains(&c.dropped_packets), "{c:?}");
        assert!((300..=500).contains(&c.dropped_bytes), "{c:?}");
        assert_eq!(
            out.len() as u64,
            (2_000 - c.dropped_packets) * PACKET_LEN as u64 - c.dropped_bytes
        );
    }
}
