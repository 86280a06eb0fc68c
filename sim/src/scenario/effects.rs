//! `[effects]`: physics that a scenario switches on. Every effect of the mismatch catalogue
//! (`hilsim diagnose`) is off by default, so a scenario's nominal simulation is exactly what it
//! declares and nothing more; a scenario with an effect switched on is how "real" data with that
//! effect is produced. Each table holds the effect's parameters; the physics behind each one is
//! in the sensor model that applies it (`hilsim-lidar-emulator`'s `effects` module for the
//! sensors, `motor_lag` here for the drive) and in `scenarios/README.md`.

use serde::Deserialize;

/// `[effects]`: each table present switches that effect on.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Effects {
    /// The lidar's range error grows as its beam meets a surface obliquely.
    #[serde(default)]
    pub lidar_incidence_angle: Option<LidarIncidenceAngle>,
    /// The lidar's range bias depends on the target's reflectivity (range walk).
    #[serde(default)]
    pub lidar_reflectivity: Option<LidarReflectivity>,
    /// The lidar's beam has a width: a beam grazing an edge returns a range between the
    /// foreground and the background.
    #[serde(default)]
    pub lidar_mixed_pixels: Option<LidarMixedPixels>,
    /// The lidar's head turns while the robot moves: the readings of a revolution are taken at
    /// their own instants, not at the revolution's start.
    #[serde(default)]
    pub lidar_motion_skew: Option<LidarMotionSkew>,
    /// The lidar's range bias drifts with the time since power-on.
    #[serde(default)]
    pub lidar_warmup_drift: Option<LidarWarmupDrift>,
    /// The sonar returns the nearest echo anywhere in a cone wider than declared.
    #[serde(default)]
    pub sonar_beam_width: Option<SonarBeamWidth>,
    /// The air's temperature scales every sonar range.
    #[serde(default)]
    pub sonar_speed_of_sound: Option<SonarSpeedOfSound>,
    /// The wheels slip in proportion to their acceleration.
    #[serde(default)]
    pub odometer_wheel_slip: Option<OdometerWheelSlip>,
    /// The wheels reach a commanded speed with a first-order lag.
    #[serde(default)]
    pub drive_motor_lag: Option<DriveMotorLag>,
    /// The lidar sits on the robot at another yaw or position than its declared mount.
    #[serde(default)]
    pub lidar_mount_offset: Option<LidarMountOffset>,
    /// Sensors' timestamps lag the moment of measurement by a constant delay each.
    #[serde(default)]
    pub sensor_latency: Option<SensorLatency>,
    /// The wheels' radii differ from nominal, each by its own scale.
    #[serde(default)]
    pub odometer_wheel_radius: Option<OdometerWheelRadius>,
    /// The effective wheel base differs from nominal.
    #[serde(default)]
    pub drive_wheel_base: Option<DriveWheelBase>,
    /// The real lidar's range bias differs from its declared one (`[sensors.lidar] bias`).
    #[serde(default)]
    pub lidar_range_bias: Option<RangeBias>,
    /// The real sonar's range bias differs from its declared one (`[sensors.sonar] bias`).
    #[serde(default)]
    pub sonar_range_bias: Option<RangeBias>,
    /// The lidar loses returns too weak to range: far, at grazing incidence, on dark surfaces.
    #[serde(default)]
    pub lidar_dropout: Option<LidarDropout>,
}

impl Effects {
    /// The catalogue names of the effects switched on, in catalogue order.
    #[must_use]
    pub fn active(&self) -> Vec<&'static str> {
        let on = [
            (
                "lidar_incidence_angle",
                self.lidar_incidence_angle.is_some(),
            ),
            ("lidar_reflectivity", self.lidar_reflectivity.is_some()),
            ("lidar_mixed_pixels", self.lidar_mixed_pixels.is_some()),
            ("lidar_motion_skew", self.lidar_motion_skew.is_some()),
            ("lidar_warmup_drift", self.lidar_warmup_drift.is_some()),
            ("sonar_beam_width", self.sonar_beam_width.is_some()),
            ("sonar_speed_of_sound", self.sonar_speed_of_sound.is_some()),
            ("odometer_wheel_slip", self.odometer_wheel_slip.is_some()),
            ("drive_motor_lag", self.drive_motor_lag.is_some()),
            ("lidar_mount_offset", self.lidar_mount_offset.is_some()),
            ("sensor_latency", self.sensor_latency.is_some()),
            (
                "odometer_wheel_radius",
                self.odometer_wheel_radius.is_some(),
            ),
            ("drive_wheel_base", self.drive_wheel_base.is_some()),
            ("lidar_range_bias", self.lidar_range_bias.is_some()),
            ("sonar_range_bias", self.sonar_range_bias.is_some()),
            ("lidar_dropout", self.lidar_dropout.is_some()),
        ];
        on.iter().filter(|(_, o)| *o).map(|(n, _)| *n).collect()
    }

    /// Whether no effect is switched on.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.active().is_empty()
    }
}

