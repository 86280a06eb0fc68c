//! The legacy express scan's 84-byte capsule: a start angle and 16 cabins of two readings.

/// Bytes in one capsule.
pub const CAPSULE_LEN: usize = 84;
/// Readings in one capsule.
pub const READINGS_PER_CAPSULE: usize = 32;
/// A full turn in 1/64 degrees.
const TURN_Q6: i64 = 360 * 64;
/// The angle compensation the encoder aims at, 1/8 degrees: the middle of the 0–31 range that
/// every driver reads alike (the field's sixth bit is a sign bit to `rplidar-roboticia` and a
/// value bit to Slamtec's SDK and `pyrplidar`, so it is never set).
const AIM_DTHETA_Q3: i64 = 16;
/// The largest compensation written, 1/8 degrees.
const MAX_DTHETA_Q3: i64 = 31;

/// Two readings of a capsule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Cabin {
    /// The readings' distances, mm, 14 bits (0: no return).
    pub distance_mm: [u16; 2],
    /// The readings' angle compensations, 1/8 degrees, 6 bits.
    pub dtheta_q3: [u8; 2],
}

/// One express capsule (protocol v2.1, "Response Data of EXPRESS_SCAN"):
///
/// | byte | content |
/// | --- | --- |
/// | 0 | `0xA` << 4, checksum bits 3..0 |
/// | 1 | `0x5` << 4, checksum bits 7..4 |
/// | 2–3 | start_angle_q6 (15 bits, LE), `S` in bit 15 |
/// | 4 + 5i .. | cabin i: distance1 << 2 \| dθ1 bits 5..4 (u16 LE), the same for distance2, then dθ1 bits 3..0 \| dθ2 bits 3..0 << 4 |
///
/// The checksum is the XOR of bytes 2..84. The readings' angles need the next capsule's start
/// angle: [`Capsule::angles_q6`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Capsule {
    /// `S`: the first capsule after the express scan started (or a restart of the data).
    pub start: bool,
    /// The start angle, 1/64 degrees, 15 bits.
    pub start_angle_q6: u16,
    /// The 32 readings in 16 cabins.
    pub cabins: [Cabin; 16],
}

impl Capsule {
    /// The capsule's bytes.
    #[must_use]
    pub fn encode(&self) -> [u8; CAPSULE_LEN] {
        let mut b = [0; CAPSULE_LEN];
        let angle = (self.start_angle_q6 & 0x7FFF) | (u16::from(self.start) << 15);
        b[2..4].copy_from_slice(&angle.to_le_bytes());
        for (chunk, cabin) in b[4..].chunks_exact_mut(5).zip(&self.cabins) {
            for (j, (&d, &t)) in cabin.distance_mm.iter().zip(&cabin.dtheta_q3).enumerate() {
                let word = ((d & 0x3FFF) << 2) | u16::from((t >> 4) & 0x3);
                chunk[2 * j..2 * j + 2].copy_from_slice(&word.to_le_bytes());
            }
            chunk[4] = (cabin.dtheta_q3[0] & 0xF) | ((cabin.dtheta_q3[1] & 0xF) << 4);
        }
        let checksum = b[2..].iter().fold(0, |acc, x| acc ^ x);
        b[0] = 0xA0 | (checksum & 0xF);
        b[1] = 0x50 | (checksum >> 4);
        b
    }

    /// Whether two bytes carry a capsule's sync nibbles.
    #[must_use]
    pub const fn is_sync(b0: u8, b1: u8) -> bool {
        b0 >> 4 == 0xA && b1 >> 4 == 0x5
    }

    /// Parses 84 bytes; `None` when the sync nibbles or the checksum are wrong.
    #[must_use]
    pub fn decode(b: &[u8; CAPSULE_LEN]) -> Option<Self> {
        let checksum = b[2..].iter().fold(0, |acc, x| acc ^ x);
        if !Self::is_sync(b[0], b[1]) || checksum != (b[0] & 0xF) | (b[1] << 4) {
            return None;
        }
        let angle = u16::from_le_bytes([b[2], b[3]]);
        let mut cabins = [Cabin::default(); 16];
        for (chunk, cabin) in b[4..].chunks_exact(5).zip(&mut cabins) {
            let w1 = u16::from_le_bytes([chunk[0], chunk[1]]);
            let w2 = u16::from_le_bytes([chunk[2], chunk[3]]);
            cabin.distance_mm = [w1 >> 2, w2 >> 2];
            // Both masked to 6 bits.
            cabin.dtheta_q3 = [
                (chunk[4] & 0xF) | (((w1 & 0x3) as u8) << 4),
                (chunk[4] >> 4) | (((w2 & 0x3) as u8) << 4),
            ];
        }
        Some(Self {
            start: angle & 0x8000 != 0,
            start_angle_q6: angle & 0x7FFF,
            cabins,
        })
    }

