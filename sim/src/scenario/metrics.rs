//! The catalogue of metric names that `[[expect]]` assertions may name. The binary computes them
//! after a run; a name outside this list is rejected when the scenario is loaded.

use hilsim_recording::Method;

/// Every metric name with what it measures. Keep `scenarios/README.md` in step.
pub const METRICS: &[(&str, &str)] = &[
    ("sim.duration_s", "simulated time, seconds"),
    (
        "sim.collisions",
        "number of contacts the robot started with obstacles",
    ),
    (
        "sim.distance_m",
        "path length the robot travelled, metres (truth)",
    ),
    ("sim.final_x_m", "true x at the end, metres"),
    ("sim.final_y_m", "true y at the end, metres"),
    ("sim.final_yaw_deg", "true heading at the end, degrees"),
    ("lidar.revolutions", "complete lidar revolutions recorded"),
    ("lidar.readings", "lidar readings recorded"),
    (
        "lidar.valid_fraction",
        "fraction of lidar readings without the invalid flag",
    ),
    (
        "lidar.rmse_m",
        "RMS of reported minus true range over valid readings, metres",
    ),
    ("sonar.readings", "sonar pings recorded"),
    (
        "sonar.rmse_m",
        "RMS of reported minus true sonar range, metres",
    ),
    ("odometer.readings", "odometer readings recorded"),
    (
        "odometer.scale",
        "encoder-reported over true wheel travel (1 + slip when noise is small)",
    ),
];

/// Calibration metrics, each prefixed by a method: `em.`, `landmarks.`, `groundtruth.` or
/// `odometry.`
/// (computed when the scenario's `[calibration] methods` names it; the `lidar.*` ones need
/// truth).
pub const CALIBRATION_METRICS: &[(&str, &str)] = &[
    ("iterations", "iterations the method ran"),
    (
        "converged",
        "1 when the method met its convergence criterion, else 0",
    ),
    ("order", "the selected polynomial order (landmarks)"),
    (
        "lidar.mse_raw",
        "MSE of the raw lidar distances against the truth, m²",
    ),
    (
        "lidar.mse_calibrated",
        "MSE of the calibrated distance estimates, m²",
    ),
    (
        "lidar.mse_ratio",
        "raw over calibrated MSE (the landmark paper's eq. 31)",
    ),
    (
        "lidar.nmse_raw",
        "mean of squared raw errors over squared true distances (EM paper, Fig. 3)",
    ),
    (
        "lidar.nmse_calibrated",
        "the same for the calibrated estimates",
    ),
    (
        "lidar_model.mse_raw",
        "MSE of the raw lidar distances scored for the lidar model alone, m²",
    ),
    (
        "lidar_model.mse_calibrated",
        "MSE of each raw reading inverted through the fitted lidar model, m²",
    ),
    (
        "lidar_model.mse_ratio",
        "the lidar model alone: raw over inverted MSE (eq. 31 with eq. 30's inversion)",
    ),
    (
        "checks_failed",
        "how many of the method's assumption checks failed",
    ),
    ("left_wheel_radius_m", "the left wheel's radius (odometry)"),
    (
        "right_wheel_radius_m",
        "the right wheel's radius (odometry)",
    ),
    ("wheel_base_m", "the wheel base (odometry)"),
    (
        "lidar_x_m",
        "the lidar's forward offset on the robot (odometry)",
    ),
    (
        "lidar_y_m",
        "the lidar's leftward offset on the robot (odometry)",
    ),
    ("lidar_yaw_deg", "the lidar's yaw on the robot (odometry)"),
];

/// Metrics of a firmware's session under `hilsim hil` (absent from `run` and `scenario test`,
/// whose assertions on them are skipped, as `hil` skips the calibration metrics).
pub const HIL_METRICS: &[(&str, &str)] = &[
    (
        "hil.lidar_revolutions_read",
        "whole revolutions of lidar bytes the firmware read from its port",
    ),
    (
        "hil.lidar_revolutions_dropped",
        "revolutions the stream dropped (a reader that did not keep up)",
    ),
    ("hil.requests", "command-port requests the firmware made"),
    (
        "hil.command_errors",
        "command-port requests answered with an error",
    ),
    (
        "hil.set_motor",
        "SetMotor requests accepted (how often the firmware drove)",
    ),
    (
        "hil.fault",
        "1 when the run ended on a firmware fault (crash, hang, flood, lidar never read), else 0",
    ),
    (
        "hil.firmware_exit_code",
        "the firmware's exit code (absent when a signal ended it)",
    ),
];

/// Whether `name` is a metric of the firmware's session ([`HIL_METRICS`]).
#[must_use]
pub fn is_hil(name: &str) -> bool {
    HIL_METRICS.iter().any(|(n, _)| *n == name)
}

/// Whether `name` is a calibration metric (`METHOD.…`).
#[must_use]
pub fn is_calibration(name: &str) -> bool {
    name.split_once('.').is_some_and(|(method, rest)| {
        Method::from_name(method).is_some() && CALIBRATION_METRICS.iter().any(|(n, _)| *n == rest)
    })
}

/// Whether `name` is in the catalogue.
#[must_use]
pub fn is_known(name: &str) -> bool {
    METRICS.iter().any(|(n, _)| *n == name) || is_calibration(name) || is_hil(name)
}
