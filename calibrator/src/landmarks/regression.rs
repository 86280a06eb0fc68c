//! The calibration regression of the paper's Sec. 3.2: the Vandermonde model (26) of the mean
//! reading against the estimated distance, fitted for every order 0..n_max by least squares
//! (eq. (28); weighted when weights are given), the order chosen by AIC and by leave-one-out
//! cross-validation, and the noise polynomial beta from the residuals.

use nalgebra::{DMatrix, DVector};

/// Σ cᵢ xⁱ by Horner's rule, lowest order first.
#[must_use]
pub fn horner(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, ci| acc * x + ci)
}

/// d/dx Σ cᵢ xⁱ.
#[must_use]
pub fn horner_derivative(c: &[f64], x: f64) -> f64 {
    c.iter()
        .enumerate()
        .skip(1)
        .rev()
        .fold(0.0, |acc, (i, ci)| acc * x + i as f64 * ci)
}

/// One order's fit.
#[derive(Debug, Clone, PartialEq)]
pub struct PolyFit {
    /// alpha_0..alpha_n.
    pub coeffs: Vec<f64>,
    /// Weighted residual sum of squares.
    pub rss: f64,
    /// Akaike's criterion, N ln(RSS/N) + 2(n + 2): the n + 1 coefficients and the noise level.
    pub aic: f64,
    /// Leave-one-out prediction error Σ wᵢ (eᵢ / (1 − hᵢᵢ))² (PRESS), exact for linear least
    /// squares.
    pub press: f64,
    /// Residuals yᵢ − ŷᵢ.
    pub residuals: Vec<f64>,
    /// Leverages hᵢᵢ.
    pub leverages: Vec<f64>,
    /// Standard errors of the coefficients: `s² (Aᵀ W A)⁻¹` diagonal with `s² = RSS/(N − n − 1)`
    /// (the weights relative, their scale from the residuals), the `x` taken as known.
    pub coeff_sd: Vec<f64>,
}

/// The fits of orders 0..=n_max and the orders the two criteria pick.
#[derive(Debug, Clone, PartialEq)]
pub struct OrderScan {
    /// `fits[n]` is the order-n fit (orders the data cannot support are absent at the end).
    pub fits: Vec<PolyFit>,
    /// The order with the least AIC.
    pub aic_order: usize,
    /// The order with the least PRESS.
    pub cv_order: usize,
}

/// Least squares fit of `y ≈ Σ cᵢ xⁱ`, i ≤ `order`, weighted by `w` (inverse variances) when
/// given. Columns are scaled by the largest |x| so that the Vandermonde matrix stays well
/// conditioned, and the system is solved by SVD. `None` when there are not more points than
/// coefficients or the data are degenerate.
#[must_use]
pub fn fit_poly(x: &[f64], y: &[f64], w: Option<&[f64]>, order: usize) -> Option<PolyFit> {
    let n = x.len();
    let p = order + 1;
    if n <= p || y.len() != n {
        return None;
    }
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-12);
    let sw: Vec<f64> = (0..n).map(|i| w.map_or(1.0, |w| w[i]).sqrt()).collect();
    let a = DMatrix::from_fn(n, p, |i, j| sw[i] * (x[i] / scale).powi(j as i32));
    let b = DVector::from_fn(n, |i, _| sw[i] * y[i]);
    let svd = a.svd(true, true);
    let smax = svd.singular_values.max();
    let well_posed = smax > 0.0 && svd.singular_values.min() >= 1e-12 * smax;
    if !well_posed {
        return None;
    }
    let sol = svd.solve(&b, 0.0).ok()?;
    let u = svd.u.as_ref()?;
    let coeffs: Vec<f64> = (0..p).map(|j| sol[j] / scale.powi(j as i32)).collect();
    if coeffs.iter().any(|c| !c.is_finite()) {
        return None;
    }
    let residuals: Vec<f64> = (0..n).map(|i| y[i] - horner(&coeffs, x[i])).collect();
    let leverages: Vec<f64> = (0..n).map(|i| u.row(i).norm_squared()).collect();
    let rss: f64 = (0..n).map(|i| (sw[i] * residuals[i]).powi(2)).sum();
    let press: f64 = (0..n)
        .map(|i| (sw[i] * residuals[i] / (1.0 - leverages[i]).max(1e-9)).powi(2))
        .sum();
    let nf = n as f64;
    let aic = nf * (rss.max(1e-300) / nf).ln() + 2.0 * (p as f64 + 1.0);
    // (AᵀWA)⁻¹ = V Σ⁻² Vᵀ from the SVD, undoing the column scaling.
    let v_t = svd.v_t.as_ref()?;
    let s2 = rss / (n - p) as f64;
    let coeff_sd = (0..p)
        .map(|j| {
            let var: f64 = (0..p)
                .map(|k| (v_t[(k, j)] / svd.singular_values[k]).powi(2))
                .sum();
            (s2 * var).sqrt() / scale.powi(j as i32)
        })
        .collect();
    Some(PolyFit {
        coeffs,
        rss,
        aic,
        press,
        residuals,
        leverages,
        coeff_sd,
    })
}