    /// The 32 readings' angles, 1/64 degrees in `[0, 360 × 64)`, given the next capsule's start
    /// angle, with the integer arithmetic of Slamtec's SDK (`_capsuleToNormal`) that `pyrplidar`
    /// copies: reading k (from 0) is at `start + k × AngleDiff / 32 − dθ_k`.
    #[must_use]
    pub fn angles_q6(&self, next_start_angle_q6: u16) -> [u16; READINGS_PER_CAPSULE] {
        let cur_q8 = i64::from(next_start_angle_q6 & 0x7FFF) << 2;
        let prev_q8 = i64::from(self.start_angle_q6) << 2;
        let mut diff_q8 = cur_q8 - prev_q8;
        if prev_q8 > cur_q8 {
            diff_q8 += 360 << 8;
        }
        let inc_q16 = diff_q8 << 3;
        let mut raw_q16 = prev_q8 << 8;
        let mut angles = [0; READINGS_PER_CAPSULE];
        for (k, angle) in angles.iter_mut().enumerate() {
            let dtheta = i64::from(self.cabins[k / 2].dtheta_q3[k % 2]);
            let q6 = ((raw_q16 - (dtheta << 13)) >> 10).rem_euclid(TURN_Q6);
            // rem_euclid keeps it in 0..23040.
            *angle = q6 as u16;
            raw_q16 += inc_q16;
        }
        angles
    }
}

/// One reading waiting for its capsule.
#[derive(Debug, Clone, Copy)]
struct Pending {
    angle_deg: f64,
    distance_mm: u32,
    t_s: f64,
    starts_revolution: bool,
}

/// Gathers readings into capsules. A capsule's angles are decoded with the next capsule's start
/// angle, so the encoder chooses that start angle when it closes a capsule (its readings' step
/// carried one step on, plus the aimed compensation) and keeps it for the next capsule.
#[derive(Debug, Clone)]
pub(crate) struct CapsuleEncoder {
    pending: Vec<Pending>,
    next_start_q6: Option<i64>,
    first: bool,
}

impl CapsuleEncoder {
    pub(crate) fn new() -> Self {
        Self {
            pending: Vec::with_capacity(READINGS_PER_CAPSULE),
            next_start_q6: None,
            first: true,
        }
    }

    /// Takes one reading; returns a capsule's bytes, its due time and whether it carries a
    /// revolution's first reading, when the reading completes one.
    pub(crate) fn push(
        &mut self,
        angle_deg: f64,
        distance_mm: u32,
        t_s: f64,
        starts_revolution: bool,
    ) -> Option<([u8; CAPSULE_LEN], f64, bool)> {
        self.pending.push(Pending {
            angle_deg: if angle_deg.is_finite() {
                angle_deg
            } else {
                0.0
            },
            distance_mm,
            t_s,
            starts_revolution,
        });
        if self.pending.len() < READINGS_PER_CAPSULE {
            return None;
        }
        let capsule = self.close();
        let due = self.pending[READINGS_PER_CAPSULE - 1].t_s;
        let starts = self.pending.iter().any(|p| p.starts_revolution);
        self.pending.clear();
        Some((capsule.encode(), due, starts))
    }

    fn close(&mut self) -> Capsule {
        // The readings' angles in 1/64 degrees, unwrapped from the first.
        let first = self.pending[0].angle_deg.rem_euclid(360.0) * 64.0;
        let unwrapped: Vec<f64> = self
            .pending
            .iter()
            .map(|p| first + (p.angle_deg * 64.0 - first).rem_euclid(TURN_Q6 as f64))
            .collect();
        let aim = |angle_q6: f64| (angle_q6 + (AIM_DTHETA_Q3 * 8) as f64).round() as i64;
        let start_q6 = match self.next_start_q6 {
            // The start chosen with the previous capsule, unless the readings moved on too far
            // for the compensations to absorb it (a stop and restart, a jump in speed).
            Some(s) if signed_q6(s - aim(first)).abs() <= 64 => s,
            _ => aim(first).rem_euclid(TURN_Q6),
        };
        let last = unwrapped[READINGS_PER_CAPSULE - 1];
        let step = (last - unwrapped[0]) / (READINGS_PER_CAPSULE - 1) as f64;
        let next_q6 = aim(last + step).rem_euclid(TURN_Q6);
        self.next_start_q6 = Some(next_q6);

        let mut capsule = Capsule {
            start: std::mem::replace(&mut self.first, false),
            start_angle_q6: start_q6 as u16,
            cabins: [Cabin::default(); 16],
        };
        // The angle each reading decodes to with no compensation, then the compensation that
        // brings it back to the reading's.
        let zero = capsule.angles_q6(next_q6 as u16);
        for (k, (p, &u)) in self.pending.iter().zip(&unwrapped).enumerate() {
            let raw = f64::from(zero[k]);
            let off = (raw - u).rem_euclid(TURN_Q6 as f64);
            let off = if off > (TURN_Q6 / 2) as f64 {
                off - TURN_Q6 as f64
            } else {
                off
            };
            let dtheta = (off / 8.0).round().clamp(0.0, MAX_DTHETA_Q3 as f64) as u8;
            let cabin = &mut capsule.cabins[k / 2];
            cabin.dtheta_q3[k % 2] = dtheta;
            cabin.distance_mm[k % 2] = p.distance_mm.min(0x3FFF) as u16;
        }
        capsule
    }
}

/// An angle difference in 1/64 degrees, wrapped into `[-180°, 180°)`.
fn signed_q6(diff: i64) -> i64 {
    (diff + TURN_Q6 / 2).rem_euclid(TURN_Q6) - TURN_Q6 / 2
}
