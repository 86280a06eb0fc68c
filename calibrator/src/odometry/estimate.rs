//! From tuples to a [`Calibration`]: the closed form, the maximum-likelihood estimate, the
//! checks and the notes.

use std::collections::BTreeMap;

use super::checks::odometry_checks;
use super::closed_form::closed_form;
use super::interval::Interval;
use super::likelihood::maximum_likelihood;
use super::tuples::Tuple;
use crate::{Calibration, CalibrationError, Method, OdometryModel};

/// Calibrates the wheels and the lidar's mount from the paper's `tuples`; `unsound` tuples (a non-finite
/// number, an interval without a length) were left out before and are counted in a note.
///
/// # Errors
/// As the estimate's: too few tuples, a drive that does not inform every parameter, an estimate
/// that diverged.
pub fn calibrate_tuples(tuples: &[Tuple], unsound: usize) -> Result<Calibration, CalibrationError> {
    let intervals: Vec<Interval> = tuples.iter().map(Interval::from).collect();
    let mut calibration = calibrate_intervals(&intervals)?;
    if unsound > 0 {
        calibration.notes.push(format!(
            "{unsound} tuple(s) left out before the estimate: a non-finite number or no length"
        ));
    }
    Ok(calibration)
}

/// Calibrates the wheels and the lidar's mount from `intervals`.
///
/// # Errors
/// As [`calibrate_tuples`].
pub fn calibrate_intervals(tuples: &[Interval]) -> Result<Calibration, CalibrationError> {
    if tuples.len() < 12 {
        return Err(CalibrationError::TooFewSamples(format!(
            "{} intervals; at least 12 are needed for 6 parameters and the 6 of the scan \
             matcher's error",
            tuples.len()
        )));
    }
    let start = closed_form(tuples)?;
    let fit = maximum_likelihood(tuples, start)?;
    let g = fit.geometry;
    let model = OdometryModel {
        left_wheel_radius_m: g.left_radius_m,
        right_wheel_radius_m: g.right_radius_m,
        wheel_base_m: g.wheel_base_m,
        lidar_x_m: g.lidar[0],
        lidar_y_m: g.lidar[1],
        lidar_yaw_rad: g.lidar[2],
        covariance: fit.covariance,
        wheel_scale: None,
        lidar_latency_s: None,
        lidar_latency_sd_s: None,
    };
    let used = fit.inlier.iter().filter(|&&i| i).count();
    let notes = vec![
        format!(
            "closed form (the paper's): wheel radii {:.3} and {:.3} mm, wheel base {:.3} mm, \
             lidar at ({:.2}, {:.2}) mm, {:.2} mrad",
            start.left_radius_m * 1e3,
            start.right_radius_m * 1e3,
            start.wheel_base_m * 1e3,
            start.lidar[0] * 1e3,
            start.lidar[1] * 1e3,
            start.lidar[2] * 1e3
        ),
        format!(
            "{used} of {} intervals used; {} left out as outliers (Mahalanobis residual beyond \
             the 0.999 quantile of chi-square(3))",
            tuples.len(),
            tuples.len() - used
        ),
        format!(
            "scan matcher's error estimated from the residuals: sd x {:.2} mm, y {:.2} mm, \
             theta {:.2} mrad",
            fit.measurement_covariance[0][0].sqrt() * 1e3,
            fit.measurement_covariance[1][1].sqrt() * 1e3,
            fit.measurement_covariance[2][2].sqrt() * 1e3
        ),
        format!(
            "the residuals' correlation in time inflates the variance {:.2}-fold; the \
             covariance is widened by it",
            fit.variance_inflation
        ),
    ];
    let checks = odometry_checks(tuples, &fit, &model);
    Ok(Calibration {
        method: Method::Odometry,
        sensors: BTreeMap::new(),
        iterations: fit.rounds,
        converged: fit.converged,
        metrics: None,
        order: None,
        landmarks: None,
        odometry: Some(model),
        checks,
        notes,
    })
}
