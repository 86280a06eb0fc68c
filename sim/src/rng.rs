//! Seeded randomness: one independent stream per component, derived from the run's seed and the
//! component's name alone, so that adding a sensor never changes another sensor's noise.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The random stream type every component uses.
pub type Rng = ChaCha8Rng;

/// The stream of component `name` in a run seeded with `seed`.
///
/// The derivation (FNV-1a of the name, mixed with the seed by SplitMix64) is fixed here and
/// independent of the Rust version, so recordings stay reproducible across toolchains.
///
/// ```
/// use rand::Rng as _;
/// let mut a = hilsim_sim::rng::stream(7, "lidar");
/// let mut b = hilsim_sim::rng::stream(7, "lidar");
/// let mut c = hilsim_sim::rng::stream(7, "sonar");
/// let (x, y, z): (u64, u64, u64) = (a.random(), b.random(), c.random());
/// assert_eq!(x, y);
/// assert_ne!(x, z);
/// ```
#[must_use]
pub fn stream(seed: u64, name: &str) -> Rng {
    let mut name_hash: u64 = 0xcbf2_9ce4_8422_2325;
    for byte in name.bytes() {
        name_hash ^= u64::from(byte);
        name_hash = name_hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    let mut state = seed ^ name_hash.rotate_left(29);
    let mut key = [0u8; 32];
    for chunk in key.chunks_mut(8) {
        chunk.copy_from_slice(&splitmix64(&mut state).to_le_bytes());
    }
    ChaCha8Rng::from_seed(key)
}

fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
