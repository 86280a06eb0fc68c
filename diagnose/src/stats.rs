//! Chi-square statistics the tests need, expressed as equivalent normal scores (the normal
//! distribution itself is `hilsim_lidar_emulator::normal`).

use hilsim_lidar_emulator::normal;

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
    normal::sf(z)
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

/// Huber's loss of a normalised residual `r` with threshold `k`: quadratic within `k`, linear
/// beyond (Huber, "Robust estimation of a location parameter", 1964), so that a few gross
/// residuals do not carry a fit.
#[must_use]
pub fn huber(r: f64, k: f64) -> f64 {
    if r.abs() <= k {
        0.5 * r * r
    } else {
        k * (r.abs() - 0.5 * k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
                normal::quantile(u.max(1e-12))
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
