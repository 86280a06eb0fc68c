//! The report's colours, one meaning each across every chart.

/// The world's walls, boards and cylinders.
pub const WORLD: &str = "#5b5b5b";
/// The true path, true distances.
pub const TRUTH: &str = "#1b1b1b";
/// The path dead-reckoned from the odometry.
pub const ODOMETRY: &str = "#e08a00";
/// Raw readings.
pub const RAW: &str = "#d9534f";
/// Calibrated readings, the fitted model.
pub const CALIBRATED: &str = "#1f6fd1";
/// The model the scenario declares.
pub const DECLARED: &str = "#2a9d4b";
/// The sonar.
pub const SONAR: &str = "#8e44ad";
/// The left wheel (the right one is drawn dashed in the same colour).
pub const LEFT: &str = "#1f6fd1";
/// The right wheel.
pub const RIGHT: &str = "#d9534f";
/// A region the diagnosis located.
pub const HIGHLIGHT: &str = "#fff1b8";

/// The path dead-reckoned with an odometry calibration's wheels (the odometry method's colour).
pub const CALIBRATED_ODOMETRY: &str = "#2e8b57";

/// Each calibration method's fitted curves.
#[must_use]
pub fn method(method: hilsim_calibrator::Method) -> &'static str {
    match method {
        hilsim_calibrator::Method::Em => CALIBRATED,
        hilsim_calibrator::Method::Groundtruth => "#12a4b6",
        hilsim_calibrator::Method::Landmarks => "#9b59b6",
        hilsim_calibrator::Method::Odometry => CALIBRATED_ODOMETRY,
    }
}