/// Fits orders 0..=`max_order` (phase #1) and picks the order by AIC and by cross-validation
/// (phase #2). `None` when not even order 0 can be fitted.
#[must_use]
pub fn scan_orders(x: &[f64], y: &[f64], w: Option<&[f64]>, max_order: usize) -> Option<OrderScan> {
    let fits: Vec<PolyFit> = (0..=max_order)
        .map_while(|n| fit_poly(x, y, w, n))
        .collect();
    let argmin = |f: fn(&PolyFit) -> f64| {
        fits.iter()
            .enumerate()
            .min_by(|a, b| f(a.1).total_cmp(&f(b.1)))
            .map(|(i, _)| i)
    };
    let aic_order = argmin(|f| f.aic)?;
    let cv_order = argmin(|f| f.press)?;
    Some(OrderScan {
        fits,
        aic_order,
        cv_order,
    })
}

/// The noise polynomial σ(d) = Σ βᵢ dⁱ from residuals `e` at distances `d`: since
/// E|e| = σ √(2/π) for Gaussian noise, √(π/2)|e| is regressed on the Vandermonde matrix with
/// non-negative coefficients (so σ(d) ≥ 0 for every d ≥ 0, as eq. (3) needs), then once more
/// weighted by 1/σ̂² (|e| is itself heteroscedastic). `dof[i]` rescales each residual for the
/// degrees of freedom its fit used (e.g. √(n/(n−1)) about a sample mean).
#[must_use]
pub fn fit_beta(d: &[f64], e: &[f64], dof: &[f64], order: usize) -> Option<Vec<f64>> {
    let k = (std::f64::consts::PI / 2.0).sqrt();
    let rows: Vec<Vec<f64>> = d
        .iter()
        .map(|x| (0..=order).map(|j| x.powi(j as i32)).collect())
        .collect();
    let y: Vec<f64> = e.iter().zip(dof).map(|(ei, f)| k * ei.abs() * f).collect();
    let beta = nnls(&rows, &y, None)?;
    let w: Vec<f64> = d
        .iter()
        .map(|x| 1.0 / horner(&beta, *x).max(1e-6).powi(2))
        .collect();
    nnls(&rows, &y, Some(&w)).or(Some(beta))
}

