//! Per-run seeds and per-run draws of varied parameters: pure functions of the dataset's seed,
//! the run's index and (for a draw) the key, so any run can be made again on its own.

use rand::{RngCore as _, SeedableRng as _};
use rand_xoshiro::SplitMix64;

/// SplitMix64's increment (2^64 divided by the golden ratio): its state after `n` outputs is its
/// seed plus `n` times this.
const GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// The largest seed a scenario file can hold: TOML integers are signed 64-bit.
pub const MAX_SEED: u64 = i64::MAX as u64;

/// The seed of run `run` in a dataset seeded with `base`: the `(run + 1)`-th output of
/// SplitMix64 (Steele, Lea & Flood, OOPSLA 2014) started from `base`, shifted right by one bit so
/// that it fits a TOML integer (below 2^63).
///
/// It depends on `base` and `run` alone: not on the number of runs, the shard or the jobs.
///
/// ```
/// use hilsim_dataset::run_seed;
/// assert_eq!(run_seed(0, 0), 0xe220_a839_7b1d_cdaf >> 1); // SplitMix64(0)'s first output
/// assert_ne!(run_seed(11, 0), run_seed(11, 1));
/// assert!(run_seed(u64::MAX, 7) <= hilsim_dataset::MAX_SEED);
/// ```
#[must_use]
pub fn run_seed(base: u64, run: u64) -> u64 {
    // Jump over the first `run` outputs: `seed_from_u64` takes the value as the state as it is.
    SplitMix64::seed_from_u64(base.wrapping_add(run.wrapping_mul(GAMMA))).next_u64() >> 1
}

/// A value drawn uniformly from `[lo, hi]` for `key` in run `run` of a dataset seeded with
/// `base`: `lo + (hi − lo)·u`, where `u` is the top 53 bits of the first output of the random
/// stream named `dataset.vary.KEY` of the run's seed ([`hilsim_sim::rng::stream`]) divided by
/// 2^53. Each key has its own stream, so adding or removing another `--vary` never changes this
/// one's values.
///
/// ```
/// use hilsim_dataset::draw;
/// let x = draw(11, 42, "robot.start.x", 0.5, 1.5);
/// assert!((0.5..=1.5).contains(&x));
/// assert_eq!(x, draw(11, 42, "robot.start.x", 0.5, 1.5));
/// assert_ne!(x, draw(11, 43, "robot.start.x", 0.5, 1.5));
/// ```
#[must_use]
pub fn draw(base: u64, run: u64, key: &str, lo: f64, hi: f64) -> f64 {
    let mut rng = hilsim_sim::rng::stream(run_seed(base, run), &format!("dataset.vary.{key}"));
    let u = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    (lo + (hi - lo) * u).clamp(lo, hi)
}

#[cfg(test)]
mod tests {
    /// Values recorded before `run_seed`'s SplitMix64 became `rand_xoshiro`'s: every dataset's
    /// runs depend on every bit of them.
    #[test]
    fn run_seeds_are_pinned() {
        let pinned: [(u64, u64, u64); 6] = [
            (0, 0, 0x7110_541c_bd8e_e6d7),
            (0, 1, 0x373c_4f35_50dc_b2fa),
            (11, 42, 0x7a5a_a93d_2dfd_1d5b),
            (u64::MAX, 7, 0x202e_d21c_51cf_4032),
            (0x1234_5678_9abc_def0, u64::MAX, 0x4b14_fac7_4762_dc83),
            (99, 1_000_000, 0x2431_63dc_31f9_37e5),
        ];
        for (base, run, expected) in pinned {
            assert_eq!(
                super::run_seed(base, run),
                expected,
                "run_seed({base}, {run})"
            );
        }
    }

    #[test]
    fn draws_are_pinned() {
        let pinned: [(u64, u64, &str, u64); 3] = [
            (11, 42, "robot.start.x", 0x3fee_726d_5d31_0563),
            (0, 0, "a", 0x3fd2_a809_7dd3_5aea),
            (5, 3, "sensors.lidar.rpm", 0x3fe2_f9c0_450b_14e3),
        ];
        for (base, run, key, expected) in pinned {
            let got = super::draw(base, run, key, 0.0, 1.0).to_bits();
            assert_eq!(got, expected, "draw({base}, {run}, {key:?})");
        }
    }
}
