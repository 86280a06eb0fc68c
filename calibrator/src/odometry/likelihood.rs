//! The maximum-likelihood estimate (Censi et al. 2013, Sec. V): the scan-matched motions are
//! the measurements, with a Gaussian error of unknown covariance `Σ` shared by every interval;
//! the wheel speeds are taken as exact over an interval (the paper's assumption: their error is
//! small against the scan matcher's at these intervals). Gauss–Newton on the six parameters,
//! alternating with `Σ` as the residuals' covariance, and with intervals whose residual is
//! improbable under `Σ` left out until the set settles. The covariance of the estimate is the
//! inverse of the Fisher information at the estimate, the Cramér–Rao bound the paper reports.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

use super::interval::Interval;
use super::kinematics::{residual, Geometry, PARAMETERS};
use crate::checks::{variance_inflation, LJUNG_BOX_LAGS};
use crate::CalibrationError;

type Jacobian = SMatrix<f64, 3, PARAMETERS>;
type Information = SMatrix<f64, PARAMETERS, PARAMETERS>;

/// The 0.999 quantile of χ² with 3 degrees of freedom: an interval whose Mahalanobis residual
/// exceeds it is an outlier (a scan match gone wrong, a wheel that slipped) with probability
/// 0.999 under the Gaussian model.
pub const OUTLIER_CHI2_3: f64 = 16.266;

/// Most rounds of fitting, re-estimating `Σ` and re-selecting the inliers.
const MAX_ROUNDS: usize = 30;

/// Most Gauss–Newton steps within a round.
const MAX_STEPS: usize = 20;

/// What the estimate found.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The estimate.
    pub geometry: Geometry,
    /// Its covariance, in [`Geometry::to_array`]'s order.
    pub covariance: [[f64; PARAMETERS]; PARAMETERS],
    /// The scan matcher's error covariance, estimated from the inliers' residuals (x, y, θ).
    pub measurement_covariance: [[f64; 3]; 3],
    /// Which intervals were used (false: left out as outliers).
    pub inlier: Vec<bool>,
    /// Each tuple's residual (observed − predicted lidar motion), whitened by `Σ`, in order.
    pub whitened: Vec<[f64; 3]>,
    /// How much the residuals' correlation in time inflates the estimate's variance (the
    /// largest of the three axes', at least 1); `covariance` includes it.
    pub variance_inflation: f64,
    /// Rounds run.
    pub rounds: usize,
    /// Whether the inliers and the estimate settled before the round limit.
    pub converged: bool,
}

/// The maximum-likelihood geometry of `intervals`, from the closed-form `start`.
///
/// # Errors
/// [`CalibrationError::Unidentifiable`] when the information matrix is singular (a parameter the
/// drive does not inform), [`CalibrationError::Diverged`] when the estimate leaves finite
/// numbers, [`CalibrationError::TooFewSamples`] when fewer than a dozen intervals remain.
pub fn maximum_likelihood(
    intervals: &[Interval],
    start: Geometry,
) -> Result<Fit, CalibrationError> {
    let mut p = SVector::<f64, PARAMETERS>::from(start.to_array());
    let mut inlier = vec![true; intervals.len()];
    let mut sigma = residual_covariance(intervals, &inlier, &p)?;
    let mut converged = false;
    let mut rounds = 0;
    while rounds < MAX_ROUNDS {
        rounds += 1;
        let weight = inverse(&sigma)?;
        p = gauss_newton(intervals, &inlier, p, &weight)?;
        sigma = residual_covariance(intervals, &inlier, &p)?;
        let weight = inverse(&sigma)?;
        let next: Vec<bool> = intervals
            .iter()
            .map(|t| {
                let e = residual_of(t, &p);
                (e.transpose() * weight * e)[0] <= OUTLIER_CHI2_3
            })
            .collect();
        if next == inlier {
            converged = true;
            break;
        }
        inlier = next;
    }
    let weight = inverse(&sigma)?;
    let mut information = Information::zeros();
    for (t, _) in intervals.iter().zip(&inlier).filter(|(_, &i)| i) {
        let j = jacobian(t, &p);
        information += j.transpose() * weight * j;
    }
    let covariance = information.try_inverse().ok_or_else(|| {
        CalibrationError::Unidentifiable(
            "the drive does not inform every parameter (a singular information matrix)".into(),
        )
    })?;
    let whitener = sigma
        .cholesky()
        .and_then(|c| c.l().try_inverse())
        .ok_or_else(|| {
            CalibrationError::Diverged("the residuals' covariance is singular".into())
        })?;
    let whitened: Vec<[f64; 3]> = intervals
        .iter()
        .map(|t| {
            let w = whitener * residual_of(t, &p);
            [w[0], w[1], w[2]]
        })
        .collect();
    // The bound assumes independent intervals. Real ones are not quite (the paper's own show a
    // lag-one correlation near 0.2: consecutive matches share a scan, the floor's grip drifts),
    // and the bound would then understate the spread; a departure from the paper, the
    // covariance is widened by the variance inflation of the most correlated axis.
    let variance_inflation = (0..3)
        .filter_map(|k| {
            let series: Vec<f64> = whitened
                .iter()
                .zip(&inlier)
                .filter(|(_, &i)| i)
                .map(|(w, _)| w[k])
                .collect();
            variance_inflation(&series, LJUNG_BOX_LAGS)
        })
        .fold(1.0, f64::max);
    let geometry = Geometry::from_array(p.into());
    Ok(Fit {
        geometry,
        covariance: (covariance * variance_inflation).into(),
        variance_inflation,
        measurement_covariance: sigma.into(),
        inlier,
        whitened,
        rounds,
        converged,
    })
}

