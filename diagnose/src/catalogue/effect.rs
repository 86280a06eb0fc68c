//! The catalogued effects: each one's name, sensor and parameters, and when it departs from
//! its absence.

use std::fmt;

use super::params::{lin, log, ParamSpec};
use super::sensor::Sensor;

/// One catalogued effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Effect {
    /// `lidar_incidence_angle`.
    LidarIncidenceAngle,
    /// `lidar_reflectivity`.
    LidarReflectivity,
    /// `lidar_mixed_pixels`.
    LidarMixedPixels,
    /// `lidar_motion_skew`.
    LidarMotionSkew,
    /// `lidar_warmup_drift`.
    LidarWarmupDrift,
    /// `sonar_beam_width`.
    SonarBeamWidth,
    /// `sonar_speed_of_sound`.
    SonarSpeedOfSound,
    /// `odometer_wheel_slip`.
    OdometerWheelSlip,
    /// `drive_motor_lag`.
    DriveMotorLag,
}

impl Effect {
    /// The whole catalogue, in `interfaces.md` order.
    pub const ALL: [Effect; 9] = [
        Effect::LidarIncidenceAngle,
        Effect::LidarReflectivity,
        Effect::LidarMixedPixels,
        Effect::LidarMotionSkew,
        Effect::LidarWarmupDrift,
        Effect::SonarBeamWidth,
        Effect::SonarSpeedOfSound,
        Effect::OdometerWheelSlip,
        Effect::DriveMotorLag,
    ];

