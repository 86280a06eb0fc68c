//! Just enough of the Neato XV-11 lidar stream for this firmware: packets of 22 bytes (`FA`,
//! index `A0`..`F9`, rpm × 64, four readings, checksum), resynchronising after anything
//! unexpected, counting gaps in the index sequence.

/// Bytes in a packet.
const PACKET_LEN: usize = 22;
/// Packets in a revolution.
const PACKETS: usize = 90;

/// One complete revolution: distance in millimetres by angle (counter-clockwise, the ROS
/// driver's convention), `None` where the reading is flagged invalid.
pub type Scan = [Option<u16>; 360];

/// Decodes the byte stream into revolutions.
pub struct Decoder {
    pending: Vec<u8>,
    scan: Scan,
    packets_in_scan: usize,
    last_index: Option<usize>,
    /// Discontinuities in the packet index sequence (a packet that is not the successor of the
    /// previous one).
    pub index_gaps: u64,
    /// Candidate packets whose checksum failed.
    pub bad_checksums: u64,
    /// Complete revolutions decoded.
    pub revolutions: u64,
}

impl Decoder {
    pub fn new() -> Self {
        Self {
            pending: Vec::with_capacity(4096),
            scan: [None; 360],
            packets_in_scan: 0,
            last_index: None,
            index_gaps: 0,
            bad_checksums: 0,
            revolutions: 0,
        }
    }

    /// Takes bytes from the port; calls `on_scan` for every revolution they complete (one whose
    /// 90 packets all arrived in order).
    pub fn feed(&mut self, bytes: &[u8], mut on_scan: impl FnMut(&Scan)) {
        self.pending.extend_from_slice(bytes);
        let mut at = 0;
        while self.pending.len() - at >= PACKET_LEN {
            let candidate = &self.pending[at..at + PACKET_LEN];
            let index = candidate[1].wrapping_sub(0xA0);
            if candidate[0] != 0xFA || usize::from(index) >= PACKETS {
                at += 1;
                continue;
            }
            if checksum(candidate) != u16::from_le_bytes([candidate[20], candidate[21]]) {
                self.bad_checksums += 1;
                at += 1;
                continue;
            }
            let mut packet = [0u8; PACKET_LEN];
            packet.copy_from_slice(candidate);
            at += PACKET_LEN;
            if self.packet(&packet) {
                on_scan(&self.scan);
            }
        }
        self.pending.drain(..at);
    }

    /// Takes one good packet; `true` when it completes a revolution.
    fn packet(&mut self, packet: &[u8; PACKET_LEN]) -> bool {
        let index = usize::from(packet[1] - 0xA0);
        if let Some(last) = self.last_index {
            if index != (last + 1) % PACKETS {
                self.index_gaps += 1;
            }
        }
        if index == 0 || self.last_index.map(|l| index != l + 1).unwrap_or(true) {
            // A revolution starts afresh at index 0 (or restarts after a gap).
            self.packets_in_scan = 0;
        }
        self.last_index = Some(index);
        for slot in 0..4 {
            let r = &packet[4 + 4 * slot..8 + 4 * slot];
            let invalid = r[1] & 0x80 != 0;
            let distance = u16::from(r[0]) | (u16::from(r[1] & 0x3F) << 8);
            self.scan[index * 4 + slot] = (!invalid).then_some(distance);
        }
        self.packets_in_scan += 1;
        if index == PACKETS - 1 && self.packets_in_scan == PACKETS {
            self.revolutions += 1;
            return true;
        }
        false
    }
}

/// The XV-11 checksum over the first 20 bytes.
fn checksum(packet: &[u8]) -> u16 {
    let mut acc: u32 = 0;
    for word in packet[..20].chunks_exact(2) {
        acc = (acc << 1) + u32::from(u16::from_le_bytes([word[0], word[1]]));
    }
    ((acc & 0x7FFF) + (acc >> 15)) as u16 & 0x7FFF
}

/// The distance straight ahead: the median of the valid readings within `half_width_deg` of
/// angle 0; `None` with fewer than three.
pub fn front_mm(scan: &Scan, half_width_deg: usize) -> Option<u16> {
    let mut near: Vec<u16> = (0..=2 * half_width_deg)
        .map(|k| (360 + k - half_width_deg) % 360)
        .filter_map(|angle| scan[angle])
        .filter(|&d| d > 0)
        .collect();
    if near.len() < 3 {
        return None;
    }
    near.sort_unstable();
    Some(near[near.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The worked example of the protocol note (index 0xA0, 300 rpm).
    const WORKED: [u8; PACKET_LEN] = [
        0xFA, 0xA0, 0x00, 0x4B, 0xE8, 0x03, 0x23, 0x01, 0xDC, 0x05, 0xC8, 0x00, 0x35, 0x80, 0x00,
        0x00, 0xB8, 0x4B, 0x10, 0x00, 0x11, 0x15,
    ];

    fn packet(index: usize, distance: u16) -> [u8; PACKET_LEN] {
        let mut p = [0u8; PACKET_LEN];
        p[0] = 0xFA;
        p[1] = 0xA0 + index as u8;
        p[2..4].copy_from_slice(&(300u16 * 64).to_le_bytes());
        for slot in 0..4 {
            p[4 + 4 * slot..6 + 4 * slot].copy_from_slice(&distance.to_le_bytes());
        }
        let sum = checksum(&p);
        p[20..].copy_from_slice(&sum.to_le_bytes());
        p
    }

    #[test]
    fn checksum_matches_the_worked_example() {
        assert_eq!(checksum(&WORKED), 0x1511);
    }

    #[test]
    fn whole_revolutions_resync_and_gaps() {
        let mut d = Decoder::new();
        let mut bytes = vec![0x00, 0xFA, 0x13];
        for index in 0..PACKETS {
            bytes.extend_from_slice(&packet(index, 1000));
        }
        let mut scans = 0;
        // Split at an awkward place.
        d.feed(&bytes[..100], |_| scans += 1);
        d.feed(&bytes[100..], |s| {
            scans += 1;
            assert_eq!(front_mm(s, 5), Some(1000));
        });
        assert_eq!((scans, d.index_gaps, d.bad_checksums), (1, 0, 0));
        // Packet 5 of the next revolution is lost.
        let mut bytes = Vec::new();
        for index in (0..PACKETS).filter(|&i| i != 5) {
            bytes.extend_from_slice(&packet(index, 700));
        }
        d.feed(&bytes, |_| scans += 1);
        assert_eq!((scans, d.index_gaps), (1, 1));
    }
}
