//! The unit's side: commands in, reply headers and point cloud packets out.

use super::packet::{angle_correction_q6, Packet, MAX_SAMPLES, TURN_Q6};
use super::{cmd, info, SYNC_BYTE, SYNC_BYTE2};
use crate::{Output, Unit, UnitReading};

/// How far a sample's decoded angle may lie from its reading's, 1/64 degrees (0.1°): a packet
/// closes before a reading that its interpolation could not place that close.
const TOLERANCE_Q6: f64 = 6.4;
/// The widest span of raw angles one packet covers (the drivers unwrap a packet across 0° only
/// when FSA is above 270° and LSA below 90°).
const MAX_SPAN_Q6: i64 = 80 * 64;

/// A reading waiting for its packet.
#[derive(Debug, Clone, Copy)]
struct Pending {
    /// Its angle, 1/64 degrees, unwrapped from the packet's first reading.
    angle_q6: f64,
    sample: u16,
    t_s: f64,
}

/// A YDLIDAR X4 on its serial line: answers the start and stop scan, device information,
/// health and soft restart commands as the X4 Development Manual gives them, and while scanning
/// sends its readings in point cloud packets: a revolution opens with its zero packet (CT bit 0
/// set, the revolution's first reading alone, the scan rate in CT bits 7..1), then packets of up
/// to [`MAX_SAMPLES`] readings. A packet closes early where its linear FSA–LSA interpolation,
/// with the manual's distance correction, could not give the next reading its own angle within
/// 0.1°: a jump in distance moves the correction by degrees.
///
/// Not emulated: the boot message after a soft restart (the unit goes idle, silent).
#[derive(Debug, Clone)]
pub struct YdlidarUnit {
    /// Whether the last byte was a command's sync byte.
    sync: bool,
    scanning: bool,
    pending: Vec<Pending>,
}

impl Default for YdlidarUnit {
    fn default() -> Self {
        Self::new()
    }
}

impl YdlidarUnit {
    /// An idle unit, just powered.
    #[must_use]
    pub fn new() -> Self {
        Self {
            sync: false,
            scanning: false,
            pending: Vec::with_capacity(MAX_SAMPLES),
        }
    }

    fn command(&mut self, code: u8, now_s: f64, out: &mut Output) {
        let header = |len: u8, multiple: bool, kind: u8| {
            [
                SYNC_BYTE,
                SYNC_BYTE2,
                len,
                0,
                0,
                if multiple { 0x40 } else { 0 },
                kind,
            ]
        };
        match code {
            cmd::SCAN => {
                self.scanning = true;
                self.pending.clear();
                out.packet(now_s, 2, false, |b| {
                    b.extend_from_slice(&header(5, true, 0x81))
                });
            }
            cmd::STOP | cmd::FORCE_STOP | cmd::RESTART => {
                self.flush(out);
                self.scanning = false;
            }
            cmd::GET_INFO => out.packet(now_s, 2, false, |b| {
                b.extend_from_slice(&header(20, false, 0x04));
                b.extend_from_slice(&info::bytes());
            }),
            // Status 0 (normal), error code 0.
            cmd::GET_HEALTH => out.packet(now_s, 2, false, |b| {
                b.extend_from_slice(&header(3, false, 0x06));
                b.extend_from_slice(&[0, 0, 0]);
            }),
            _ => {}
        }
    }

    /// The packet of the pending readings, if they fit one (see [`YdlidarUnit`]).
    fn fit(pending: &[Pending]) -> Option<Packet> {
        let first = pending.first()?;
        let last = pending[pending.len() - 1];
        let raw = |p: &Pending| (p.angle_q6 - f64::from(angle_correction_q6(p.sample))).round();
        let (fsa, lsa) = (raw(first) as i64, raw(&last) as i64);
        if lsa < fsa || lsa - fsa > MAX_SPAN_Q6 {
            return None;
        }
        let n = pending.len();
        let interval = if n > 1 {
            (lsa - fsa) as f64 / (n - 1) as f64
        } else {
            0.0
        };
        let fits = pending.iter().enumerate().all(|(i, p)| {
            let decoded =
                fsa as f64 + interval * i as f64 + f64::from(angle_correction_q6(p.sample));
            (decoded - p.angle_q6).abs() <= TOLERANCE_Q6
        });
        let wrap = |a: i64| a.rem_euclid(i64::from(TURN_Q6)) as u16;
        fits.then(|| Packet {
            ct: 0,
            fsa_q6: wrap(fsa),
            lsa_q6: wrap(lsa),
            samples: pending.iter().map(|p| p.sample).collect(),
        })
    }

    /// Sends the pending readings, if any.
    fn flush(&mut self, out: &mut Output) {
        let Some(last) = self.pending.last() else {
            return;
        };
        let due = last.t_s;
        // The pending readings always fit: each was taken only if it did (one alone always does).
        if let Some(packet) = Self::fit(&self.pending) {
            out.packet(due, 2, false, |b| packet.write(b));
        }
        self.pending.clear();
    }
}

impl Unit for YdlidarUnit {
    fn host_wrote(&mut self, bytes: &[u8], now_s: f64, out: &mut Output) {
        for &byte in bytes {
            if self.sync && byte != SYNC_BYTE {
                self.sync = false;
                self.command(byte, now_s, out);
            } else {
                self.sync = byte == SYNC_BYTE;
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
        let angle = if reading.angle_deg.is_finite() {
            reading.angle_deg.rem_euclid(360.0) * 64.0
        } else {
            0.0
        };
        let reading_pending = |base: Option<f64>| Pending {
            angle_q6: base.map_or(angle, |b| b + (angle - b).rem_euclid(f64::from(TURN_Q6))),
            // distance × 4, as far as 16 bits carry (16,383.75 mm).
            sample: (u64::from(reading.distance_mm) * 4).min(0xFFFC) as u16,
            t_s: reading.t_s,
        };
        if reading.starts_revolution {
            self.flush(out);
            let zero = [reading_pending(None)];
            if let Some(mut packet) = Self::fit(&zero) {
                // Tenths of a hertz in seven bits.
                let tenths = (reading.rev_hz * 10.0).round().clamp(0.0, 127.0) as u8;
                packet.ct = (tenths << 1) | 1;
                out.packet(reading.t_s, 2, true, |b| packet.write(b));
            }
            return;
        }
        let base = self.pending.first().map(|p| p.angle_q6);
        self.pending.push(reading_pending(base));
        if Self::fit(&self.pending).is_none() {
            self.pending.pop();
            self.flush(out);
            self.pending.push(reading_pending(None));
        }
        if self.pending.len() >= MAX_SAMPLES {
            self.flush(out);
        }
    }
}
