//! The assumptions each method makes of its data, tested on the data: a calibration that comes
//! out of a recording its method does not fit is still printed, with the checks that failed
//! (exit code 1), instead of passing as a confident result.
//!
//! The thresholds are stated with each check. They are meant to separate a recording the
//! method fits from one it does not, not to test the model at a significance level: every
//! checked-in scenario passes them, and the misuses seen in practice (EM on a run that turns,
//! a start distance metres off, a landmark seen from one place only) fail them by a wide margin.

use hilsim_recording::{wrap_angle, CommandSample, OdometrySample, Recording};
use serde::{Deserialize, Serialize};

use crate::calibration::lenient;
use crate::SensorModel;

/// One assumption tested on the data (interfaces.md: `checks`).
///
/// Read back from JSON, a check needs its `name` and `pass`; a figure that is not a number (a
/// NaN is written as `null`) reads as NaN and a missing `detail` as empty.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Check {
    /// What is tested, e.g. `lidar.bias_plausible`.
    pub name: String,
    /// The figure measured.
    #[serde(default = "lenient::nan", deserialize_with = "lenient::number_or_nan")]
    pub value: f64,
    /// The bound it is held to.
    #[serde(default = "lenient::nan", deserialize_with = "lenient::number_or_nan")]
    pub threshold: f64,
    /// Whether it held.
    pub pass: bool,
    /// In words: what the figure is and what a failure means.
    #[serde(default, deserialize_with = "lenient::or_default")]
    pub detail: String,
}

impl Check {
    /// A check that holds when `value <= threshold`.
    #[must_use]
    pub fn at_most(name: &str, value: f64, threshold: f64, detail: String) -> Self {
        Self {
            name: name.into(),
            value,
            threshold,
            pass: value <= threshold,
            detail,
        }
    }

    /// A check that holds when `value >= threshold`.
    #[must_use]
    pub fn at_least(name: &str, value: f64, threshold: f64, detail: String) -> Self {
        Self {
            name: name.into(),
            value,
            threshold,
            pass: value >= threshold,
            detail,
        }
    }
}

/// Largest plausible |alpha0| of a range sensor, metres: an XV-11's offset is a few centimetres
/// (the EM paper's Table I: 0.05 m; the landmark paper's Fig. 6), a sonar's its mount and
/// electronics delay, an odometer's none. Half a metre is ten times any of them.
pub const MAX_ABS_ALPHA0_M: f64 = 0.5;

/// Largest plausible |alpha1 − 1|: a scale 12 % low for the XV-11 (EM paper, Table I: 0.88), a
/// few per cent for a sonar's speed of sound or a wheel's radius. Half is four times any.
pub const MAX_SCALE_ERROR: f64 = 0.5;

/// Lags of the Ljung–Box test of whiteness: ten, the usual choice for a few hundred samples
/// (Ljung & Box, Biometrika 1978, use up to 20 for 200).
pub const LJUNG_BOX_LAGS: usize = 10;

/// The χ² quantile of ten degrees of freedom at 0.999 (standard tables): a white series
/// exceeds it once in a thousand runs, so a failure is evidence, not bad luck.
pub const CHI2_10_P999: f64 = 29.588;

/// The bias of `sensor`'s model is one a range sensor could have.
#[must_use]
pub fn bias_plausible(sensor: &str, model: &SensorModel) -> Vec<Check> {
    let alpha0 = model.alpha.first().copied().unwrap_or(0.0);
    let scale = model.alpha.get(1).copied().unwrap_or(1.0);
    vec![
        Check::at_most(
            &format!("{sensor}.offset_plausible"),
            alpha0.abs(),
            MAX_ABS_ALPHA0_M,
            format!(
                "|alpha0| = {:.3} m; a range sensor's offset is centimetres: more means the \
                 start distance or the target is wrong",
                alpha0.abs()
            ),
        ),
        Check::at_most(
            &format!("{sensor}.scale_plausible"),
            (scale - 1.0).abs(),
            MAX_SCALE_ERROR,
            format!(
                "|alpha1 - 1| = {:.3}; a range sensor's scale is within per cents of 1: more \
                 means the distances the method inferred are wrong",
                (scale - 1.0).abs()
            ),
        ),
    ]
}

