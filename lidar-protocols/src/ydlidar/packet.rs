//! One point cloud packet: header, samples, checksum, and the angle arithmetic.

/// Bytes before the samples: PH, CT, LSN, FSA, LSA, CS.
pub const HEADER_LEN: usize = 10;
/// The most samples the unit puts in one packet (the X4's full packet; `lds2d`'s
/// `PACKAGE_SAMPLE_MAX_LENGTH` and the manual's worked example, LSN = 0x28).
pub const MAX_SAMPLES: usize = 40;
/// The packet header, `AA 55` on the wire.
pub const PH: u16 = 0x55AA;
/// A full turn in 1/64 degrees.
pub(crate) const TURN_Q6: i32 = 360 * 64;

/// The manual's angle correction for a sample's distance, in 1/64 degrees as `lds2d` and the
/// YDLIDAR SDK compute it: `atan(21.8 × (155.3 − d) / (155.3 × d))`, truncated toward zero
/// (`d` = sample / 4 mm; 0 when the distance is 0).
#[must_use]
pub fn angle_correction_q6(sample: u16) -> i32 {
    if sample < 4 {
        return 0;
    }
    let d = f64::from(sample) * 0.25;
    // |atan| < π/2, so the value fits an i32.
    ((21.8 * (155.3 - d) / 155.3 / d).atan() * 3666.93) as i32
}

/// One packet as on the wire.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Packet {
    /// CT: bit 0 set on a revolution's first packet (the zero packet); bits 7..1 the scan rate
    /// in 0.1 Hz there, as `lds2d` and the SDK read it.
    pub ct: u8,
    /// FSA's angle, 1/64 degrees (15 bits; the wire shifts it left and sets the check bit).
    pub fsa_q6: u16,
    /// LSA's angle, the same.
    pub lsa_q6: u16,
    /// The samples: distance × 4 (mm in q2).
    pub samples: Vec<u16>,
}

impl Packet {
    /// The checksum: the XOR of PH, `CT | LSN << 8`, FSA, LSA (as on the wire, check bits
    /// included) and every sample, as 16-bit words (manual, "Check code parsing").
    #[must_use]
    pub fn checksum(ct: u8, lsn: u8, fsa_raw: u16, lsa_raw: u16, samples: &[u16]) -> u16 {
        samples.iter().fold(
            PH ^ u16::from_le_bytes([ct, lsn]) ^ fsa_raw ^ lsa_raw,
            |acc, s| acc ^ s,
        )
    }

    /// Appends the packet's bytes (the unit writes at most [`MAX_SAMPLES`] samples; past 255
    /// they are cut, as LSN is one byte).
    pub fn write(&self, out: &mut Vec<u8>) {
        let samples = &self.samples[..self.samples.len().min(255)];
        // Cut to 255 above.
        let lsn = samples.len() as u8;
        let fsa = ((self.fsa_q6 & 0x7FFF) << 1) | 1;
        let lsa = ((self.lsa_q6 & 0x7FFF) << 1) | 1;
        let cs = Self::checksum(self.ct, lsn, fsa, lsa, samples);
        out.extend_from_slice(&PH.to_le_bytes());
        out.extend_from_slice(&[self.ct, lsn]);
        out.extend_from_slice(&fsa.to_le_bytes());
        out.extend_from_slice(&lsa.to_le_bytes());
        out.extend_from_slice(&cs.to_le_bytes());
        for s in samples {
            out.extend_from_slice(&s.to_le_bytes());
        }
    }

    /// The samples' angles in 1/64 degrees, `[0, 360 × 64)`, as `lds2d` (`_try_parse`) and the
    /// SDK compute them: `FSA + i × (LSA − FSA) / (LSN − 1) + AngCorrect(sample)`, the difference
    /// taken across 0° when FSA is above 270° and LSA below 90°. `last_interval` is the step a
    /// packet whose LSA is below its FSA otherwise reuses (updated).
    #[must_use]
    pub fn angles_q6(&self, last_interval: &mut f64) -> Vec<f64> {
        let (fsa, lsa) = (f64::from(self.fsa_q6), f64::from(self.lsa_q6));
        let n = self.samples.len();
        let interval = if n <= 1 {
            0.0
        } else if lsa < fsa {
            if fsa > 17_280.0 && lsa < 5_760.0 {
                *last_interval = (f64::from(TURN_Q6) + lsa - fsa) / (n - 1) as f64;
            }
            *last_interval
        } else {
            *last_interval = (lsa - fsa) / (n - 1) as f64;
            *last_interval
        };
        self.samples
            .iter()
            .enumerate()
            .map(|(i, &s)| {
                let a = fsa + interval * i as f64 + f64::from(angle_correction_q6(s));
                a.rem_euclid(f64::from(TURN_Q6))
            })
            .collect()
    }
}
