//! The study's random numbers: each run's seed, and the generator it seeds.

use rand::{RngCore, SeedableRng};
use rand_xoshiro::{SplitMix64, Xoshiro256PlusPlus};

/// The seed of run `i` of a study seeded `seed` (SplitMix64 of the pair, so neighbouring runs and
/// studies get unrelated streams).
#[must_use]
pub fn run_seed(seed: u64, i: u64) -> u64 {
    splitmix64(seed ^ splitmix64(i.wrapping_add(0x9E37_79B9_7F4A_7C15)))
}

/// The SplitMix64 finaliser of `z + γ` (γ the golden-ratio increment): the first output of
/// SplitMix64 started at `z`.
fn splitmix64(z: u64) -> u64 {
    SplitMix64::seed_from_u64(z).next_u64()
}

/// xoshiro256++ (Blackman & Vigna, "Scrambled linear pseudorandom number generators", ACM TOMS
/// 2021; `rand_xoshiro`'s), seeded through SplitMix64 as its authors recommend: small, fast, and
/// the same on every platform, so each run's numbers depend on its seed alone.
#[derive(Debug, Clone)]
pub struct Xoshiro256pp(Xoshiro256PlusPlus);

impl Xoshiro256pp {
    /// The generator seeded from one 64-bit number: its four state words are the first four
    /// outputs of SplitMix64 started at `seed`.
    #[must_use]
    pub fn seed_from_u64(seed: u64) -> Self {
        Self(Xoshiro256PlusPlus::seed_from_u64(seed))
    }
}

impl RngCore for Xoshiro256pp {
    fn next_u32(&mut self) -> u32 {
        self.0.next_u32()
    }

    fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Little-endian bytes of successive `next_u64` outputs, the last one truncated (unlike
    /// `rand_core`'s default, which ends a short tail with `next_u32`).
    fn fill_bytes(&mut self, dst: &mut [u8]) {
        for chunk in dst.chunks_mut(8) {
            let v = self.next_u64().to_le_bytes();
            chunk.copy_from_slice(&v[..chunk.len()]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The generator's and the run seeds' streams, pinned (recorded from the hand-written
    /// xoshiro256++/SplitMix64 this module used before `rand_xoshiro`): every Monte Carlo
    /// figure in the docs depends on them.
    #[test]
    fn the_random_streams_are_pinned() {
        /// A seed, its first four `next_u64`, the next two `next_u32`, then 13 bytes.
        type Pin = (u64, [u64; 4], [u32; 2], [u8; 13]);
        let pins: [Pin; 3] = [
            (
                0,
                [
                    0x5317_5d61_490b_23df,
                    0x61da_6f3d_c380_d507,
                    0x5c0f_df91_ec9a_7bfc,
                    0x02ee_bf8c_3bbe_5e1a,
                ],
                [0x7eca_04eb, 0x0543_c377],
                [110, 2, 181, 90, 199, 144, 116, 219, 89, 201, 75, 70, 230],
            ),
            (
                3,
                [
                    0x0d2b_eb91_b919_6929,
                    0xa5dd_ec9f_6e30_6924,
                    0xddf4_a242_68e3_e59f,
                    0xd846_4738_d525_af37,
                ],
                [0xa075_b61e, 0x1c77_4512],
                [57, 132, 48, 130, 96, 172, 32, 46, 151, 168, 124, 209, 35],
            ),
            (
                42,
                [
                    0xd076_4d4f_4476_689f,
                    0x519e_4174_576f_3791,
                    0xfbe0_7cfb_0c24_ed8c,
                    0xb37d_9f60_0cd8_35b8,
                ],
                [0xcb23_1c38, 0x968d_9f00],
                [86, 53, 26, 34, 255, 24, 23, 32, 70, 203, 216, 14, 7],
            ),
        ];
        for (seed, u64s, u32s, bytes) in pins {
            let mut rng = Xoshiro256pp::seed_from_u64(seed);
            assert_eq!([(); 4].map(|()| rng.next_u64()), u64s, "seed {seed}");
            assert_eq!([(); 2].map(|()| rng.next_u32()), u32s, "seed {seed}");
            let mut b = [0u8; 13];
            rng.fill_bytes(&mut b);
            assert_eq!(b, bytes, "seed {seed}");
        }
        assert_eq!(run_seed(0, 0), 0x46b7_3e79_f0c3_7c00);
        assert_eq!(run_seed(0, 1), 0x778b_1aa9_c29b_c868);
        assert_eq!(run_seed(10, 7), 0x1ad0_44fe_6a05_7bec);
        assert_eq!(run_seed(u64::MAX, 3), 0x569f_b987_22e6_67b9);
    }
}
