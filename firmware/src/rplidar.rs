//! The Slamtec RPLIDAR A1's standard scan, read as a robot's firmware reads it: send SCAN, skip
//! the response descriptor, then take 5-byte measurement nodes, a revolution from one node
//! with its start flag to the next (Slamtec, "RPLIDAR Interface Protocol and Application
//! Notes": the SCAN request and the measurement node).

/// Stop, then start a standard scan: the requests `A5 25` and `A5 20`.
pub const START: [u8; 4] = [0xA5, 0x25, 0xA5, 0x20];
/// The response descriptor of SCAN: 5-byte nodes, sent until STOP.
const DESCRIPTOR: [u8; 7] = [0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81];
const NODE_LEN: usize = 5;

/// One revolution's readings: (angle in degrees, clockwise from the front; distance in mm).
pub type Scan = Vec<(f64, u16)>;

/// A stream reader: descriptor, then nodes; it resynchronises on a node whose check bits fail.
#[derive(Default)]
pub struct Decoder {
    pending: Vec<u8>,
    described: bool,
    scan: Scan,
    /// Nodes refused for their check bits.
    pub bad_nodes: u64,
    /// Revolutions completed.
    pub revolutions: u64,
}

impl Decoder {
    /// Decodes `bytes`, calling `on_scan` with each revolution it completes.
    pub fn feed(&mut self, bytes: &[u8], mut on_scan: impl FnMut(&Scan)) {
        self.pending.extend_from_slice(bytes);
        let mut at = 0;
        if !self.described {
            match self
                .pending
                .windows(DESCRIPTOR.len())
                .position(|w| w == DESCRIPTOR)
            {
                Some(k) => {
                    self.described = true;
                    at = k + DESCRIPTOR.len();
                }
                None => {
                    let keep = self.pending.len().min(DESCRIPTOR.len() - 1);
                    self.pending.drain(..self.pending.len() - keep);
                    return;
                }
            }
        }
        while self.pending.len() - at >= NODE_LEN {
            let node = &self.pending[at..at + NODE_LEN];
            let start = node[0] & 1;
            let inverse = (node[0] >> 1) & 1;
            let check = node[1] & 1;
            if start == inverse || check != 1 {
                self.bad_nodes += 1;
                at += 1;
                continue;
            }
            let angle = f64::from(u16::from_le_bytes([node[1], node[2]]) >> 1) / 64.0;
            let distance_mm = u16::from_le_bytes([node[3], node[4]]) / 4;
            if start == 1 && !self.scan.is_empty() {
                self.revolutions += 1;
                on_scan(&self.scan);
                self.scan.clear();
            }
            self.scan.push((angle, distance_mm));
            at += NODE_LEN;
        }
        self.pending.drain(..at);
    }
}

/// The distance straight ahead: the median of the readings within `half_width_deg` of the
/// front (0°), `None` with fewer than three.
pub fn front_mm(scan: &Scan, half_width_deg: f64) -> Option<u16> {
    let mut near: Vec<u16> = scan
        .iter()
        .filter(|(angle, d)| *d > 0 && (angle.min(360.0 - angle)) <= half_width_deg)
        .map(|&(_, d)| d)
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

    fn node(start: bool, angle_deg: f64, distance_mm: u16) -> [u8; NODE_LEN] {
        let s = u8::from(start);
        let angle = (((angle_deg * 64.0).round() as u16) << 1) | 1;
        let distance = (distance_mm * 4).to_le_bytes();
        let a = angle.to_le_bytes();
        [
            (20 << 2) | ((1 - s) << 1) | s,
            a[0],
            a[1],
            distance[0],
            distance[1],
        ]
    }

    #[test]
    fn nodes_after_the_descriptor_make_revolutions_with_the_front_ahead() {
        let mut bytes = vec![0x00, 0x13];
        bytes.extend_from_slice(&DESCRIPTOR);
        for rev in 0..3 {
            for k in 0..360 {
                let angle = f64::from(k);
                let d = if (4..=356).contains(&k) {
                    2000 + rev
                } else {
                    800
                };
                bytes.extend_from_slice(&node(k == 0, angle, d));
            }
        }
        let mut decoder = Decoder::default();
        let mut fronts = Vec::new();
        for chunk in bytes.chunks(37) {
            decoder.feed(chunk, |scan| fronts.push(front_mm(scan, 5.0)));
        }
        assert_eq!(fronts, vec![Some(800), Some(800)]);
        assert_eq!(decoder.bad_nodes, 0);
    }
}
