//! The scenario's `[effects]` table that switches each effect on: how the diagnosis's physics
//! tries a hypothesis, and how the self-test conceals a drawn effect in its "real" run.

use hilsim_lidar_emulator::effects::real_mount;
use hilsim_recording::Mount;
use hilsim_sim::scenario::{self, Effects};

use super::{Effect, Sensor};

/// The reference reflectivity of `[effects.lidar_reflectivity]` (the catalogue's coefficient is
/// the range walk on a surface of half of it).
pub(crate) const REFERENCE_REFLECTIVITY: f64 = 0.8;
/// The range about which the catalogue's range bias is parametrised (its error there, slope and
/// curvature), metres: the middle of a room's ranges.
const RANGE_BIAS_ABOUT_M: f64 = 2.0;

/// The temperature the sonar's speed of sound is calibrated at, °C.
const CALIBRATED_AT_C: f64 = 20.0;

/// The lidar's real mount under a `lidar_mount_offset` of `params` (in the order of
/// [`Effect::params`]) from the `declared` one: the simulator's own [`real_mount`].
pub(crate) fn mounted(declared: &Mount, params: &[f64]) -> Mount {
    let mut e = Effects::default();
    Effect::LidarMountOffset.apply(params, &mut e);
    real_mount(*declared, e.lidar_mount_offset)
}

/// A `lidar_range_bias` of `params` (its error at 2 m, slope and curvature there; a missing one
/// is 0) in the papers' form, `c + s d + q d²`: the scenario's `[effects.lidar_range_bias]`.
pub(crate) fn range_bias(params: &[f64]) -> scenario::RangeBias {
    let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
    let (a, s, q, r) = (p(0), p(1), p(2), RANGE_BIAS_ABOUT_M);
    scenario::RangeBias {
        offset_m: a - s * r + q * r * r,
        scale_error: s - 2.0 * q * r,
        quadratic_per_m: q,
    }
}

impl Effect {
    /// Switches the effect on in `effects` with `params` (in the order of [`Effect::params`]; a
    /// missing one is 0), replacing its table if the scenario already has one. A parameter at
    /// which the scenario's table cannot exist (a mixed-pixel footprint or a motor lag of 0)
    /// leaves the effect off.
    ///
    /// `sensor_latency` sets its sensor's delay only, keeping the others' in the table.
    ///
    /// Motion skew's table has no parameter: the revolution's duration is the lidar's `rpm` in
    /// a scenario, and the diagnosis's physics fits it as the timing of each reading
    /// ([`crate::SimPhysics`]).
    ///
    /// ```
    /// use hilsim_diagnose::Effect;
    /// let mut effects = hilsim_sim::scenario::Effects::default();
    /// Effect::SonarBeamWidth.apply(&[12.0], &mut effects);
    /// assert_eq!(effects.sonar_beam_width.map(|b| b.half_angle_deg), Some(12.0));
    /// ```
    pub fn apply(self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        let e = effects;
        match self {
            Effect::LidarIncidenceAngle => {
                e.lidar_incidence_angle = Some(scenario::LidarIncidenceAngle {
                    coefficient: p(0),
                    collimated_m: p(1),
                    exponent: params.get(2).copied().unwrap_or(1.0),
                });
            }
            Effect::LidarReflectivity => {
                e.lidar_reflectivity = Some(scenario::LidarReflectivity {
                    coefficient_m: p(0),
                    reference: REFERENCE_REFLECTIVITY,
                });
            }
            Effect::LidarMixedPixels => {
                e.lidar_mixed_pixels = (p(0) > 0.0).then_some(scenario::LidarMixedPixels {
                    half_width_deg: p(0),
                });
            }
            Effect::LidarMotionSkew => {
                e.lidar_motion_skew = Some(scenario::LidarMotionSkew {});
            }
            Effect::LidarWarmupDrift => {
                e.lidar_warmup_drift = Some(scenario::LidarWarmupDrift {
                    coefficient_per_m: p(0),
                    time_constant_s: p(1).max(1e-3),
                    offset_m: p(2),
                    stretch: 1.0,
                });
            }
            Effect::SonarBeamWidth => {
                e.sonar_beam_width = Some(scenario::SonarBeamWidth {
                    half_angle_deg: p(0).clamp(0.0, 89.0),
                });
            }
            Effect::SonarSpeedOfSound => {
                e.sonar_speed_of_sound = Some(scenario::SonarSpeedOfSound {
                    air_temperature_c: p(0),
                    calibrated_at_c: CALIBRATED_AT_C,
                });
            }
            Effect::OdometerWheelSlip => {
                // The braking gain as a share of the driving one; even (1) when not fitted.
                let share = params.get(1).copied().unwrap_or(1.0);
                e.odometer_wheel_slip = Some(scenario::OdometerWheelSlip {
                    gain_s: p(0),
                    braking_gain_s: (share != 1.0).then(|| share * p(0)),
                });
            }
            Effect::DriveMotorLag => {
                // The underdamping 1/ζ; under 0.1 (ζ past 10) the response is the first-order
                // lag's to a tenth of a percent.
                let underdamping = p(1);
                e.drive_motor_lag = (p(0) > 0.0).then_some(scenario::DriveMotorLag {
                    time_constant_s: p(0),
                    damping: (underdamping >= 0.1).then(|| 1.0 / underdamping),
                });
            }
            Effect::LidarMountOffset => {
                e.lidar_mount_offset = Some(scenario::LidarMountOffset {
                    yaw_deg: p(0),
                    x_m: p(1),
                    y_m: p(2),
                });
            }
            Effect::SensorLatency(sensor) => {
                // A delay is never negative: the fit's range starts at 0.
                let delay = p(0).max(0.0);
                let mut l = e.sensor_latency.unwrap_or_default();
                match sensor {
                    Sensor::Lidar => l.lidar_s = delay,
                    Sensor::Sonar => l.sonar_s = delay,
                    Sensor::Odometer => l.odometer_s = delay,
                    Sensor::Drive => {}
                }
                e.sensor_latency = Some(l);
            }
            Effect::OdometerWheelRadius => {
                let scale = |i: usize| params.get(i).copied().unwrap_or(1.0);
                e.odometer_wheel_radius = Some(scenario::OdometerWheelRadius {
                    left_scale: scale(0),
                    right_scale: scale(1),
                });
            }
            Effect::LidarRangeBias => {
                e.lidar_range_bias = Some(range_bias(params));
            }
            Effect::SonarRangeBias => {
                e.sonar_range_bias = Some(scenario::RangeBias {
                    offset_m: p(0),
                    ..scenario::RangeBias::default()
                });
            }
            Effect::LidarDropout => {
                e.lidar_dropout = Some(scenario::LidarDropout {
                    half_loss_range_m: p(0),
                    log_power_spread: p(1),
                    reference: REFERENCE_REFLECTIVITY,
                });
            }
            Effect::DriveWheelBase => {
                e.drive_wheel_base = Some(scenario::DriveWheelBase {
                    scale: params.first().copied().unwrap_or(1.0),
                });
            }
        }
    }
}