fn inverse(sigma: &Matrix3<f64>) -> Result<Matrix3<f64>, CalibrationError> {
    sigma
        .try_inverse()
        .filter(|w| w.iter().all(|v| v.is_finite()))
        .ok_or_else(|| {
            CalibrationError::Diverged(
                "the scan matches' residuals have no spread in some direction (a singular \
                 covariance): the intervals are not measurements"
                    .into(),
            )
        })
}

/// The covariance of the inliers' residuals at `p` (the ML estimate of `Σ`).
fn residual_covariance(
    intervals: &[Interval],
    inlier: &[bool],
    p: &SVector<f64, PARAMETERS>,
) -> Result<Matrix3<f64>, CalibrationError> {
    let mut sum = Matrix3::<f64>::zeros();
    let mut n = 0usize;
    for (t, _) in intervals.iter().zip(inlier).filter(|(_, &i)| i) {
        let e = residual_of(t, p);
        sum += e * e.transpose();
        n += 1;
    }
    if n < 12 {
        return Err(CalibrationError::TooFewSamples(format!(
            "{n} intervals left of {}; at least 12 are needed for 6 parameters and the 6 of the \
             scan matcher's error",
            intervals.len()
        )));
    }
    let sigma = sum / n as f64;
    if sigma.iter().all(|v| v.is_finite()) {
        Ok(sigma)
    } else {
        Err(CalibrationError::Diverged(
            "the residuals left finite numbers".into(),
        ))
    }
}

fn residual_of(t: &Interval, p: &SVector<f64, PARAMETERS>) -> Vector3<f64> {
    let g = Geometry::from_array((*p).into());
    let predicted = g.lidar_motion(g.robot_motion(&t.wheel_turns_rad));
    Vector3::from(residual(t.lidar_motion, predicted))
}

/// `∂e/∂p` by central differences, each step a millionth of the parameter's scale.
fn jacobian(t: &Interval, p: &SVector<f64, PARAMETERS>) -> Jacobian {
    let mut j = Jacobian::zeros();
    for k in 0..PARAMETERS {
        // Radii and base in metres scale with themselves; the mount's offsets with the base;
        // its yaw with a radian.
        let scale = match k {
            0..=2 => p[k].abs(),
            3 | 4 => p[2].abs(),
            _ => 1.0,
        }
        .max(1e-6);
        let h = scale * 1e-6;
        let (mut up, mut down) = (*p, *p);
        up[k] += h;
        down[k] -= h;
        let column = (residual_of(t, &up) - residual_of(t, &down)) / (2.0 * h);
        j.set_column(k, &column);
    }
    j
}

/// Gauss–Newton on the inliers' Mahalanobis cost, each step halved until it lowers the cost.
fn gauss_newton(
    intervals: &[Interval],
    inlier: &[bool],
    mut p: SVector<f64, PARAMETERS>,
    weight: &Matrix3<f64>,
) -> Result<SVector<f64, PARAMETERS>, CalibrationError> {
    let cost = |p: &SVector<f64, PARAMETERS>| -> f64 {
        intervals
            .iter()
            .zip(inlier)
            .filter(|(_, &i)| i)
            .map(|(t, _)| {
                let e = residual_of(t, p);
                (e.transpose() * weight * e)[0]
            })
            .sum()
    };
    let mut current = cost(&p);
    for _ in 0..MAX_STEPS {
        let (mut h, mut g) = (Information::zeros(), SVector::<f64, PARAMETERS>::zeros());
        for (t, _) in intervals.iter().zip(inlier).filter(|(_, &i)| i) {
            let j = jacobian(t, &p);
            let e = residual_of(t, &p);
            h += j.transpose() * weight * j;
            g += j.transpose() * weight * e;
        }
        let Some(step) = h.cholesky().map(|c| c.solve(&g)) else {
            return Err(CalibrationError::Unidentifiable(
                "the drive does not inform every parameter (a singular information matrix)".into(),
            ));
        };
        // Linearised, e(p + δ) ≈ e + J δ, least at δ = −H⁻¹ g.
        let mut scale = 1.0;
        let mut accepted = false;
        for _ in 0..30 {
            let candidate = p - step * scale;
            let c = cost(&candidate);
            if c.is_finite() && c <= current {
                let gain = current - c;
                p = candidate;
                current = c;
                accepted = true;
                if gain <= 1e-9 * current.max(1.0) {
                    return finite(p);
                }
                break;
            }
            scale /= 2.0;
        }
        if !accepted {
            break;
        }
    }
    finite(p)
}

fn finite(p: SVector<f64, PARAMETERS>) -> Result<SVector<f64, PARAMETERS>, CalibrationError> {
    if p.iter().all(|v| v.is_finite()) {
        Ok(p)
    } else {
        Err(CalibrationError::Diverged(
            "the estimate left finite numbers".into(),
        ))
    }
}
