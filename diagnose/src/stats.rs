//! The few distributions the tests need: the standard normal's density, tail and quantile, and
//! chi-square statistics expressed as equivalent normal scores.

use std::f64::consts::PI;

/// `ln φ(z)`, the standard normal log-density.
#[must_use]
pub fn ln_normal_pdf(z: f64) -> f64 {
    -0.5 * z * z - 0.5 * (2.0 * PI).ln()
}

/// `erfc(x)` for x ≥ 0 with relative error below 1.2e-7 everywhere, including the far tail
/// (Numerical Recipes' `erfcc`, a Chebyshev fit of `exp(x²) erfc(x)`).
fn erfc_nonneg(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.5 * x);
    let poly = -x * x - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    t * poly.exp()
}

/// `P(Z > z)` for a standard normal Z.
///
/// ```
/// use hilsim_diagnose::stats::normal_sf;
/// assert!((normal_sf(0.0) - 0.5).abs() < 1e-7);
/// assert!((normal_sf(1.959964) - 0.025).abs() < 1e-7);
/// assert!((normal_sf(10.0) / 7.619853e-24 - 1.0).abs() < 1e-5);
/// ```
#[must_use]
pub fn normal_sf(z: f64) -> f64 {
    if z >= 0.0 {
        0.5 * erfc_nonneg(z / std::f64::consts::SQRT_2)
    } else {
        1.0 - 0.5 * erfc_nonneg(-z / std::f64::consts::SQRT_2)
    }
}

/// `P(Z ≤ z)`.
#[must_use]
pub fn normal_cdf(z: f64) -> f64 {
    normal_sf(-z)
}

/// The standard normal quantile (Acklam's rational approximation, relative error below 1.2e-9,
/// refined by one Halley step).
///
/// ```
/// use hilsim_diagnose::stats::normal_quantile;
/// assert!((normal_quantile(0.975) - 1.959964).abs() < 1e-6);
/// assert!((normal_quantile(1e-10) + 6.361341).abs() < 1e-5);
/// ```
#[must_use]
pub fn normal_quantile(p: f64) -> f64 {
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
    // One Halley step against the CDF.
    let e = normal_cdf(x) - p;
    let u = e * (2.0 * PI).sqrt() * (0.5 * x * x).exp();
    x - u / (1.0 + x * u / 2.0)
}

/// The normal score of a chi-square statistic `q` on `k` degrees of freedom: the z with the same
/// upper tail, by the Wilson–Hilferty cube-root transformation (accurate to a few hundredths of
/// a standard deviation for k ≥ 3; conservative enough for smaller k in the far tail).
///
/// ```
/// use hilsim_diagnose::stats::chi2_score;
/// // χ²₁₀ = 23.21 has an upper tail of 0.01: z = 2.326.
/// assert!((chi2_score(23.21, 10) - 2.326).abs() < 0.02);
/// ```
#[must_use]
pub fn chi2_score(q: f64, k: usize) -> f64 {
    if k == 0 {
        return 0.0;
    }
    let k = k as f64;
    let v = 2.0 / (9.0 * k);
    ((q.max(0.0) / k).cbrt() - (1.0 - v)) / v.sqrt()
}

/// The one-sided tail probability of a normal score, for reports.
#[must_use]
pub fn p_value(z: f64) -> f64 {
    normal_sf(z)
}

/// The Ljung–Box statistic of `x` (in time order) over lags `1..=lags`, with its degrees of
/// freedom: χ²_lags when `x` is white. The autocorrelations are taken relative to a variance of
/// at least `min_var`: scores whose noise model predicts variance 1 are correlated "beyond their
/// noise" only by what exceeds it, so tiny residuals (a simulation that reproduces the data far
/// better than its declared noise) do not count as structure however smooth they are.
#[must_use]
pub fn ljung_box(x: &[f64], lags: usize, min_var: f64) -> (f64, usize) {
    let n = x.len();
    if n <= lags + 2 {
        return (0.0, 0);
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let var: f64 = x
        .iter()
        .map(|v| (v - mean) * (v - mean))
        .sum::<f64>()
        .max(min_var * n as f64);
    if var <= 0.0 {
        return (0.0, 0);
    }
    let mut q = 0.0;
    for lag in 1..=lags {
        let r: f64 = (lag..n)
            .map(|i| (x[i] - mean) * (x[i - lag] - mean))
            .sum::<f64>()
            / var;
        q += r * r / (n - lag) as f64;
    }
    (q * n as f64 * (n as f64 + 2.0), lags)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantile_inverts_the_tail() {
        for &z in &[-7.0, -3.0, -0.5, 0.0, 0.3, 2.0, 5.5] {
            let back = normal_quantile(normal_cdf(z));
            assert!((back - z).abs() < 1e-5, "{z} -> {back}");
        }
    }

    #[test]
    fn white_noise_passes_ljung_box_and_a_random_walk_fails() {
        // A deterministic white sequence: xorshift64* uniforms through the normal quantile.
        let mut state: u64 = 0x2545_f491_4f6c_dd1d;
        let white: Vec<f64> = (0..5000)
            .map(|_| {
                state ^= state >> 12;
                state ^= state << 25;
                state ^= state >> 27;
                let u =
                    (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64;
                normal_quantile(u.max(1e-12))
            })
            .collect();
        let (q, k) = ljung_box(&white, 10, 0.0);
        // White noise: Q ~ χ²₁₀, whose normal score exceeds 4 with probability 3e-5.
        assert!(chi2_score(q, k) < 4.0, "{q}");
        let walk: Vec<f64> = white
            .iter()
            .scan(0.0, |s, v| {
                *s += v;
                Some(*s)
            })
            .collect();
        let (q, k) = ljung_box(&walk, 10, 0.0);
        assert!(chi2_score(q, k) > 50.0);
    }
}
