//! A scenario's robot as a calibration found it: an odometry calibration's wheels and lidar
//! mount put into the simulation as the effects that model them, so that a diagnosis compares
//! the recording with the robot it came from, not with the one the scenario declares.

use hilsim_calibrator::{Calibration, OdometryModel};
use hilsim_recording::Sensor;
use hilsim_sim::scenario::{DriveWheelBase, LidarMountOffset, OdometerWheelRadius};
use hilsim_sim::Scenario;

/// The scales the simulation models a wheel or a wheel base with (`[effects]`' bounds).
const SCALES: std::ops::RangeInclusive<f64> = 0.5..=1.5;

/// `scenario` with `model`'s wheels and lidar mount: each wheel's radius over the scenario's
/// nominal one (`[effects.odometer_wheel_radius]`), the wheel base over the declared one
/// (`[effects.drive_wheel_base]`), and the mount's difference from the declared one
/// (`[effects.lidar_mount_offset]`), each replacing what the scenario had.
///
/// # Errors
/// A sentence when the calibration's wheels are beyond what the simulation models (a scale
/// outside 0.5–1.5: a calibration of another robot), or it has a lidar mount and the scenario
/// no lidar.
pub fn with_odometry(scenario: &Scenario, model: &OdometryModel) -> Result<Scenario, String> {
    let mut s = scenario.clone();
    let nominal = scenario.robot.wheel_radius_m;
    let [left_scale, right_scale] = [
        model.left_wheel_radius_m / nominal,
        model.right_wheel_radius_m / nominal,
    ];
    let base_scale = model.wheel_base_m / scenario.robot.wheel_base_m;
    for (what, scale) in [
        ("the left wheel's radius", left_scale),
        ("the right wheel's radius", right_scale),
        ("the wheel base", base_scale),
    ] {
        if !SCALES.contains(&scale) {
            return Err(format!(
                "{what} is {scale:.3} times the scenario's: not a calibration of this robot \
                 (the scenario's [robot] wheel_radius_m and wheel_base_m are its nominal ones)"
            ));
        }
    }
    s.effects.odometer_wheel_radius = Some(OdometerWheelRadius {
        left_scale,
        right_scale,
    });
    s.effects.drive_wheel_base = Some(DriveWheelBase { scale: base_scale });
    let Some(lidar) = s.sensors.lidar.as_ref() else {
        return Err("the scenario has no lidar for the calibration's lidar mount".into());
    };
    let declared = lidar.mount;
    s.effects.lidar_mount_offset = Some(LidarMountOffset {
        yaw_deg: hilsim_recording::wrap_angle(model.lidar_yaw_rad - declared.yaw_deg.to_radians())
            .to_degrees(),
        x_m: model.lidar_x_m - declared.x_m,
        y_m: model.lidar_y_m - declared.y_m,
    });
    Ok(s)
}

/// `scenario` with what `calibration` found declared: an odometry calibration's wheels and lidar
/// mount (as [`with_odometry`]), and each calibrated range sensor's bias and noise polynomials
/// (the papers' eq. 2) as that sensor's declared `bias` and `noise`, replacing the scenario's.
///
/// # Errors
/// A sentence when the calibration has nothing the scenario can take (no wheels, no mount, no
/// model of a sensor the scenario has), or as [`with_odometry`].
pub fn with_calibration(
    scenario: &Scenario,
    calibration: &Calibration,
) -> Result<Scenario, String> {
    let mut s = match &calibration.odometry {
        Some(model) => with_odometry(scenario, model)?,
        None => scenario.clone(),
    };
    let mut declared = calibration.odometry.is_some();
    for (sensor, model) in &calibration.sensors {
        let (bias, noise) = match sensor {
            Sensor::Lidar => match s.sensors.lidar.as_mut() {
                Some(l) => (&mut l.bias, &mut l.noise),
                None => continue,
            },
            Sensor::Sonar => match s.sensors.sonar.as_mut() {
                Some(u) => (&mut u.bias, &mut u.noise),
                None => continue,
            },
            // The odometer's calibration is the wheels' (`odometry` above).
            Sensor::Odometer => continue,
        };
        if model.alpha.is_empty() || model.beta.is_empty() {
            continue;
        }
        bias.clone_from(&model.alpha);
        noise.clone_from(&model.beta);
        declared = true;
    }
    if declared {
        Ok(s)
    } else {
        Err(format!(
            "the {} method's calibration has no wheels, no lidar mount and no model of a sensor \
             the scenario has",
            calibration.method.name()
        ))
    }
}