    /// The catalogue name.
    ///
    /// ```
    /// use hilsim_diagnose::Effect;
    /// for e in Effect::ALL {
    ///     assert_eq!(Effect::from_name(e.name()), Some(e));
    /// }
    /// ```
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Effect::LidarIncidenceAngle => "lidar_incidence_angle",
            Effect::LidarReflectivity => "lidar_reflectivity",
            Effect::LidarMixedPixels => "lidar_mixed_pixels",
            Effect::LidarMotionSkew => "lidar_motion_skew",
            Effect::LidarWarmupDrift => "lidar_warmup_drift",
            Effect::SonarBeamWidth => "sonar_beam_width",
            Effect::SonarSpeedOfSound => "sonar_speed_of_sound",
            Effect::OdometerWheelSlip => "odometer_wheel_slip",
            Effect::DriveMotorLag => "drive_motor_lag",
        }
    }

    /// The effect of a catalogue name.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.name() == name)
    }

    /// The sensor it shows in.
    #[must_use]
    pub fn sensor(self) -> Sensor {
        match self {
            Effect::LidarIncidenceAngle
            | Effect::LidarReflectivity
            | Effect::LidarMixedPixels
            | Effect::LidarMotionSkew
            | Effect::LidarWarmupDrift => Sensor::Lidar,
            Effect::SonarBeamWidth | Effect::SonarSpeedOfSound => Sensor::Sonar,
            Effect::OdometerWheelSlip => Sensor::Odometer,
            Effect::DriveMotorLag => Sensor::Drive,
        }
    }

    /// Its parameters, in the order a [`super::Hypothesis`] holds them.
    ///
    /// The fit's ranges are wide enough for any plausible unit (several times the self-test's
    /// draws) and the grids fine enough that the likelihood is unimodal between neighbouring
    /// points. The self-test's moderate ranges (× its strength unless said): incidence κ
    /// ±[0.01, 0.03]; reflectivity c ±[0.008, 0.02] m; mixed pixels half-width [0.5, 1.5]°
    /// (at most 5°); motion skew the head's own period; warm-up k ±[0.004, 0.01] /m with τ in
    /// [5, 20] s (unscaled); sonar cone [8, 20]° (at most 60°); air temperature 20 °C ±
    /// [15, 30] °C (within [−50, 60] °C, scored as the departure from 20 °C); slip gain
    /// [0.03, 0.1] s; motor lag τ [0.1, 0.4] s (at most 10 s).
    #[must_use]
    pub const fn params(self) -> &'static [ParamSpec] {
        use super::params::SelfTestRange as R;
        const INCIDENCE: [ParamSpec; 1] = [lin(
            "coefficient",
            "",
            (-0.1, 0.1),
            11,
            R::uniform(0.01, 0.03).signed(),
        )];
        const REFLECTIVITY: [ParamSpec; 1] = [lin(
            "coefficient_m",
            "m",
            (-0.1, 0.1),
            11,
            R::uniform(0.008, 0.02).signed(),
        )];
        const MIXED: [ParamSpec; 1] = [log(
            "half_width_deg",
            "deg",
            (0.05, 3.0),
            10,
            R::uniform(0.5, 1.5).at_most(5.0),
        )];
        const SKEW: [ParamSpec; 1] = [lin(
            "revolution_s",
            "s",
            (0.0, 0.6),
            9,
            R::lidar_revolution(),
        )];
        const WARMUP: [ParamSpec; 2] = [
            lin(
                "coefficient_per_m",
                "1/m",
                (-0.05, 0.05),
                7,
                R::uniform(0.004, 0.01).signed(),
            ),
            log(
                "time_constant_s",
                "s",
                (1.0, 1000.0),
                6,
                R::uniform(5.0, 20.0).unscaled(),
            ),
        ];
        const BEAM: [ParamSpec; 1] = [lin(
            "half_angle_deg",
            "deg",
            (0.0, 45.0),
            16,
            R::uniform(8.0, 20.0).at_most(60.0),
        )];
        const SOUND: [ParamSpec; 1] = [lin(
            "air_temperature_c",
            "degC",
            (-50.0, 60.0),
            23,
            R::uniform(15.0, 30.0).signed().around(20.0, -50.0, 60.0),
        )];
        const SLIP: [ParamSpec; 1] = [lin("gain_s", "s", (-0.5, 0.5), 11, R::uniform(0.03, 0.1))];
        const LAG: [ParamSpec; 1] = [log(
            "time_constant_s",
            "s",
            (0.005, 5.0),
            13,
            R::uniform(0.1, 0.4).at_most(10.0),
        )];
        match self {
            Effect::LidarIncidenceAngle => &INCIDENCE,
            Effect::LidarReflectivity => &REFLECTIVITY,
            Effect::LidarMixedPixels => &MIXED,
            Effect::LidarMotionSkew => &SKEW,
            Effect::LidarWarmupDrift => &WARMUP,
            Effect::SonarBeamWidth => &BEAM,
            Effect::SonarSpeedOfSound => &SOUND,
            Effect::OdometerWheelSlip => &SLIP,
            Effect::DriveMotorLag => &LAG,
        }
    }

    /// The parameter values at which the effect is absent (what the nominal model assumes),
    /// given the declared sonar cone for the beam width and the declared calibration
    /// temperature (20 °C) for the speed of sound. The warm-up drift is absent at k = 0 for
    /// any τ.
    #[must_use]
    pub fn absent(self, declared_half_angle_deg: f64) -> Vec<f64> {
        match self {
            Effect::LidarWarmupDrift => vec![0.0, 10.0],
            Effect::SonarBeamWidth => vec![declared_half_angle_deg],
            Effect::SonarSpeedOfSound => vec![20.0],
            _ => vec![0.0],
        }
    }

    /// The smallest departure of the scored parameter (the first) from its absence that names
    /// the effect: below it the fitted model is the nominal one to within what the sensors
    /// resolve, so what it "explains" is noise the fit chased. Each is about one millimetre of
    /// range where the effect acts (or the model's own resolution):
    /// - incidence κ: 0.001 is 1 mm per metre at 45°;
    /// - reflectivity c: 1 mm on a surface of half the reference's reflectivity;
    /// - mixed pixels: a beam half-width of 0.1°, a third of a typical 0.3° direction noise;
    /// - motion skew: a revolution of 0.02 s, a tenth of the XV-11's 0.2 s;
    /// - warm-up k: 0.00025 /m, 1 mm at 2 m at power-on;
    /// - sonar cone: 1°, four of the emulator's 0.25° rays;
    /// - speed of sound: 0.6 °C, 0.1 % of range (1 mm at 1 m);
    /// - wheel slip g: 0.005 s, 1 mm of travel at 0.2 m/s;
    /// - motor lag τ: 0.02 s, two physics steps (the drive's resolution is 0.01 s).
    #[must_use]
    pub fn departs(self, params: &[f64], declared_half_angle_deg: f64) -> bool {
        let Some(&value) = params.first() else {
            return false;
        };
        let absent = self.absent(declared_half_angle_deg)[0];
        let least = match self {
            Effect::LidarIncidenceAngle => 0.001,
            Effect::LidarReflectivity => 0.001,
            Effect::LidarMixedPixels => 0.1,
            Effect::LidarMotionSkew => 0.02,
            Effect::LidarWarmupDrift => 0.000_25,
            Effect::SonarBeamWidth => 1.0,
            Effect::SonarSpeedOfSound => 0.6,
            Effect::OdometerWheelSlip => 0.005,
            Effect::DriveMotorLag => 0.02,
        };
        (value - absent).abs() >= least
    }
}

impl fmt::Display for Effect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::Effect;

    /// An effect fitted to its own absence names nothing: the sonar cone against the declared
    /// one (not against zero), the speed of sound against the calibration temperature.
    #[test]
    fn an_effect_departs_only_beyond_what_the_sensors_resolve() {
        assert!(!Effect::SonarBeamWidth.departs(&[15.004], 15.0));
        assert!(Effect::SonarBeamWidth.departs(&[15.004], 0.0));
        assert!(Effect::SonarBeamWidth.departs(&[12.0], 15.0));
        assert!(!Effect::SonarSpeedOfSound.departs(&[20.3], 0.0));
        assert!(Effect::SonarSpeedOfSound.departs(&[5.0], 0.0));
        assert!(!Effect::DriveMotorLag.departs(&[0.005], 0.0));
        assert!(Effect::DriveMotorLag.departs(&[0.1], 0.0));
        assert!(!Effect::LidarIncidenceAngle.departs(&[], 0.0));
        for e in Effect::ALL {
            assert!(!e.departs(&e.absent(10.0), 10.0), "{e:?}");
        }
    }
}
