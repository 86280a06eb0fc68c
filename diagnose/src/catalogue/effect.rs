//! The catalogued effects as one identity type: each names its [`Entry`] (`entries/`), which
//! holds what the catalogue says about it.

use std::fmt;

use hilsim_sim::scenario::Effects;

use super::entries;
use super::entry::{Entry, Variable};
use super::params::ParamSpec;
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
    /// `lidar_mount_offset`.
    LidarMountOffset,
    /// `sensor_latency` of one sensor (the lidar, the sonar or the odometer): one catalogue
    /// entry, fitted in each sensor where a mismatch is located and reporting that sensor's
    /// delay only, since each sensor's driver stamps its own readings.
    SensorLatency(Sensor),
    /// `odometer_wheel_radius`.
    OdometerWheelRadius,
    /// `drive_wheel_base`.
    DriveWheelBase,
    /// `lidar_range_bias`.
    LidarRangeBias,
    /// `sonar_range_bias`.
    SonarRangeBias,
    /// `lidar_dropout`: readings missing where the world says the unit would read. Fitted on
    /// the lidar's readings valid or not (`crate::dropout`), not on the ranges.
    LidarDropout,
}

impl Effect {
    /// The whole catalogue, in `interfaces.md` order (`sensor_latency` once per sensor it
    /// concerns).
    pub const ALL: [Effect; 18] = [
        Effect::LidarIncidenceAngle,
        Effect::LidarReflectivity,
        Effect::LidarMixedPixels,
        Effect::LidarMotionSkew,
        Effect::LidarWarmupDrift,
        Effect::SonarBeamWidth,
        Effect::SonarSpeedOfSound,
        Effect::OdometerWheelSlip,
        Effect::DriveMotorLag,
        Effect::LidarMountOffset,
        Effect::SensorLatency(Sensor::Lidar),
        Effect::SensorLatency(Sensor::Sonar),
        Effect::SensorLatency(Sensor::Odometer),
        Effect::OdometerWheelRadius,
        Effect::DriveWheelBase,
        Effect::LidarRangeBias,
        Effect::SonarRangeBias,
        Effect::LidarDropout,
    ];