/// `[effects.lidar_incidence_angle]`: range error `(coefficient · d + collimated_m) · tanᵖ θ`,
/// θ the angle between the beam and the surface normal, p the `exponent`: the footprint of a
/// diverging beam (its depth grows with the range) and of a collimated one (a fixed width), its
/// centroid's offset growing as the footprint's depth (p = 1) or faster (see
/// `hilsim_lidar_emulator::effects::incidence_error_m`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarIncidenceAngle {
    /// Dimensionless: the range error per metre of range per unit of `tan θ`; positive reads
    /// long.
    pub coefficient: f64,
    /// Metres: the range-independent error per unit of `tan θ` (at 45°); default 0.
    #[serde(default)]
    pub collimated_m: f64,
    /// The power of `tan θ` the error grows with; default 1 (the footprint's depth).
    #[serde(default = "LidarIncidenceAngle::footprint_exponent")]
    pub exponent: f64,
}

impl LidarIncidenceAngle {
    /// The error growing as the footprint's depth, `tan θ`: the exponent when none is given.
    #[must_use]
    pub const fn footprint_exponent() -> f64 {
        1.0
    }
}

/// `[effects.lidar_reflectivity]`: range walk `coefficient_m · (reference / ρ − 1)`, ρ the
/// surface's reflectivity (`world.materials`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarReflectivity {
    /// Metres: the range walk per unit of `reference / ρ − 1`; positive: dark surfaces read long.
    pub coefficient_m: f64,
    /// The reflectivity at which the unit was calibrated (no walk); default 0.8, the built-in
    /// material's.
    #[serde(default = "default_reference_reflectivity")]
    pub reference: f64,
}

fn default_reference_reflectivity() -> f64 {
    0.8
}

/// `[effects.lidar_mixed_pixels]`: the beam's footprint spans `±half_width_deg`; a footprint on
/// two surfaces returns their intensity-weighted triangulation centroid.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarMixedPixels {
    /// Half of the beam's angular width, degrees.
    pub half_width_deg: f64,
}

/// `[effects.lidar_motion_skew]`: no parameters; needs `[sensors.lidar] timing =
/// "per_revolution"` (a lidar that takes a revolution at one instant), whose readings it spreads
/// over the revolution as the head turns.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarMotionSkew {}

/// `[effects.lidar_warmup_drift]`: range error
/// `(offset_m + coefficient_per_m · d²) · exp(−t / τ)`, t the time since power-on (the recording's start): the drift of the range bias's quadratic
/// term (the laser's pointing) and of its constant term (the housing's expansion), settling
/// together.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarWarmupDrift {
    /// Per metre: the quadratic part of the range error at power-on is this times d².
    pub coefficient_per_m: f64,
    /// The thermal time constant τ, seconds.
    pub time_constant_s: f64,
    /// The constant part of the range error at power-on, metres; default 0.
    #[serde(default)]
    pub offset_m: f64,
    /// β of the settling `e^{−(t/τ)^β}`; default 1, one thermal mass.
    #[serde(default = "one")]
    pub stretch: f64,
}

/// `[effects.sonar_beam_width]`: the sonar's real cone, and how it times an echo spread
/// across it.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SonarBeamWidth {
    /// Half of the real beam cone, degrees; replaces `[sensors.sonar] half_angle_deg`.
    pub half_angle_deg: f64,
    /// The share of the reading that is the echoes' centroid across the beam's main lobe
    /// rather than the nearest echo in the cone: 0 (default) times the echo's onset, 1 its
    /// centre (an envelope detector's peak).
    #[serde(default)]
    pub centroid_share: f64,
}

/// `[effects.sonar_speed_of_sound]`: every range scaled by `c(calibrated_at_c) / c(air)`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SonarSpeedOfSound {
    /// The air's temperature during the run, °C.
    pub air_temperature_c: f64,
    /// The temperature whose speed of sound the sonar converts echo times with, °C; default 20.
    #[serde(default = "default_calibrated_at")]
    pub calibrated_at_c: f64,
}

fn default_calibrated_at() -> f64 {
    20.0
}

/// `[effects.odometer_wheel_slip]`: each wheel's slip velocity is `gain_s` times its
/// acceleration while it speeds up and `braking_gain_s` times it while it brakes, so the
/// encoders lead the true travel by `gain_s · v_wheel` when the two are equal.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OdometerWheelSlip {
    /// Seconds: slip velocity per unit of wheel acceleration while the wheel speeds up.
    pub gain_s: f64,
    /// Seconds: the same while the wheel brakes (its speed's magnitude falls); default
    /// `gain_s`, the encoders giving back on braking what they led by on speeding up.
    #[serde(default)]
    pub braking_gain_s: Option<f64>,
}

impl OdometerWheelSlip {
    /// The slip's gain while braking: `braking_gain_s`, or `gain_s` when not given.
    #[must_use]
    pub fn braking_gain(&self) -> f64 {
        self.braking_gain_s.unwrap_or(self.gain_s)
    }
}

/// `[effects.drive_motor_lag]`: each wheel's speed follows its command through a first-order
/// lag, or a second-order response of the same response time.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveMotorLag {
    /// The lag's time constant τ, seconds: the time a step takes to reach `1 − 1/e` of itself.
    pub time_constant_s: f64,
    /// The second-order response's damping ζ (absent: first order).
    #[serde(default)]
    pub damping: Option<f64>,
}

