//! The normal distribution, in one place: the standard normal's distribution function, tail,
//! log-density and quantile, and one component of a predictive mixture ([`Gaussian`]), a normal
//! truncated to the interval in which a sensor reports a reading at all.
//!
//! The distribution function and the tail are `erfc` ([`libm::erfc`], exact to double
//! precision), each on the side that keeps its precision: `sf(10)` is 7.6e-24, not `1 − cdf`.

use std::f64::consts::{PI, SQRT_2};

/// A bound this many standard deviations out on each side leaves the whole of the mass
/// (to the last bit of an `f64`).
const WHOLE_Z: f64 = 9.0;

/// `P(Z ≤ z)` for a standard normal Z.
///
/// ```
/// use hilsim_lidar_emulator::normal;
/// assert_eq!(normal::cdf(0.0), 0.5);
/// assert!((normal::cdf(-1.959963984540054) - 0.025).abs() < 1e-16);
/// ```
#[must_use]
pub fn cdf(z: f64) -> f64 {
    0.5 * libm::erfc(-z / SQRT_2)
}

/// `P(Z > z)` for a standard normal Z.
///
/// ```
/// use hilsim_lidar_emulator::normal;
/// assert!((normal::sf(1.959963984540054) - 0.025).abs() < 1e-16);
/// assert!((normal::sf(10.0) / 7.619853024160527e-24 - 1.0).abs() < 1e-14);
/// ```
#[must_use]
pub fn sf(z: f64) -> f64 {
    0.5 * libm::erfc(z / SQRT_2)
}

/// `ln φ(z)`, the standard normal log-density.
#[must_use]
pub fn ln_pdf(z: f64) -> f64 {
    -0.5 * z * z - 0.5 * (2.0 * PI).ln()
}