/// The Ljung–Box statistic `Q = n(n+2) Σ_{k=1..h} ρ_k² / (n − k)` of `x` (time order), χ² with
/// `h` degrees of freedom for a white series; `None` with fewer than `4 h` values.
#[must_use]
pub fn ljung_box(x: &[f64], lags: usize) -> Option<f64> {
    let n = x.len();
    if n < 4 * lags || lags == 0 {
        return None;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let c0: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
    if c0.is_nan() || c0 <= 0.0 {
        return None;
    }
    let nf = n as f64;
    let q = (1..=lags)
        .map(|k| {
            let ck: f64 = x[k..]
                .iter()
                .zip(x)
                .map(|(a, b)| (a - mean) * (b - mean))
                .sum();
            let rho = ck / c0;
            rho * rho / (nf - k as f64)
        })
        .sum::<f64>();
    Some(nf * (nf + 2.0) * q)
}

/// How much a series' correlation in time inflates the variance of an estimate from it:
/// `1 + 2 Σ_{k=1..lags} ρ_k`, the factor by which `n` correlated values carry less information
/// than `n` independent ones (the "effective sample size" of time-series analysis, e.g.
/// Shumway & Stoffer, Time Series Analysis, 4th ed., Sec. 1.5). At least 1: a negative sum is
/// read as white. `None` with fewer than `4 lags` values.
#[must_use]
pub fn variance_inflation(x: &[f64], lags: usize) -> Option<f64> {
    let n = x.len();
    if n < 4 * lags || lags == 0 {
        return None;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let c0: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
    if !(c0.is_finite() && c0 > 0.0) {
        return None;
    }
    let sum: f64 = (1..=lags)
        .map(|k| {
            x[k..]
                .iter()
                .zip(x)
                .map(|(a, b)| (a - mean) * (b - mean))
                .sum::<f64>()
                / c0
        })
        .sum();
    Some((1.0 + 2.0 * sum).max(1.0))
}

/// Whiteness of a standardised residual series, as a check named `name`.
#[must_use]
pub fn white(name: &str, what: &str, residuals: &[f64]) -> Option<Check> {
    let q = ljung_box(residuals, LJUNG_BOX_LAGS)?;
    Some(Check::at_most(
        name,
        q,
        CHI2_10_P999,
        format!(
            "Ljung-Box Q({LJUNG_BOX_LAGS}) of the {what} = {q:.1} over {} values; above the \
             0.999 quantile of chi-square({LJUNG_BOX_LAGS}) they are correlated in time: the \
             model leaves structure (a drift, an effect it lacks)",
            residuals.len()
        ),
    ))
}

/// The robot's heading change and lateral drift from its start line, metres and radians, at
/// their largest over the run: from the odometry when the recording has it, else from the
/// commands.
#[must_use]
pub fn path_deviation(rec: &Recording) -> (f64, f64) {
    let base = rec.meta.robot.wheel_base_m;
    match rec.odometry.as_deref().filter(|o| o.len() >= 2) {
        Some(odo) => deviation_from_odometry(odo, base),
        None => deviation_from_commands(&rec.commands, base),
    }
}

/// Encoder readings averaged into each heading: the encoders' noise is per reading (a 4 mm
/// error on one wheel is 1° over a 0.23 m base), so the largest of raw headings measures the
/// noise, not the turn; fifteen readings cut it four-fold.
const HEADING_AVERAGE: usize = 15;

fn deviation_from_odometry(odo: &[OdometrySample], base: f64) -> (f64, f64) {
    let (l0, r0) = (odo[0].left_m, odo[0].right_m);
    let heading = |s: &OdometrySample| ((s.right_m - r0) - (s.left_m - l0)) / base;
    let (mut y, mut max_y) = (0.0_f64, 0.0_f64);
    for w in odo.windows(2) {
        let ds = ((w[1].left_m - w[0].left_m) + (w[1].right_m - w[0].right_m)) / 2.0;
        let (h0, h1) = (heading(&w[0]), heading(&w[1]));
        y += ds * (h0 + wrap_angle(h1 - h0) / 2.0).sin();
        max_y = max_y.max(y.abs());
    }
    let headings: Vec<f64> = odo.iter().map(heading).collect();
    let window = HEADING_AVERAGE.min(headings.len());
    let max_yaw = headings
        .windows(window)
        .map(|w| wrap_angle(w.iter().sum::<f64>() / window as f64).abs())
        .fold(0.0, f64::max);
    (max_yaw, max_y)
}

fn deviation_from_commands(commands: &[CommandSample], base: f64) -> (f64, f64) {
    let (mut yaw, mut y, mut max_yaw, mut max_y) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    for w in commands.windows(2) {
        let dt = w[1].t_s - w[0].t_s;
        if dt.is_nan() || dt <= 0.0 {
            continue;
        }
        let c = &w[0];
        let v = (c.left_mps + c.right_mps) / 2.0;
        let dyaw = (c.right_mps - c.left_mps) / base * dt;
        y += v * dt * (yaw + dyaw / 2.0).sin();
        yaw += dyaw;
        max_yaw = max_yaw.max(wrap_angle(yaw).abs());
        max_y = max_y.max(y.abs());
    }
    (max_yaw, max_y)
}

/// Largest heading change over a "straight" run: 10°. The EM paper's robot drives straight at
/// a board; 10° off, the beam meets the board 1.5 % farther than the line it drives.
pub const MAX_HEADING_CHANGE_DEG: f64 = 10.0;

/// Largest lateral drift from the start line: 0.25 m, a fifth of the EM paper's 1.2 m board (the
/// beam must stay on one target).
pub const MAX_LATERAL_DRIFT_M: f64 = 0.25;

/// The robot moved on a line (EM, ground truth on one target): heading and lateral drift.
#[must_use]
pub fn on_a_line(rec: &Recording) -> Vec<Check> {
    let (yaw, lateral) = path_deviation(rec);
    let source = if rec.odometry.as_ref().is_some_and(|o| o.len() >= 2) {
        "odometry"
    } else {
        "commands"
    };
    vec![
        Check::at_most(
            "path.heading_change_deg",
            yaw.to_degrees(),
            MAX_HEADING_CHANGE_DEG,
            format!(
                "the robot turned up to {:.1} deg from its start heading ({source}); the method \
                 follows one target along one straight line",
                yaw.to_degrees()
            ),
        ),
        Check::at_most(
            "path.lateral_drift_m",
            lateral,
            MAX_LATERAL_DRIFT_M,
            format!(
                "the robot drifted up to {lateral:.3} m sideways from its start line \
                 ({source}); the beam may have left the target"
            ),
        ),
    ]
}

/// Smallest R² of the target beam's readings against a quadratic in the commanded distance:
/// 0.95. A beam that follows one target along the run reads a smooth function of the distance
/// driven (the XV-11's noise is ~1 % of the range); one that sweeps across other objects does
/// not.
pub const MIN_TARGET_R2: f64 = 0.95;

/// The target beam's readings follow the commanded distance (R² of a quadratic fit).
#[must_use]
pub fn target_follows_commands(commanded_m: &[f64], lidar_m: &[Option<f64>]) -> Option<Check> {
    let pairs: Vec<(f64, f64)> = commanded_m
        .iter()
        .zip(lidar_m)
        .filter_map(|(&d, y)| y.map(|y| (d, y)))
        .collect();
    let r2 = quadratic_r2(&pairs)?;
    Some(Check::at_least(
        "lidar.target_follows_commands",
        r2,
        MIN_TARGET_R2,
        format!(
            "R² = {r2:.3} of the target beam's {} readings against a quadratic in the commanded \
             distance; low means the beam does not see one target throughout the run",
            pairs.len()
        ),
    ))
}

/// R² of the least-squares quadratic `y ≈ a + b x + c x²`; `None` with fewer than 10 points or
/// no spread.
fn quadratic_r2(pairs: &[(f64, f64)]) -> Option<f64> {
    if pairs.len() < 10 {
        return None;
    }
    let (x, y): (Vec<f64>, Vec<f64>) = pairs.iter().copied().unzip();
    let fit = crate::landmarks::regression::fit_poly(&x, &y, None, 2)?;
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let total: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
    (total > 0.0).then(|| 1.0 - fit.rss / total)
}

/// Bounds on the mean squared standardised innovation: [0.5, 2]. It is 1 when the fitted noise
/// is the data's; with 100 innovations its sampling sd is 0.14, so a value outside says the
/// noise model is off by a factor √2 or more.
pub const INNOVATION_SIZE: [f64; 2] = [0.5, 2.0];

/// The lidar's standardised innovations are of the fitted size and white (EM and `smooth`).
#[must_use]
pub fn lidar_innovations(standardised: &[f64]) -> Vec<Check> {
    innovations_sized("lidar.innovation_size", standardised)
        .into_iter()
        .chain(white(
            "lidar.innovations_white",
            "lidar's standardised innovations",
            standardised,
        ))
        .collect()
}

/// The innovations are of the fitted size: the mean of ν²/S.
#[must_use]
pub fn innovations_sized(name: &str, standardised: &[f64]) -> Option<Check> {
    if standardised.len() < 10 {
        return None;
    }
    let size = standardised.iter().map(|v| v * v).sum::<f64>() / standardised.len() as f64;
    let [lo, hi] = INNOVATION_SIZE;
    Some(Check {
        name: name.into(),
        value: size,
        threshold: if size < lo { lo } else { hi },
        pass: (lo..=hi).contains(&size),
        detail: format!(
            "mean squared standardised innovation {size:.2} over {} readings (1 when the \
             fitted noise is the data's; allowed {lo}-{hi})",
            standardised.len()
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_noise_passes_and_a_random_walk_fails_the_ljung_box_test() {
        // A fixed pseudo-random sequence (xorshift), centred.
        let mut s = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let noise: Vec<f64> = (0..400).map(|_| next()).collect();
        assert!(ljung_box(&noise, 10).unwrap() < CHI2_10_P999);
        let walk: Vec<f64> = noise
            .iter()
            .scan(0.0, |w, v| {
                *w += v;
                Some(*w)
            })
            .collect();
        assert!(ljung_box(&walk, 10).unwrap() > 10.0 * CHI2_10_P999);
        assert!(ljung_box(&noise[..20], 10).is_none());
    }

    #[test]
    fn a_quadratic_through_noise_has_r2_near_one_and_a_sweep_does_not() {
        let smooth: Vec<(f64, f64)> = (0..100)
            .map(|i| {
                let x = f64::from(i) * 0.035;
                (
                    x,
                    0.05 + 0.88 * x + 0.06 * x * x + 0.002 * (f64::from(i) * 1.7).sin(),
                )
            })
            .collect();
        assert!(quadratic_r2(&smooth).unwrap() > 0.999);
        let sweep: Vec<(f64, f64)> = (0..100)
            .map(|i| (f64::from(i) * 0.035, 1.0 + (f64::from(i) * 2.3).sin()))
            .collect();
        assert!(quadratic_r2(&sweep).unwrap() < 0.2);
    }

    #[test]
    fn the_emitted_bias_of_a_wrong_start_fails_plausibility() {
        let garbage = SensorModel::without_sd(vec![-1.68, 1.84, -0.07], vec![0.0, 0.0, 0.015]);
        assert!(bias_plausible("lidar", &garbage).iter().all(|c| !c.pass));
        let xv11 = SensorModel::without_sd(vec![0.0525, 0.8838, 0.0584], vec![0.0, 0.0, 0.004]);
        assert!(bias_plausible("lidar", &xv11).iter().all(|c| c.pass));
    }
}