/// Non-negative least squares min Σ wᵢ (yᵢ − xᵢ·c)², c ≥ 0, for a handful of coefficients: the
/// optimum is the unconstrained fit on some subset of the coefficients, so every subset is tried
/// (at most 2⁹ for order 8) and the best feasible kept.
#[must_use]
pub fn nnls(x: &[Vec<f64>], y: &[f64], w: Option<&[f64]>) -> Option<Vec<f64>> {
    let n = x.len();
    let p = x.first()?.len();
    if n == 0 || p == 0 || p > 12 {
        return None;
    }
    let wt = |i: usize| w.map_or(1.0, |w| w[i]);
    let mut best: Option<(f64, Vec<f64>)> = None;
    for mask in 0u32..(1 << p) {
        let cols: Vec<usize> = (0..p).filter(|j| mask & (1 << j) != 0).collect();
        let mut c = vec![0.0; p];
        if !cols.is_empty() {
            if cols.len() >= n {
                continue;
            }
            let a = DMatrix::from_fn(n, cols.len(), |i, k| wt(i).sqrt() * x[i][cols[k]]);
            let b = DVector::from_fn(n, |i, _| wt(i).sqrt() * y[i]);
            let Ok(sol) = a.svd(true, true).solve(&b, 1e-12) else {
                continue;
            };
            if sol.iter().any(|v| *v < 0.0 || !v.is_finite()) {
                continue;
            }
            for (k, j) in cols.iter().enumerate() {
                c[*j] = sol[k];
            }
        }
        let cost: f64 = (0..n)
            .map(|i| {
                let fit: f64 = x[i].iter().zip(&c).map(|(a, b)| a * b).sum();
                wt(i) * (y[i] - fit).powi(2)
            })
            .sum();
        if best.as_ref().is_none_or(|(b, _)| cost < *b) {
            best = Some((cost, c));
        }
    }
    best.map(|(_, c)| c)
}

/// Standard errors of [`fit_beta`]'s coefficients: its weighted regression of `√(π/2)|e|` on
/// the Vandermonde rows at `d` (one row per reading), whose responses have variance
/// `(π/2 − 1) σ(d)²` for Gaussian noise, so `cov = (π/2 − 1) (Rᵀ W R)⁻¹`, `W = 1/σ̂(d)²`.
/// (The non-negativity constraint is ignored: a coefficient at 0 gets the unconstrained sd.)
#[must_use]
pub fn beta_sd(d: &[f64], beta: &[f64]) -> Vec<f64> {
    let p = beta.len();
    if d.len() <= p || p == 0 {
        return vec![f64::INFINITY; p];
    }
    let mut info = nalgebra::DMatrix::<f64>::zeros(p, p);
    for &x in d {
        let w = 1.0 / horner(beta, x).max(1e-6).powi(2);
        for i in 0..p {
            for j in 0..p {
                info[(i, j)] += w * x.powi((i + j) as i32);
            }
        }
    }
    let factor = std::f64::consts::FRAC_PI_2 - 1.0;
    match info.try_inverse() {
        Some(inv) => (0..p)
            .map(|j| (factor * inv[(j, j)]).max(0.0).sqrt())
            .collect(),
        None => vec![f64::INFINITY; p],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_polynomial_is_recovered_and_press_is_tiny() {
        let x: Vec<f64> = (0..20).map(|i| 0.3 + 0.2 * i as f64).collect();
        let c = [0.0525, 0.8838, 0.0584];
        let y: Vec<f64> = x.iter().map(|v| horner(&c, *v)).collect();
        let f = fit_poly(&x, &y, None, 2).unwrap();
        for (a, b) in f.coeffs.iter().zip(c) {
            assert!((a - b).abs() < 1e-10);
        }
        assert!(f.press < 1e-20);
        assert!((horner_derivative(&c, 2.0) - (0.8838 + 2.0 * 0.0584 * 2.0)).abs() < 1e-15);
    }

    #[test]
    fn nnls_clamps_negative_coefficients() {
        // y = 1 − 0.1 x has a negative slope; the non-negative fit is a constant.
        let x: Vec<Vec<f64>> = (0..10).map(|i| vec![1.0, i as f64]).collect();
        let y: Vec<f64> = (0..10).map(|i| 1.0 - 0.1 * i as f64).collect();
        let c = nnls(&x, &y, None).unwrap();
        assert_eq!(c[1], 0.0);
        assert!((c[0] - 0.55).abs() < 1e-12);
    }
}
