//! The method's assumptions tested on the data ([`crate::checks`]): the drive turned both ways
//! and drove straight enough for every parameter to be observable, each parameter is known to a
//! useful precision, few intervals were outliers, and what is left is nearly white.

use super::interval::Interval;
use super::likelihood::Fit;
use crate::checks::Check;
use crate::OdometryModel;

/// Least turning each way: a quarter turn. Turning one way only, a wheel's radius trades
/// against the lidar's sideways offset (both bend the sensed path the same way); a quarter turn
/// each way puts the lidar's offset on both sides of the turn centre.
pub const MIN_TURN_EACH_WAY_DEG: f64 = 90.0;

/// Least straight driving, in wheel bases: 10. Turning alone fixes only the radii over the base
/// (the paper's J₂₁, J₂₂); straight travel sets their scale, and over 10 wheel bases a 1 % error
/// of scale moves the lidar by a tenth of a base, well above a scan matcher's millimetres.
pub const MIN_STRAIGHT_WHEEL_BASES: f64 = 10.0;

/// An interval is straight when its path bends on a radius of at least this many wheel bases:
/// 5 (a wheel then turns at least 80 % as fast as the other). Wheels a few per cent off bend a
/// commanded straight line on a radius of tens of wheel bases, which still counts.
pub const STRAIGHT_RADIUS_WHEEL_BASES: f64 = 5.0;

/// Largest relative standard deviation of a wheel radius or the wheel base: 0.5 %. The errors
/// the calibration exists to find are 1–5 % (a worn or soft tyre, an axle measured to its
/// wheels' outer edges); above 0.5 % it cannot tell them from nothing.
pub const MAX_RELATIVE_SD: f64 = 0.005;

/// Largest standard deviation of the lidar's position: 1 cm, the size of the mount errors a
/// bracket made by hand has.
pub const MAX_POSITION_SD_M: f64 = 0.01;

/// Largest standard deviation of the lidar's yaw: 0.5° (8.7 mrad); a 1° yaw error puts a wall
/// 4 m ahead 7 cm aside.
pub const MAX_YAW_SD_RAD: f64 = 0.008_726_646;

/// Largest share of intervals left out as outliers: 10 %. More means the scan matcher or the
/// wheels fail often (slipping wheels, a featureless room): the rest is not a random sample.
pub const MAX_OUTLIER_SHARE: f64 = 0.10;

/// Largest variance inflation from the residuals' correlation in time: 4, standard deviations
/// understated twofold by the white model. The paper's own data inflate it about 2-fold.
pub const MAX_VARIANCE_INFLATION: f64 = 4.0;

/// The checks of a fit of `intervals`.
#[must_use]
pub fn odometry_checks(intervals: &[Interval], fit: &Fit, model: &OdometryModel) -> Vec<Check> {
    let mut checks = Vec::new();
    let (mut left, mut right, mut straight_m) = (0.0f64, 0.0f64, 0.0f64);
    let base = model.wheel_base_m.abs().max(1e-9);
    for t in intervals {
        let [x, y, turn] = t.lidar_motion;
        if turn > 0.0 {
            left += turn;
        } else {
            right -= turn;
        }
        let travel = x.hypot(y);
        if turn.abs() * STRAIGHT_RADIUS_WHEEL_BASES * base <= travel {
            straight_m += travel;
        }
    }
    for (name, way, turned) in [
        ("odometry.turned_left_deg", "left", left),
        ("odometry.turned_right_deg", "right", right),
    ] {
        checks.push(Check::at_least(
            name,
            turned.to_degrees(),
            MIN_TURN_EACH_WAY_DEG,
            format!(
                "the drive turned {:.0}° to the {way} in all; turning one way only, a \
                 wheel's radius trades against the lidar's sideways offset",
                turned.to_degrees()
            ),
        ));
    }
    let bases = straight_m / base;
    checks.push(Check::at_least(
        "odometry.straight_wheel_bases",
        bases,
        MIN_STRAIGHT_WHEEL_BASES,
        format!(
            "the drive went {straight_m:.2} m straight ({bases:.0} wheel bases); straight \
             travel sets the scale of the radii and the base"
        ),
    ));
    let sd = model.standard_deviations();
    let relative = [
        sd[0] / model.left_wheel_radius_m.abs(),
        sd[1] / model.right_wheel_radius_m.abs(),
        sd[2] / model.wheel_base_m.abs(),
    ];
    checks.push(Check::at_most(
        "odometry.wheels_sd",
        relative.iter().copied().fold(0.0, f64::max),
        MAX_RELATIVE_SD,
        format!(
            "the radii and the base are known to {:.3} %, {:.3} % and {:.3} % (one standard \
             deviation); above {:.1} % the drive does not inform them",
            relative[0] * 100.0,
            relative[1] * 100.0,
            relative[2] * 100.0,
            MAX_RELATIVE_SD * 100.0
        ),
    ));
    checks.push(Check::at_most(
        "odometry.lidar_position_sd_m",
        sd[3].max(sd[4]),
        MAX_POSITION_SD_M,
        format!(
            "the lidar's position is known to {:.2} mm forward and {:.2} mm sideways",
            sd[3] * 1e3,
            sd[4] * 1e3
        ),
    ));
    checks.push(Check::at_most(
        "odometry.lidar_yaw_sd_rad",
        sd[5],
        MAX_YAW_SD_RAD,
        format!("the lidar's yaw is known to {:.2} mrad", sd[5] * 1e3),
    ));
    let left_out = fit.inlier.iter().filter(|&&i| !i).count();
    let share = left_out as f64 / fit.inlier.len().max(1) as f64;
    checks.push(Check::at_most(
        "odometry.outlier_share",
        share,
        MAX_OUTLIER_SHARE,
        format!(
            "{left_out} of {} intervals were outliers; many mean the wheels slipped or the scan \
             matcher failed often, and the rest is not a random sample",
            fit.inlier.len()
        ),
    ));
    checks.push(Check::at_most(
        "odometry.residual_correlation",
        fit.variance_inflation,
        MAX_VARIANCE_INFLATION,
        format!(
            "the residuals' correlation in time inflates the estimate's variance {:.2}-fold \
             (the covariance includes it); beyond {MAX_VARIANCE_INFLATION} the model leaves \
             structure (slip, a drift, an effect it lacks) and the bound is not to be trusted",
            fit.variance_inflation
        ),
    ));
    checks
}
