//! What a "real" robot has that its scenario does not say: the catalogue's physics, written
//! here again from its definitions (`docs/diagnose.md`, `scenarios/README.md` `[effects]`), and
//! physics outside the catalogue. Each mechanism carries its form ([`crate::form`]): the
//! catalogue's by default, another where the self-test's varied reality draws one.

use crate::form::{
    Blend, Curve, DriveResponse, EchoPick, IncidenceGrowth, LossBy, ReflectivityWalk, Settling,
    Traction,
};

/// One concealed effect with its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Concealed {
    /// The lidar reads `(κ d + c) g(θ)` long (θ the incidence angle, capped at 80°; `g` the
    /// growth, `tan θ` in the catalogue): a diverging beam's footprint and a collimated one's.
    LidarIncidence {
        coefficient: f64,
        collimated_m: f64,
        growth: IncidenceGrowth,
    },
    /// The lidar's range walks by `c h(ρ)` on a surface of reflectivity ρ (`h` the walk,
    /// `ρ_ref/ρ − 1` in the catalogue).
    LidarReflectivity {
        coefficient_m: f64,
        reference: f64,
        walk: ReflectivityWalk,
    },
    /// The beam has an angular half-width; a footprint over several surfaces returns a blend
    /// of their ranges weighted by `share · ρ cos θ / d²` (the harmonic mean in the catalogue).
    LidarMixedPixels { half_width_deg: f64, blend: Blend },
    /// Each reading's geometry is taken at its own instant (the head turns while the robot
    /// moves), where the scenario says a revolution is one instant.
    LidarMotionSkew,
    /// The range error `(c + k d²) w(t)` of a unit warming up: its pointing (k) and its
    /// housing (c) settling together (`w` the settling, `e^{−t/τ}` in the catalogue).
    LidarWarmup {
        coefficient_per_m: f64,
        time_constant_s: f64,
        offset_m: f64,
        settling: Settling,
    },
    /// The sonar's beam has this half-angle; `pick` says which echo across it is reported
    /// (the nearest in the catalogue).
    SonarBeamWidth { half_angle_deg: f64, pick: EchoPick },
    /// Every sonar range scaled by `c(calibrated)/c(air)`, `c(T) = 331.3 √(1 + T/273.15)`.
    SonarSpeedOfSound {
        air_temperature_c: f64,
        calibrated_at_c: f64,
    },
    /// The encoders lead the true travel by a slip that grows at `g f(a)` while a wheel speeds
    /// up and `braking_share · g f(a)` while it slows (`f(a) = a` in the catalogue, where an
    /// even slip, share 1, leads by `g v`).
    WheelSlip {
        gain_s: f64,
        braking_share: f64,
        traction: Traction,
    },
    /// Each wheel's speed follows its command with response time τ (a first-order lag in the
    /// catalogue).
    MotorLag {
        time_constant_s: f64,
        response: DriveResponse,
    },
    /// The lidar sits turned by `yaw_deg` (counter-clockwise) and moved `x_m` forward, `y_m`
    /// left of where the scenario mounts it.
    LidarMountOffset { yaw_deg: f64, x_m: f64, y_m: f64 },
    /// One sensor's readings are stamped `delay_s` after they were taken.
    SensorLatency { sensor: Stamped, delay_s: f64 },
    /// Each wheel's radius over nominal: the ground moves `scale` times the commanded wheel
    /// speed, the encoders report the ground's travel over `scale`.
    WheelRadius { left_scale: f64, right_scale: f64 },
    /// The wheels' effective contact points are `scale` times the nominal base apart.
    WheelBase { scale: f64 },
    /// The lidar's own calibration is not the declared one, as a triangulation unit's geometry
    /// makes it (`d = f b / x`: focal length f, baseline b, x the spot's image; Konolige et al.,
    /// "A low-cost laser distance sensor", ICRA 2008): its range origin `origin_m` off the
    /// head's axis, its baseline `baseline_ratio` times the one its firmware converts with, and
    /// its laser turned by a small δ towards the camera (`pointing_per_m` = δ / b). The spot's
    /// image then lies at `f (b' / d + δ)`, so where the declared unit reads d this one reads
    /// `origin_m + d / (baseline_ratio + d δ / b)` (to first order in δ a range error `−d² δ / b`).
    LidarTriangulation {
        origin_m: f64,
        baseline_ratio: f64,
        pointing_per_m: f64,
    },
    /// The sonar detects each echo `delay_s` later than its calibration assumes (its threshold
    /// crossed later in the echo's rise, or a transducer's ring-down), and converts that time
    /// too with the speed of sound at `calibrated_at_c`: `c(T) · delay / 2` more range.
    SonarEchoDelay { delay_s: f64, calibrated_at_c: f64 },
    /// The lidar loses returns too weak to range: the power its camera receives from a diffuse
    /// surface, relative to its detection threshold, is `(ρ / reference) cos θ (d½ / d)²`
    /// times a log-normal scatter of `log_power_sd` from reading to reading, and a return below
    /// the threshold (a relative power under 1) is reported invalid.
    LidarWeakReturns {
        half_loss_range_m: f64,
        log_power_sd: f64,
        reference: f64,
        loss: LossBy,
    },
    /// The lidar's range error a smooth increasing curve of the range: `at_2m_m` at 2 m, and
    /// `slope` its mean slope over [0, 8] m (a unit's calibration table off by a drawn shape).
    LidarRangeCurve {
        at_2m_m: f64,
        slope: f64,
        curve: Curve,
    },
    /// Outside the catalogue: a periodic range error of the lidar, `A sin(2π d / λ)` (a
    /// triangulation unit's sub-pixel interpolation error repeats with the spot's position on
    /// the sensor, which moves with 1/d; over a room's ranges it reads as a ripple in d).
    LidarPeriodicRange { amplitude_m: f64, period_m: f64 },
}

