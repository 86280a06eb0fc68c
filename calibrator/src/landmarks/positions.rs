//! Landmark positions by the weighted least-squares intersection of bearings, the paper's
//! eqs. (18)–(25), from the nominal stop positions.
//!
//! Each bearing θ̃ₖ from the nominal sensor position (xₖ, yₖ) gives one line, eq. (9):
//! `sin θ̃ₖ · x − cos θ̃ₖ · y = sin θ̃ₖ · xₖ − cos θ̃ₖ · yₖ`, a row hₖ of H and an entry bₖ of b
//! (eq. (19); eq. (22) prints b with the opposite sign, which would reflect the estimate through
//! the origin, so we follow (9) and (19)). The estimate is ĉ = (Hᵀ W H)⁻¹ Hᵀ W b, eq. (23)
//! (eq. (20) prints `W Hᵀ b`, whose dimensions do not agree; Aitken's estimator is `Hᵀ W b`).
//!
//! The residual of line k is, to first order, eq. (24): `sin θ eₓ − cos θ e_y + d̃ₖ νₖ`, with
//! variance σs² + σθ² d̃ₖ². The paper's weights W_l (eq. (19)) are 1/var(d̃ₖ); with its
//! simulation's β = 0.05 α, var(d̃ₖ) = 0.0025 E[d̃ₖ]², so W_l is 1/d̃ₖ² up to a constant: the
//! exact weight when σs = 0. [`Weights::Paper`] uses 1/d̃ₖ². Eq. (25) adds the precisions
//! (σs⁻² I + σθ⁻² W_l) where the variances add; [`Weights::Residual`] uses the residual variance
//! itself, 1/(σs² + σθ² d̃ₖ²), with σs and σθ estimated by [`variance_components`].

use super::regression::nnls;

/// One bearing line: a bearing taken from a nominal sensor position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BearingLine {
    /// Nominal sensor position, metres, start-pose frame.
    pub sensor: [f64; 2],
    /// Bearing of the landmark's centre, radians, start-pose frame.
    pub bearing_rad: f64,
    /// The distance the weights scale with, metres: the raw reading d̃ₖ for the paper's weights,
    /// the centre distance |ĉ − sₖ| of a first estimate for the residual-variance weights.
    pub range_m: f64,
}

/// The weights W of eq. (23).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Weights {
    /// The paper's W_l, eq. (19): 1/d̃ₖ² (see the module docs).
    Paper,
    /// The inverse residual variance of eq. (24): 1/(σs² + σθ² d̃ₖ²).
    Residual {
        /// σs², m².
        sigma_s2: f64,
        /// σθ², rad².
        sigma_theta2: f64,
    },
}

impl Weights {
    fn of(&self, line: &BearingLine) -> f64 {
        let d2 = line.range_m.max(1e-3).powi(2);
        match *self {
            Weights::Paper => 1.0 / d2,
            Weights::Residual {
                sigma_s2,
                sigma_theta2,
            } => 1.0 / (sigma_s2 + sigma_theta2 * d2),
        }
    }
}

/// Why the bearings do not fix a position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PositionError {
    /// Fewer than two bearings.
    TooFewBearings,
    /// The bearings are (nearly) parallel: their spread, radians, is below the minimum.
    Colinear(f64),
    /// The lines meet behind the sensor.
    Behind,
}

/// Bearings whose weighted spread is below this do not intersect meaningfully: half a degree,
/// the XV-11's ±0.5° angular quantisation. (For two lines at angle δ the eigenvalue ratio of
/// HᵀWH is tan²(δ/2), i.e. the squared spread.)
pub const MIN_BEARING_SPREAD_RAD: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// One landmark's estimated position.
#[derive(Debug, Clone, PartialEq)]
pub struct Position {
    /// ĉ, metres, start-pose frame.
    pub centre: [f64; 2],
    /// (HᵀWH)⁻¹, the covariance of ĉ when the weights are inverse variances.
    pub cov: [[f64; 2]; 2],
    /// Residuals hₖ ĉ − bₖ of the lines, metres.
    pub residuals: Vec<f64>,
    /// Leverages wₖ hₖᵀ (HᵀWH)⁻¹ hₖ of the lines.
    pub leverages: Vec<f64>,
}

