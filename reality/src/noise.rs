//! Random numbers of this generator: its own stream per component (xoshiro256++ seeded through
//! SplitMix64 from the run's seed and the component's name), standard normals by the polar
//! Box–Muller method, Student-t deviates for heavier tails.

use rand_xoshiro::rand_core::{RngCore, SeedableRng};
use rand_xoshiro::{SplitMix64, Xoshiro256PlusPlus};

/// One component's random stream.
pub struct Stream {
    rng: Xoshiro256PlusPlus,
    spare: Option<f64>,
}

impl Stream {
    /// The stream of component `name` in the run with `seed`.
    #[must_use]
    pub fn new(seed: u64, name: &str) -> Self {
        // FNV-1a of the name, mixed with the seed: streams of different components differ.
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in name.bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
        let mut mix = SplitMix64::seed_from_u64(seed ^ h);
        Self {
            rng: Xoshiro256PlusPlus::seed_from_u64(mix.next_u64()),
            spare: None,
        }
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    /// A standard normal deviate (polar Box–Muller; the second of each pair kept).
    pub fn normal(&mut self) -> f64 {
        if let Some(v) = self.spare.take() {
            return v;
        }
        loop {
            let u = 2.0 * self.unit() - 1.0;
            let v = 2.0 * self.unit() - 1.0;
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let f = (-2.0 * s.ln() / s).sqrt();
                self.spare = Some(v * f);
                return u * f;
            }
        }
    }

    /// A Student-t deviate with `nu` > 2 degrees of freedom, scaled to unit variance
    /// (`t · √((ν−2)/ν)`): the same spread as a standard normal, heavier tails.
    pub fn student_unit_variance(&mut self, nu: f64) -> f64 {
        // t = Z / √(χ²_ν / ν), χ²_ν as a sum of squares for the integer part and a gamma-free
        // approximation is not needed: ν is drawn as an integer.
        let k = nu.round().max(3.0) as usize;
        let chi2: f64 = (0..k).map(|_| self.normal().powi(2)).sum();
        let t = self.normal() / (chi2 / k as f64).sqrt();
        t * ((k as f64 - 2.0) / k as f64).sqrt()
    }
}