/// The standard normal quantile: Acklam's rational approximation (relative error below
/// 1.2e-9), refined by one Halley step against [`cdf`].
///
/// ```
/// use hilsim_lidar_emulator::normal;
/// assert!((normal::quantile(0.975) - 1.959963984540054).abs() < 1e-12);
/// assert!((normal::quantile(1e-10) + 6.361340902404056).abs() < 1e-9);
/// ```
#[must_use]
pub fn quantile(p: f64) -> f64 {
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let low = 0.024_25;
    let x = if p < low {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else if p <= 1.0 - low {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        let q = (-2.0 * (1.0 - p).ln()).sqrt();
        -(((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    // One Halley step against the distribution function.
    let e = cdf(x) - p;
    let u = e * (2.0 * PI).sqrt() * (0.5 * x * x).exp();
    x - u / (1.0 + x * u / 2.0)
}

/// One component of a predictive mixture: a normal distribution, truncated to the interval in
/// which the sensor reports a reading at all (a lidar's range limits: a reading beyond them is
/// reported invalid, so a valid one near a limit comes from the part of the normal inside it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gaussian {
    /// Weight (a prediction's weights sum to 1).
    pub weight: f64,
    /// Mean of the untruncated normal, metres.
    pub mean_m: f64,
    /// Standard deviation of the untruncated normal, metres (> 0).
    pub sd_m: f64,
    /// The smallest reading reported (−∞: no limit).
    pub lower_m: f64,
    /// The largest reading reported (+∞: no limit).
    pub upper_m: f64,
}

impl Gaussian {
    /// An untruncated normal with weight `weight`.
    #[must_use]
    pub fn new(weight: f64, mean_m: f64, sd_m: f64) -> Self {
        Self {
            weight,
            mean_m,
            sd_m,
            lower_m: f64::NEG_INFINITY,
            upper_m: f64::INFINITY,
        }
    }

    /// The same normal truncated to `[lower_m, upper_m]`.
    #[must_use]
    pub fn truncated(self, lower_m: f64, upper_m: f64) -> Self {
        Self {
            lower_m,
            upper_m,
            ..self
        }
    }

    fn is_truncated(&self) -> bool {
        self.lower_m != f64::NEG_INFINITY || self.upper_m != f64::INFINITY
    }

    fn bounds(&self) -> (f64, f64) {
        (
            (self.lower_m - self.mean_m) / self.sd_m,
            (self.upper_m - self.mean_m) / self.sd_m,
        )
    }

    /// The probability the untruncated normal puts inside the interval (computed on the side of
    /// the median that keeps its precision).
    #[must_use]
    pub fn mass(&self) -> f64 {
        let (a, b) = self.bounds();
        // Beyond 9 standard deviations on both sides the tails (Φ(−9) ≈ 1.1e−19) are below
        // half an ulp of 1: the difference below is exactly 1, without its two erfc.
        if a <= -WHOLE_Z && b >= WHOLE_Z {
            return 1.0;
        }
        if a > 0.0 {
            sf(a) - sf(b)
        } else {
            cdf(b) - cdf(a)
        }
        .max(f64::MIN_POSITIVE)
    }

    /// `ln` of the density at `y` (−∞ outside the interval).
    #[must_use]
    pub fn ln_density(&self, y: f64) -> f64 {
        if y < self.lower_m || y > self.upper_m {
            return f64::NEG_INFINITY;
        }
        let z = (y - self.mean_m) / self.sd_m;
        let ln_mass = if self.is_truncated() {
            self.mass().ln()
        } else {
            0.0
        };
        ln_pdf(z) - self.sd_m.ln() - ln_mass
    }

    /// The distribution function at `y`.
    #[must_use]
    pub fn cdf(&self, y: f64) -> f64 {
        let z = (y - self.mean_m) / self.sd_m;
        if !self.is_truncated() {
            return cdf(z);
        }
        let (a, _) = self.bounds();
        let below = if a > 0.0 {
            sf(a) - sf(z)
        } else {
            cdf(z) - cdf(a)
        };
        (below / self.mass()).clamp(0.0, 1.0)
    }

    /// The mean and the standard deviation of the truncated distribution (the standard
    /// truncated-normal moments: Johnson, Kotz & Balakrishnan, *Continuous Univariate
    /// Distributions* 1, §10.1).
    #[must_use]
    pub fn moments(&self) -> (f64, f64) {
        if !self.is_truncated() {
            return (self.mean_m, self.sd_m);
        }
        let (a, b) = self.bounds();
        let z = self.mass();
        let pdf = |x: f64| {
            if x.is_finite() {
                ln_pdf(x).exp()
            } else {
                0.0
            }
        };
        let x_pdf = |x: f64| if x.is_finite() { x * pdf(x) } else { 0.0 };
        let shift = (pdf(a) - pdf(b)) / z;
        let var = 1.0 + (x_pdf(a) - x_pdf(b)) / z - shift * shift;
        (
            self.mean_m + self.sd_m * shift,
            self.sd_m * var.max(1e-12).sqrt(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shortcut for a bound far out on both sides gives what the two tails give.
    #[test]
    fn a_wide_interval_holds_the_whole_mass() {
        for a in [-WHOLE_Z, -9.5, -40.0, f64::NEG_INFINITY] {
            for b in [WHOLE_Z, 12.0, f64::INFINITY] {
                assert_eq!(cdf(b) - cdf(a), 1.0, "{a} {b}");
                let g = Gaussian::new(1.0, 0.0, 1.0).truncated(a, b);
                assert_eq!(g.mass(), 1.0);
            }
        }
        // Nearer, a tail counts.
        assert!(Gaussian::new(1.0, 0.0, 1.0).truncated(-8.0, 9.0).mass() < 1.0);
    }

    #[test]
    fn quantile_inverts_the_distribution_function() {
        for &z in &[-7.0, -3.0, -0.5, 0.0, 0.3, 2.0, 5.5] {
            let back = quantile(cdf(z));
            assert!((back - z).abs() < 1e-9, "{z} -> {back}");
        }
    }

    /// Tabulated values (Abramowitz & Stegun 26.2, and `erfc` to 16 digits).
    #[test]
    fn the_tails_are_exact_far_out() {
        assert_eq!(cdf(0.0), 0.5);
        assert_eq!(sf(0.0), 0.5);
        assert!((sf(1.0) - 0.158_655_253_931_457_05).abs() < 1e-16);
        assert!((cdf(-5.0) / 2.866_515_718_791_939e-7 - 1.0).abs() < 1e-14);
        assert!((sf(20.0) / 2.753_624_118_606_233_7e-89 - 1.0).abs() < 1e-13);
        for &z in &[-8.0, -1.0, 0.5, 3.0] {
            assert!((cdf(z) + sf(z) - 1.0).abs() < 1e-16, "{z}");
        }
    }

    /// The truncated component against a midpoint-rule integration of the normal density over
    /// the interval (10⁵ steps: the rule's error is ~1e-10 here, far below the tolerances).
    #[test]
    fn a_truncated_component_is_the_normal_renormalised_inside_its_interval() {
        let g = Gaussian::new(1.0, 5.9, 0.1).truncated(0.2, 6.0);
        let (lo, hi, steps) = (0.2_f64, 6.0_f64, 100_000);
        let dx = (hi - lo) / f64::from(steps);
        let (mut mass, mut first, mut second, mut below) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..steps {
            let x = lo + (f64::from(i) + 0.5) * dx;
            let p = g.ln_density(x).exp() * dx;
            mass += p;
            first += x * p;
            second += x * x * p;
            if i < 98_276 {
                below += p;
            }
        }
        assert!((mass - 1.0).abs() < 1e-6, "density integrates to {mass}");
        let (mean, sd) = g.moments();
        assert!((mean - first).abs() < 1e-6, "{mean} vs {first}");
        // Central, normalised: Σx²p − (Σxp)² would multiply the mass's rounding by ~34 m².
        let numeric_sd = (second / mass - (first / mass).powi(2)).sqrt();
        assert!((sd - numeric_sd).abs() < 1e-6, "{sd} vs {numeric_sd}");
        // Cut at 1 σ above the mean: the valid readings' mean is 0.29 σ below it.
        assert!((5.9 - mean - 0.1 * 0.2876).abs() < 1e-4, "{mean}");
        // At the cell edge nearest the normal's mean (5.9 m).
        let edge = lo + 98_276.0 * dx;
        assert!(
            (g.cdf(edge) - below).abs() < 1e-6,
            "{} vs {below}",
            g.cdf(edge)
        );
        assert_eq!(g.cdf(6.0), 1.0);
        assert_eq!(g.cdf(0.1), 0.0);
        assert_eq!(g.ln_density(6.001), f64::NEG_INFINITY);
        // Untruncated: the plain normal.
        let n = Gaussian::new(1.0, 1.0, 0.5);
        assert_eq!(n.moments(), (1.0, 0.5));
        assert_eq!(n.cdf(1.0), 0.5);
    }
}