    /// Its catalogue entry: what the catalogue says about it.
    ///
    /// ```
    /// use hilsim_diagnose::{Effect, Entry, Sensor};
    /// let latency = Effect::SensorLatency(Sensor::Sonar).entry();
    /// assert_eq!(latency.name(), "sensor_latency");
    /// assert_eq!(latency.sensor(), Sensor::Sonar);
    /// ```
    #[must_use]
    pub fn entry(self) -> &'static dyn Entry {
        match self {
            Effect::LidarIncidenceAngle => &entries::LidarIncidenceAngle,
            Effect::LidarReflectivity => &entries::LidarReflectivity,
            Effect::LidarMixedPixels => &entries::LidarMixedPixels,
            Effect::LidarMotionSkew => &entries::LidarMotionSkew,
            Effect::LidarWarmupDrift => &entries::LidarWarmupDrift,
            Effect::SonarBeamWidth => &entries::SonarBeamWidth,
            Effect::SonarSpeedOfSound => &entries::SonarSpeedOfSound,
            Effect::OdometerWheelSlip => &entries::OdometerWheelSlip,
            Effect::DriveMotorLag => &entries::DriveMotorLag,
            Effect::LidarMountOffset => &entries::LidarMountOffset,
            Effect::SensorLatency(s) => entries::SensorLatency::of(s),
            Effect::OdometerWheelRadius => &entries::OdometerWheelRadius,
            Effect::DriveWheelBase => &entries::DriveWheelBase,
            Effect::LidarRangeBias => &entries::LidarRangeBias,
            Effect::SonarRangeBias => &entries::SonarRangeBias,
            Effect::LidarDropout => &entries::LidarDropout,
        }
    }

    /// The catalogue's entries (its names, each once), in `interfaces.md` order.
    ///
    /// ```
    /// use hilsim_diagnose::Effect;
    /// assert_eq!(Effect::entries().len(), 16);
    /// assert_eq!(Effect::entries()[10], "sensor_latency");
    /// ```
    #[must_use]
    pub fn entries() -> Vec<&'static str> {
        let mut names: Vec<&'static str> = Vec::new();
        for e in Self::ALL {
            if !names.contains(&e.name()) {
                names.push(e.name());
            }
        }
        names
    }

    /// The name with the sensor where one entry is fitted in several (`sensor_latency
    /// (lidar)`), for reports that list the effects one by one ([`Entry::label`]).
    #[must_use]
    pub fn label(self) -> String {
        self.entry().label()
    }

    /// The catalogue name ([`Entry::name`]).
    ///
    /// ```
    /// use hilsim_diagnose::Effect;
    /// for e in Effect::ALL {
    ///     assert!(Effect::named(e.name()).contains(&e));
    ///     assert_eq!(Effect::from_name(e.name()).map(Effect::name), Some(e.name()));
    /// }
    /// ```
    #[must_use]
    pub fn name(self) -> &'static str {
        self.entry().name()
    }

    /// The effect of a catalogue name (`sensor_latency`: the lidar's; see [`Effect::named`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.name() == name)
    }

    /// Every effect of a catalogue name (`sensor_latency`: one per sensor).
    #[must_use]
    pub fn named(name: &str) -> Vec<Self> {
        Self::ALL.into_iter().filter(|e| e.name() == name).collect()
    }

    /// The sensor it is fitted and named in ([`Entry::sensor`]).
    #[must_use]
    pub fn sensor(self) -> Sensor {
        self.entry().sensor()
    }

    /// Whether it changes what `sensor` reads (or where the drive goes) ([`Entry::shows_in`]).
    #[must_use]
    pub fn shows_in(self, sensor: Sensor) -> bool {
        self.entry().shows_in(sensor)
    }

    /// Whether it changes the values its sensor reads (or where the drive goes): every entry
    /// but the lidar's dropout ([`Entry::moves_readings`]).
    #[must_use]
    pub fn moves_readings(self) -> bool {
        self.entry().moves_readings()
    }

    /// Whether a second cause of it adds its scored size to the first's: every entry but the
    /// lidar's dropout ([`Entry::sizes_add`]).
    #[must_use]
    pub fn sizes_add(self) -> bool {
        self.entry().sizes_add()
    }

    /// The explanatory variables its mechanism acts through ([`Entry::variables`]).
    ///
    /// ```
    /// use hilsim_diagnose::{Effect, Variable};
    /// assert!(Effect::LidarIncidenceAngle.variables().contains(&Variable::IncidenceAngle));
    /// assert!(Effect::ALL.iter().all(|e| !e.variables().is_empty()));
    /// ```
    #[must_use]
    pub fn variables(self) -> &'static [Variable] {
        self.entry().variables()
    }

    /// Its parameters, in the order a [`crate::Hypothesis`] holds them ([`Entry::params`]).
    #[must_use]
    pub fn params(self) -> &'static [ParamSpec] {
        self.entry().params()
    }

    /// The shapes its fit searches one at a time before refining every parameter together
    /// ([`Entry::shapes`]).
    #[must_use]
    pub fn shapes(self) -> &'static [&'static [usize]] {
        self.entry().shapes()
    }

    /// The parameters its shapes' joint refinement frees besides theirs: against a recorded
    /// path those of [`Entry::refined_against_recorded_path`], along an estimated one
    /// (`estimated`) none.
    #[must_use]
    pub fn refined_besides_shapes(self, estimated: bool) -> &'static [usize] {
        if estimated {
            &[]
        } else {
            self.entry().refined_against_recorded_path()
        }
    }

    /// The parameters that set its form, not its size ([`Entry::form_params`]).
    #[must_use]
    pub fn form_params(self) -> &'static [usize] {
        self.entry().form_params()
    }

    /// The parameters its fit left free at `params` ([`Entry::free`]).
    #[must_use]
    pub fn free(self, params: &[f64]) -> Vec<usize> {
        self.entry().free(params)
    }

    /// Whether the best of [`Effect::shapes`] is refined with all parameters free
    /// ([`Entry::shapes_refined_together`]).
    #[must_use]
    pub fn shapes_refined_together(self) -> bool {
        self.entry().shapes_refined_together()
    }

    /// The parameter values at which the effect is absent, given the declared sonar cone
    /// ([`Entry::absent`]).
    #[must_use]
    pub fn absent(self, declared_half_angle_deg: f64) -> Vec<f64> {
        self.entry().absent(declared_half_angle_deg)
    }

    /// Whether `params` depart from the effect's absence by more than the sensors resolve
    /// ([`Entry::departs`]).
    #[must_use]
    pub fn departs(self, params: &[f64], declared_half_angle_deg: f64) -> bool {
        self.entry().departs(params, declared_half_angle_deg)
    }

    /// The quantity the self-test scores a fit of `params` by ([`Entry::scored`]).
    #[must_use]
    pub fn scored(self, params: &[f64]) -> f64 {
        self.entry().scored(params)
    }

    /// The parameters that carry its size, each with its weight in the size
    /// ([`Entry::size_terms`]).
    #[must_use]
    pub fn size_terms(self) -> &'static [(usize, f64)] {
        self.entry().size_terms()
    }

    /// Switches the effect on in `effects` with `params` (in the order of [`Effect::params`]; a
    /// missing one is 0), replacing its table if the scenario already has one
    /// ([`Entry::apply`]).
    ///
    /// ```
    /// use hilsim_diagnose::Effect;
    /// let mut effects = hilsim_sim::scenario::Effects::default();
    /// Effect::SonarBeamWidth.apply(&[12.0], &mut effects);
    /// assert_eq!(effects.sonar_beam_width.map(|b| b.half_angle_deg), Some(12.0));
    /// ```
    pub fn apply(self, params: &[f64], effects: &mut Effects) {
        self.entry().apply(params, effects);
    }

    /// One sentence: the physics the simulation left out, with the fitted parameters
    /// ([`Entry::explanation`]).
    #[must_use]
    pub fn explanation(self, params: &[f64], declared_half_angle_deg: f64) -> String {
        self.entry().explanation(params, declared_half_angle_deg)
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
        // Either wheel, any part of the mount.
        assert!(Effect::OdometerWheelRadius.departs(&[1.0, 1.02], 0.0));
        assert!(!Effect::OdometerWheelRadius.departs(&[1.0001, 0.9999], 0.0));
        assert!(Effect::LidarMountOffset.departs(&[0.0, 0.0, 0.01], 0.0));
        assert!(!Effect::LidarMountOffset.departs(&[0.01, 0.001, 0.0], 0.0));
        // Half a long-range unit's returns lost head-on at 28 m (half of all beyond 6 m of a
        // building's corridors); at 45 m, within the search's far end.
        assert!(Effect::LidarDropout.departs(&[28.3, 1.13], 0.0));
        assert!(!Effect::LidarDropout.departs(&[45.0, 1.13], 0.0));
    }

    #[test]
    fn latency_is_one_entry_fitted_per_sensor() {
        use super::Sensor;
        let all = Effect::named("sensor_latency");
        assert_eq!(all.len(), 3);
        for (e, s) in all
            .iter()
            .zip([Sensor::Lidar, Sensor::Sonar, Sensor::Odometer])
        {
            assert_eq!(e.sensor(), s);
            assert_eq!(e.params().len(), 1);
            assert_eq!(e.params()[0].name, format!("{}_s", s.name()));
        }
        assert!(Effect::DriveWheelBase.shows_in(Sensor::Drive));
        assert!(!Effect::OdometerWheelSlip.shows_in(Sensor::Drive));
    }

    /// A warm-up's stretch is refined against a recorded path only, is a free parameter (with
    /// a standard error) where the refinement moved it off one mass, and its sentence says the
    /// shape departs from the catalogue's; a sonar timed at the centroid says so too.
    #[test]
    fn a_form_refined_off_the_catalogues_is_free_and_said() {
        let warmup = Effect::LidarWarmupDrift;
        assert_eq!(warmup.refined_besides_shapes(false), &[3]);
        assert!(warmup.refined_besides_shapes(true).is_empty());
        let one_mass = [0.005, 10.0, 0.0, 1.0];
        let stretched = [0.005, 10.0, 0.0, 1.6];
        assert_eq!(warmup.free(&one_mass), vec![0, 1, 2]);
        assert_eq!(warmup.free(&stretched), vec![0, 1, 2, 3]);
        assert!(!warmup.explanation(&one_mass, 0.0).contains("differs"));
        let said = warmup.explanation(&stretched, 0.0);
        assert!(said.contains("^1.60") && said.contains("differs"), "{said}");
        let sonar = Effect::SonarBeamWidth;
        assert!(!sonar.explanation(&[12.0, 0.0], 0.0).contains("centroid"));
        let said = sonar.explanation(&[12.0, 1.0], 0.0);
        assert!(
            said.contains("echoes at their centroid") && said.contains("differs"),
            "{said}"
        );
        let said = sonar.explanation(&[12.0, 0.5], 0.0);
        assert!(said.contains("50 % at their centroid"), "{said}");
    }
}