impl Concealed {
    /// A name for reports.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::LidarIncidence { .. } => "lidar_incidence_angle",
            Self::LidarReflectivity { .. } => "lidar_reflectivity",
            Self::LidarMixedPixels { .. } => "lidar_mixed_pixels",
            Self::LidarMotionSkew => "lidar_motion_skew",
            Self::LidarWarmup { .. } => "lidar_warmup_drift",
            Self::SonarBeamWidth { .. } => "sonar_beam_width",
            Self::SonarSpeedOfSound { .. } => "sonar_speed_of_sound",
            Self::WheelSlip { .. } => "odometer_wheel_slip",
            Self::MotorLag { .. } => "drive_motor_lag",
            Self::LidarMountOffset { .. } => "lidar_mount_offset",
            Self::SensorLatency { .. } => "sensor_latency",
            Self::WheelRadius { .. } => "odometer_wheel_radius",
            Self::WheelBase { .. } => "drive_wheel_base",
            Self::LidarTriangulation { .. } | Self::LidarRangeCurve { .. } => "lidar_range_bias",
            Self::SonarEchoDelay { .. } => "sonar_range_bias",
            Self::LidarWeakReturns { .. } => "lidar_dropout",
            Self::LidarPeriodicRange { .. } => "lidar_periodic_range",
        }
    }
}

/// A sensor whose driver stamps its readings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stamped {
    Lidar,
    Sonar,
    Odometer,
}

/// How late `sensor`'s readings are stamped under `concealed`, seconds (0: on time).
#[must_use]
pub fn delay_s(concealed: &[Concealed], sensor: Stamped) -> f64 {
    concealed
        .iter()
        .map(|c| match *c {
            Concealed::SensorLatency { sensor: s, delay_s } if s == sensor => delay_s,
            _ => 0.0,
        })
        .sum()
}

/// Speed of sound in air at `t_c` °C, m/s (ideal gas: `331.3 √(1 + T/273.15)`).
#[must_use]
pub fn speed_of_sound(t_c: f64) -> f64 {
    331.3 * (1.0 + t_c / 273.15).sqrt()
}