/// `[effects.lidar_mount_offset]`: the lidar's real mount is its declared one (`[sensors.lidar]
/// mount`, what `meta.toml` records) moved by this much in the robot's frame: a unit bolted on a
/// little rotated or off-centre.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarMountOffset {
    /// Extra yaw, degrees (counter-clockwise seen from above).
    #[serde(default)]
    pub yaw_deg: f64,
    /// Extra forward offset, metres.
    #[serde(default)]
    pub x_m: f64,
    /// Extra leftward offset, metres.
    #[serde(default)]
    pub y_m: f64,
}

/// `[effects.sensor_latency]`: each sensor's timestamps are this much later than the moment it
/// measured (a driver that stamps a reading when it arrives, not when it was taken).
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorLatency {
    /// The lidar's delay, seconds.
    #[serde(default)]
    pub lidar_s: f64,
    /// The sonar's delay, seconds.
    #[serde(default)]
    pub sonar_s: f64,
    /// The odometer's delay, seconds.
    #[serde(default)]
    pub odometer_s: f64,
}

/// `[effects.odometer_wheel_radius]`: each wheel's real radius is its nominal one times a scale.
/// The motors turn the wheels at the commanded speed over the nominal radius, so the robot moves
/// `scale` times the command; the encoders count turns times the nominal radius, so they report
/// the true travel divided by `scale` (the command, near enough): only the outside world sees it.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OdometerWheelRadius {
    /// The left wheel's radius over nominal.
    #[serde(default = "one")]
    pub left_scale: f64,
    /// The right wheel's radius over nominal.
    #[serde(default = "one")]
    pub right_scale: f64,
}

fn one() -> f64 {
    1.0
}

/// `[effects.drive_wheel_base]`: the wheels' effective contact points are `scale` times the
/// nominal wheel base apart (wide tyres, a soft floor), so a turn commanded for the nominal base
/// comes out `1 / scale` times as large, and the encoders' turn likewise.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveWheelBase {
    /// The effective wheel base over nominal.
    pub scale: f64,
}

/// `[effects.lidar_range_bias]` and `[effects.sonar_range_bias]`: the real unit reads `offset_m + scale_error · d +
/// quadratic_per_m · d²` more than its declared bias polynomial (eq. 2 of the papers,
/// `Σ alpha_i d^i`) says, d the true distance: the difference between the unit's own
/// calibration and the one the scenario declares, in the papers' polynomial form.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeBias {
    /// Metres added to every reading (c).
    #[serde(default)]
    pub offset_m: f64,
    /// Added to the bias's linear coefficient (s): the reading is `s · d` longer.
    #[serde(default)]
    pub scale_error: f64,
    /// Per metre, added to the bias's quadratic coefficient.
    #[serde(default)]
    pub quadratic_per_m: f64,
}

impl RangeBias {
    /// The difference's coefficients, lowest order first, to add to the declared `alpha`.
    #[must_use]
    pub fn coefficients(&self) -> [f64; 3] {
        [self.offset_m, self.scale_error, self.quadratic_per_m]
    }
}

/// `[effects.lidar_dropout]`: the lidar loses a return whose power falls below its detection
/// threshold, and reports the reading invalid. The power a triangulation unit's camera receives
/// from a diffuse (Lambertian) surface filling its spot goes as `ρ cos θ / d²`; with the power's
/// reading-to-reading scatter logistic in its logarithm, the chance a reading is lost is
/// `1 / (1 + e^{−z/s})`, `z = 2 ln(d / d½) − ln cos θ − ln(ρ / ρ_ref)`: half are lost at
/// `half_loss_range_m` on a surface of the reference reflectivity met head-on, nearer at
/// grazing incidence and on darker surfaces. A surface that is not diffuse returns `cos^m θ`
/// (`incidence_power` m): `z = 2 ln(d / d½) − m ln cos θ − ln(ρ / ρ_ref)`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarDropout {
    /// The range at which half the returns are lost, head-on on a surface of reflectivity
    /// `reference`, metres.
    pub half_loss_range_m: f64,
    /// The scatter of the return's log power from reading to reading (s above): head-on, the
    /// loss rises from 12 % to 88 % as the range grows by a factor `e^{2s}`.
    pub log_power_spread: f64,
    /// The reflectivity `half_loss_range_m` is stated for (default 0.8, the emulator's
    /// strength reference).
    #[serde(default = "default_dropout_reference")]
    pub reference: f64,
    /// How the returned power falls with the incidence θ, as `cos^m θ`: 1 (the default) a
    /// diffuse surface's (Lambert's law), 0 a unit whose losses the range alone sets (its gain
    /// set for its surfaces), above 1 a glossy surface's, whose return falls faster off the
    /// normal.
    #[serde(default = "default_dropout_incidence_power")]
    pub incidence_power: f64,
}

fn default_dropout_reference() -> f64 {
    0.8
}

fn default_dropout_incidence_power() -> f64 {
    1.0
}