/// Eq. (23): the weighted least-squares intersection of the bearing lines.
///
/// # Errors
/// Fewer than two lines, (nearly) parallel bearings, or an intersection behind the sensors.
pub fn intersect(lines: &[BearingLine], weights: Weights) -> Result<Position, PositionError> {
    if lines.len() < 2 {
        return Err(PositionError::TooFewBearings);
    }
    let (mut a11, mut a12, mut a22, mut g1, mut g2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for l in lines {
        let w = weights.of(l);
        let (s, c) = l.bearing_rad.sin_cos();
        let (h1, h2) = (s, -c);
        let b = s * l.sensor[0] - c * l.sensor[1];
        a11 += w * h1 * h1;
        a12 += w * h1 * h2;
        a22 += w * h2 * h2;
        g1 += w * h1 * b;
        g2 += w * h2 * b;
    }
    let tr = a11 + a22;
    let det = a11 * a22 - a12 * a12;
    let disc = (tr * tr / 4.0 - det).max(0.0).sqrt();
    let (lmin, lmax) = (tr / 2.0 - disc, tr / 2.0 + disc);
    let spread = if lmax > 0.0 {
        (lmin.max(0.0) / lmax).sqrt()
    } else {
        0.0
    };
    let spread_ok = spread >= MIN_BEARING_SPREAD_RAD && det > 0.0;
    if !spread_ok {
        return Err(PositionError::Colinear(spread));
    }
    let inv = [[a22 / det, -a12 / det], [-a12 / det, a11 / det]];
    let centre = [
        inv[0][0] * g1 + inv[0][1] * g2,
        inv[1][0] * g1 + inv[1][1] * g2,
    ];
    let mut behind = 0;
    let mut residuals = Vec::with_capacity(lines.len());
    let mut leverages = Vec::with_capacity(lines.len());
    for l in lines {
        let (s, c) = l.bearing_rad.sin_cos();
        let (h1, h2) = (s, -c);
        let b = s * l.sensor[0] - c * l.sensor[1];
        residuals.push(h1 * centre[0] + h2 * centre[1] - b);
        let q = h1 * (inv[0][0] * h1 + inv[0][1] * h2) + h2 * (inv[1][0] * h1 + inv[1][1] * h2);
        leverages.push(weights.of(l) * q);
        if (centre[0] - l.sensor[0]) * c + (centre[1] - l.sensor[1]) * s <= 0.0 {
            behind += 1;
        }
    }
    if 2 * behind > lines.len() {
        return Err(PositionError::Behind);
    }
    Ok(Position {
        centre,
        cov: inv,
        residuals,
        leverages,
    })
}

/// σs² and σθ² of eq. (24) from the lines' residuals: the squared residuals (leverage-corrected)
/// regressed on [1, ρ²] (ρ the lines' `range_m`) with non-negative coefficients; with σs² given,
/// σθ² alone from the squared residuals less σs². Floored at (1 mm)² and (0.05°)² (a tenth of
/// the XV-11's half-degree quantisation) so that neither group of the joint refinement gets an
/// unbounded weight when the data cannot separate the two.
#[must_use]
pub fn variance_components(
    lines: &[&[BearingLine]],
    fits: &[&Position],
    sigma_s2: Option<f64>,
) -> (f64, f64) {
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for (ls, p) in lines.iter().zip(fits) {
        for ((l, r), h) in ls.iter().zip(&p.residuals).zip(&p.leverages) {
            x.push(vec![1.0, l.range_m.powi(2)]);
            y.push(r * r / (1.0 - h).max(0.05));
        }
    }
    let floor_s2 = 1e-6;
    let floor_t2 = (0.05f64.to_radians()).powi(2);
    if y.len() < 3 {
        return (sigma_s2.unwrap_or(floor_s2), floor_t2);
    }
    match sigma_s2 {
        Some(s2) => {
            let rows: Vec<Vec<f64>> = x.iter().map(|r| vec![r[1]]).collect();
            let z: Vec<f64> = y.iter().map(|v| v - s2).collect();
            let t2 = nnls(&rows, &z, None).map_or(0.0, |c| c[0]);
            (s2, t2.max(floor_t2))
        }
        None => {
            let coef = nnls(&x, &y, None).unwrap_or_else(|| vec![0.0, 0.0]);
            (coef[0].max(floor_s2), coef[1].max(floor_t2))
        }
    }
}

/// The bias of eq. (23) to second order in the bearing errors, for a landmark at `centre` seen
/// from `sensors` with weights `weights`.
///
/// Eq. (23) is linear in b but not in H, which holds the measured bearings: it is an
/// errors-in-variables estimator, unbiased to first order only. With δₖ = θ̃ₖ − θₖ the error of
/// bearing k relative to the nominal sensor position (variance σθ² + σs²/ρₖ²: a stop off its
/// nominal position by e turns the bearing by e⊥/ρ), nₖ = (sin θₖ, −cos θₖ), uₖ the unit vector
/// towards the landmark, ρₖ the distance and A₀ = Σ wₖ nₖ nₖᵀ, expanding ĉ − c =
/// −A(δ)⁻¹ Σ wₖ ñₖ ρₖ sin δₖ to second order gives
///
/// ```text
/// E[ĉ − c] ≈ A₀⁻¹ [ −Σ wₖ ρₖ σₖ² uₖ + Σ wₖ² ρₖ σₖ² (nₖuₖᵀ + uₖnₖᵀ) A₀⁻¹ nₖ ].
/// ```
///
/// The first term pulls the estimate towards the sensors along the lines of sight (the classic
/// attenuation of errors in variables).
#[must_use]
pub fn second_order_bias(
    centre: [f64; 2],
    sensors: &[[f64; 2]],
    weights: &[f64],
    sigma_theta_rad: f64,
    sigma_s_m: f64,
) -> [f64; 2] {
    let geo: Vec<([f64; 2], [f64; 2], f64, f64)> = sensors
        .iter()
        .zip(weights)
        .map(|(s, w)| {
            let (dx, dy) = (centre[0] - s[0], centre[1] - s[1]);
            let rho = dx.hypot(dy);
            let u = [dx / rho, dy / rho];
            let n = [u[1], -u[0]];
            (n, u, rho, *w)
        })
        .collect();
    let (mut a11, mut a12, mut a22) = (0.0, 0.0, 0.0);
    for (n, _, _, w) in &geo {
        a11 += w * n[0] * n[0];
        a12 += w * n[0] * n[1];
        a22 += w * n[1] * n[1];
    }
    let det = a11 * a22 - a12 * a12;
    if det <= 0.0 {
        return [f64::NAN; 2];
    }
    let inv = |v: [f64; 2]| {
        [
            (a22 * v[0] - a12 * v[1]) / det,
            (-a12 * v[0] + a11 * v[1]) / det,
        ]
    };
    let mut t = [0.0; 2];
    for (n, u, rho, w) in &geo {
        let s2 = sigma_theta_rad.powi(2) + (sigma_s_m / rho).powi(2);
        let an = inv(*n);
        // (n uᵀ + u nᵀ) A₀⁻¹ n = n (u·A₀⁻¹n) + u (n·A₀⁻¹n)
        let un = u[0] * an[0] + u[1] * an[1];
        let nn = n[0] * an[0] + n[1] * an[1];
        for k in 0..2 {
            t[k] += -w * rho * s2 * u[k] + w * w * rho * s2 * (n[k] * un + u[k] * nn);
        }
    }
    inv(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines_to(c: [f64; 2], sensors: &[[f64; 2]]) -> Vec<BearingLine> {
        sensors
            .iter()
            .map(|s| BearingLine {
                sensor: *s,
                bearing_rad: (c[1] - s[1]).atan2(c[0] - s[0]),
                range_m: (c[0] - s[0]).hypot(c[1] - s[1]),
            })
            .collect()
    }

    #[test]
    fn exact_bearings_intersect_at_the_landmark() {
        let sensors: Vec<[f64; 2]> = (0..10).map(|k| [0.3 * k as f64, 0.0]).collect();
        let lines = lines_to([1.5, 2.0], &sensors);
        let p = intersect(&lines, Weights::Paper).unwrap();
        assert!((p.centre[0] - 1.5).abs() < 1e-12 && (p.centre[1] - 2.0).abs() < 1e-12);
        assert!(p.residuals.iter().all(|r| r.abs() < 1e-12));
    }

    #[test]
    fn parallel_bearings_are_colinear() {
        let sensors: Vec<[f64; 2]> = (0..10).map(|k| [0.3 * k as f64, 0.0]).collect();
        let lines = lines_to([6.0, 0.0], &sensors);
        assert!(matches!(
            intersect(&lines, Weights::Paper),
            Err(PositionError::Colinear(_))
        ));
        assert_eq!(
            intersect(&lines[..1], Weights::Paper),
            Err(PositionError::TooFewBearings)
        );
    }
}
