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

/// The least mount yaw named, degrees: 5 mm at 2 m, the world's own tolerance (see
/// [`Effect::departs`]).
pub(crate) const MOUNT_YAW_RESOLUTION_DEG: f64 = 0.15;

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
    /// (lidar)`), for reports that list the effects one by one.
    #[must_use]
    pub fn label(self) -> String {
        match self {
            Effect::SensorLatency(s) => format!("{} ({s})", self.name()),
            _ => self.name().to_string(),
        }
    }

    /// The catalogue name.
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
            Effect::LidarMountOffset => "lidar_mount_offset",
            Effect::SensorLatency(_) => "sensor_latency",
            Effect::OdometerWheelRadius => "odometer_wheel_radius",
            Effect::DriveWheelBase => "drive_wheel_base",
            Effect::LidarRangeBias => "lidar_range_bias",
            Effect::SonarRangeBias => "sonar_range_bias",
            Effect::LidarDropout => "lidar_dropout",
        }
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

    /// The sensor it is fitted and named in.
    ///
    /// Where an effect shows in two, the one whose data tell it apart from its neighbours:
    /// - `odometer_wheel_radius` moves the robot `scale` times the command (the drive) and
    ///   makes the encoders disagree with the world (the odometer). It is the odometer's: the
    ///   encoders' disagreement is per wheel and everywhere (straight runs and turns), a
    ///   millimetre sensor against the truth, while in the drive an equal scale on both
    ///   wheels is what the declared actuation scale error already allows.
    /// - `drive_wheel_base` turns the robot `1/scale` times the command (the drive) while the
    ///   encoders agree with the command, so they disagree with the world's turn (the
    ///   odometer). It is the odometer's too: fitted beside the wheel radius on the same
    ///   data, the forward selection tells the two apart (the radius moves straight travel
    ///   as well, the base only turns) instead of each being named in its own sensor for
    ///   the other's mismatch. See [`Effect::shows_in`] for the drive.
    #[must_use]
    pub fn sensor(self) -> Sensor {
        match self {
            Effect::LidarMountOffset | Effect::LidarRangeBias | Effect::LidarDropout => {
                Sensor::Lidar
            }
            Effect::SensorLatency(s) => s,
            Effect::OdometerWheelRadius | Effect::DriveWheelBase => Sensor::Odometer,
            Effect::LidarIncidenceAngle
            | Effect::LidarReflectivity
            | Effect::LidarMixedPixels
            | Effect::LidarMotionSkew
            | Effect::LidarWarmupDrift => Sensor::Lidar,
            Effect::SonarBeamWidth | Effect::SonarSpeedOfSound | Effect::SonarRangeBias => {
                Sensor::Sonar
            }
            Effect::OdometerWheelSlip => Sensor::Odometer,
            Effect::DriveMotorLag => Sensor::Drive,
        }
    }

    /// Whether it changes what `sensor` reads (or where the drive goes): its own sensor and,
    /// for the wheels' radius and base, the drive too. The drive's data are diagnosed on top
    /// of the effects named elsewhere that show in it, so that their mismatch there is
    /// theirs, not another effect's.
    #[must_use]
    pub fn shows_in(self, sensor: Sensor) -> bool {
        self.sensor() == sensor
            || matches!(
                (self, sensor),
                (
                    Effect::OdometerWheelRadius | Effect::DriveWheelBase,
                    Sensor::Drive
                )
            )
    }

    /// Whether it changes the values its sensor reads (or where the drive goes): every entry
    /// but the lidar's dropout, which changes which readings there are, not what they read.
    #[must_use]
    pub fn moves_readings(self) -> bool {
        self != Effect::LidarDropout
    }

    /// Whether a second cause of it adds its scored size to the first's (two delays add, two
    /// radius errors multiply to about their sum): every entry but the lidar's dropout, whose
    /// losses compose as chances do, not as half-loss ranges add.
    #[must_use]
    pub fn sizes_add(self) -> bool {
        self != Effect::LidarDropout
    }

    /// Its parameters, in the order a [`super::Hypothesis`] holds them.
    ///
    /// The fit's ranges are wide enough for any plausible unit (several times the self-test's
    /// draws) and the grids fine enough that the likelihood is unimodal between neighbouring
    /// points. The self-test's moderate ranges (× its strength unless said): incidence κ
    /// ±[0.01, 0.03] (its power of `tan θ` 1); reflectivity c ±[0.008, 0.02] m; mixed pixels half-width [0.5, 1.5]°
    /// (at most 5°); motion skew the head's own period; warm-up k ±[0.004, 0.01] /m with τ in
    /// [5, 20] s (unscaled) — these two, on a fair coin, moved whole to their second term (the
    /// same scored error; `draw_values`); sonar cone [8, 20]° (at most 60°); air temperature 20 °C ±
    /// [15, 30] °C (within [−50, 60] °C, scored as the departure from 20 °C); slip gain
    /// [0.03, 0.1] s (braking alike); motor lag τ [0.1, 0.4] s (at most 10 s); mount yaw ±[1, 3]° and
    /// position ±[0.01, 0.03] m; latency [0.02, 0.08] s; each wheel's radius scale 1 ±
    /// [0.01, 0.03]; wheel-base scale 1 ± [0.03, 0.1]; range bias ±[10, 60] mm at 2 m and scale
    /// error ±[0.5, 3] % (its quadratic term not drawn); the sonar's range offset ±[10, 60] mm.
    #[must_use]
    pub const fn params(self) -> &'static [ParamSpec] {
        use super::params::SelfTestRange as R;
        // The collimated beam's term over ±0.2 m at 45° on a 2 cm grid: κ's window at 2 m, as
        // the self-test draws its size as κ's there (`draw_values` puts it all in one or the
        // other), so that a draw is never past the search's edge.
        // The power of tan θ over [0.5, 4] on a √2 grid through 1 (the footprint's depth) and 2
        // (an asymmetry that grows with it, `1/cos² θ − 1`): the form of the growth, which
        // the self-test's catalogue reality does not vary.
        const INCIDENCE: [ParamSpec; 3] = [
            lin(
                "coefficient",
                "",
                (-0.1, 0.1),
                11,
                R::uniform(0.01, 0.03).signed(),
            ),
            lin("collimated_m", "m", (-0.2, 0.2), 21, R::zero()),
            log(
                "exponent",
                "",
                (0.5, 4.0),
                7,
                R::zero().around(1.0, 0.5, 4.0),
            )
            .form(),
        ];
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
        )
        .searched_from_zero()];
        const SKEW: [ParamSpec; 1] =
            [lin("revolution_s", "s", (0.0, 0.6), 9, R::lidar_revolution()).searched_from_zero()];
        // The warm-up's constant term over ±0.1 m on a 5 cm grid (a unit's drift is
        // centimetres at most), Nelder–Mead refining the three together. The self-test draws
        // its size as the quadratic term's (`draw_values` puts it all in one or the other).
        const WARMUP: [ParamSpec; 3] = [
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
            )
            .form(),
            lin("offset_m", "m", (-0.1, 0.1), 5, R::zero()),
        ];
        const BEAM: [ParamSpec; 1] = [lin(
            "half_angle_deg",
            "deg",
            (0.0, 45.0),
            16,
            R::uniform(8.0, 20.0).at_most(60.0),
        )
        .searched_from_zero()];
        const SOUND: [ParamSpec; 1] = [lin(
            "air_temperature_c",
            "degC",
            (-50.0, 60.0),
            23,
            R::uniform(15.0, 30.0).signed().around(20.0, -50.0, 60.0),
        )];
        // Slip's gain is searched at g ≥ 0 only (the same 0.1 s grid as before on that side):
        // a driven wheel's surface outruns the ground as it accelerates (the traction force
        // needs a positive slip ratio: Wong, *Theory of Ground Vehicles*, ch. 1), so the
        // encoders lead. Encoders that lag the travel by `L v` are a late stamp, the
        // odometer's `sensor_latency`, which is otherwise a slip with g = −L.
        //
        // The braking gain as a share of the driving one over [−1, 1] on a 0.5 grid
        // through 1 (even: braking gives back what speeding up led), 0 (slip only while speeding
        // up) and −1 (a lead gained at every change of speed): the form, which the self-test's
        // catalogue reality keeps even.
        const SLIP: [ParamSpec; 2] = [
            lin("gain_s", "s", (0.0, 0.5), 6, R::uniform(0.03, 0.1)).searched_from_zero(),
            lin(
                "braking_share",
                "",
                (-1.0, 1.0),
                5,
                R::zero().around(1.0, -1.0, 1.0),
            )
            .form(),
        ];
        // The lag's response time, and its form as the inverse of a second-order response's
        // damping over [0, 2.5] on a 0.5 grid: 0 the first-order lag (a second order's limit as
        // its damping grows at the same response time), 1 critical damping, 2.5 a wheel that
        // overshoots by 52 % (ζ = 0.4). The form, which the self-test's catalogue reality keeps
        // first order.
        const LAG: [ParamSpec; 2] = [
            log(
                "time_constant_s",
                "s",
                (0.005, 5.0),
                13,
                R::uniform(0.1, 0.4).at_most(10.0),
            )
            .searched_from_zero(),
            lin("underdamping", "", (0.0, 2.5), 6, R::zero()).form(),
        ];
        // The mount's yaw is searched over ±8° (a unit bolted visibly crooked is past it) on
        // a 2° grid: a wall seen 2° off moves by 3.5 % of its range, which the likelihood
        // follows smoothly; its position over ±0.1 m on a coarse grid, Nelder–Mead refining
        // all three.
        const MOUNT: [ParamSpec; 3] = [
            lin(
                "yaw_deg",
                "deg",
                (-8.0, 8.0),
                9,
                R::uniform(1.0, 3.0).signed(),
            ),
            lin("x_m", "m", (-0.1, 0.1), 3, R::uniform(0.01, 0.03).signed()),
            lin("y_m", "m", (-0.1, 0.1), 3, R::uniform(0.01, 0.03).signed()),
        ];
        // A delay of up to 0.3 s (a driver buffering a whole revolution of a 5 Hz lidar is
        // 0.2 s) on a 0.02 s grid.
        const LIDAR_LATENCY: [ParamSpec; 1] =
            [lin("lidar_s", "s", (0.0, 0.3), 16, R::uniform(0.02, 0.08)).searched_from_zero()];
        const SONAR_LATENCY: [ParamSpec; 1] =
            [lin("sonar_s", "s", (0.0, 0.3), 16, R::uniform(0.02, 0.08)).searched_from_zero()];
        const ODOMETER_LATENCY: [ParamSpec; 1] =
            [lin("odometer_s", "s", (0.0, 0.3), 16, R::uniform(0.02, 0.08)).searched_from_zero()];
        // Radius and base scales within ±20 % / ±30 % of nominal (a worn or soft tyre is a
        // few per cent; the scenario allows ±50 %).
        const RADIUS: [ParamSpec; 2] = [
            lin(
                "left_scale",
                "",
                (0.8, 1.2),
                9,
                R::uniform(0.01, 0.03).signed().around(1.0, 0.5, 1.5),
            ),
            lin(
                "right_scale",
                "",
                (0.8, 1.2),
                9,
                R::uniform(0.01, 0.03).signed().around(1.0, 0.5, 1.5),
            ),
        ];
        const BASE: [ParamSpec; 1] = [lin(
            "scale",
            "",
            (0.7, 1.3),
            13,
            R::uniform(0.03, 0.1).signed().around(1.0, 0.5, 1.5),
        )];
        // The range bias as its error at 2 m (the middle of a room's ranges), its slope there
        // and its curvature about it, `a + s (d − 2 m) + q (d − 2 m)²`: in the papers'
        // `c + s d + q d²` the offset and the scale trade against each other over a room's
        // ranges (the simplex, started on the grid, ran along their valley to the box's
        // corner), while about the middle the three are nearly independent. The error at 2 m
        // over ±0.2 m on a 5 cm grid, the scale error over ±10 % on a 5 % grid, the curvature
        // over ±0.02 /m (a third of the XV-11's own 0.058 /m, the landmark paper's Sec. 4.1):
        // the readings' means are linear in all three, so the likelihood is unimodal.
        const RANGE_BIAS: [ParamSpec; 3] = [
            lin(
                "at_2m_m",
                "m",
                (-0.2, 0.2),
                9,
                R::uniform(0.01, 0.06).signed(),
            ),
            lin(
                "scale_error",
                "",
                (-0.1, 0.1),
                5,
                R::uniform(0.005, 0.03).signed(),
            ),
            lin("quadratic_per_m", "1/m", (-0.02, 0.02), 3, R::zero()).form(),
        ];
        // The sonar's range offset alone, over ±0.2 m on a 5 cm grid: its scale is the speed
        // of sound's (`sonar_speed_of_sound` scales every range, and an affine sonar's scale
        // error is that one's parameter), so the two entries together are the EM paper's
        // affine sonar and neither can pass for the other.
        const SONAR_RANGE_BIAS: [ParamSpec; 1] = [lin(
            "offset_m",
            "m",
            (-0.2, 0.2),
            9,
            R::uniform(0.01, 0.06).signed(),
        )];
        // The range at which half the returns are lost head-on on the reference surface over
        // 0.5–50 m on a log grid (a unit that loses half at 50 m loses nothing a room shows),
        // the spread of the returned log power over 0.05–2 (the loss rising from 12 % to 88 %
        // over a factor 1.1 to 55 of range). The loss chance is smooth in both, so the
        // Bernoulli likelihood is unimodal between grid points.
        const DROPOUT: [ParamSpec; 2] = [
            log(
                "half_loss_range_m",
                "m",
                (0.5, 50.0),
                11,
                R::uniform(3.0, 5.0).unscaled(),
            )
            .form(),
            log(
                "log_power_spread",
                "",
                (0.05, 2.0),
                7,
                R::uniform(0.15, 0.4).unscaled(),
            )
            .form(),
        ];
        match self {
            Effect::LidarDropout => &DROPOUT,
            Effect::LidarMountOffset => &MOUNT,
            Effect::SonarRangeBias => &SONAR_RANGE_BIAS,
            Effect::LidarRangeBias => &RANGE_BIAS,
            Effect::SensorLatency(Sensor::Lidar) => &LIDAR_LATENCY,
            Effect::SensorLatency(Sensor::Sonar) => &SONAR_LATENCY,
            Effect::SensorLatency(Sensor::Odometer) => &ODOMETER_LATENCY,
            // The drive's commands are stamped when issued: no latency of its own.
            Effect::SensorLatency(Sensor::Drive) => &[],
            Effect::OdometerWheelRadius => &RADIUS,
            Effect::DriveWheelBase => &BASE,
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

    /// The shapes its fit searches one at a time before (see
    /// [`Effect::shapes_refined_together`]) refining every parameter together: each the
    /// parameters left free (indices into [`Effect::params`]), the others at their
    /// [`Effect::absent`] values. None (all parameters at once) but for the warm-up, whose drift
    /// is searched in its quadratic term with τ and in its constant term with τ: a drift all in
    /// one term (as a unit's pointing or its housing makes it, or another simulator's "bias
    /// drift") sits between the joint grid's coarse points but on that shape's own grid, and
    /// Nelder–Mead over all three from the joint grid was measured to stop at τ's bound (an
    /// independent reality's k = −0.0044 /m, τ = 12.8 s fitted as τ = 1 s).
    ///
    /// Against a trajectory estimated from the lidar itself the warm-up's constant term is
    /// fitted too. The scan matching takes part of a range offset every beam shares into the
    /// pose (it weighs the near readings most, and the pose shifts away from them), and the
    /// realignment gives it back (`realign_lidar` in the diagnosis settles each term apart, by
    /// rounds of estimating the path under it, and keeps the one the lidar's held-out readings
    /// favour). Held at zero, a warm-up drawn in that term would be fitted in its quadratic
    /// term and its early position error named as a wheel radius or slip; a drift that does not settle within the run, which the term freed
    /// took up beside a concealed reflectivity, is not named (`select::earns_place`).
    ///
    /// The incidence's two terms, a diverging beam's `κ d tanᵖ θ` and a collimated one's
    /// `c tanᵖ θ`, are alternatives: searched each alone (each with the power p of its growth)
    /// and not refined together (see [`Effect::shapes_refined_together`]).
    #[must_use]
    pub fn shapes(self) -> &'static [&'static [usize]] {
        match self {
            Effect::LidarWarmupDrift => &[&[0, 1], &[2, 1]],
            Effect::LidarIncidenceAngle => &[&[0, 2], &[1, 2]],
            _ => &[],
        }
    }

    /// The parameters that set its form, not its size (indices into [`Effect::params`]): the
    /// warm-up's time constant, the incidence's power of `tan θ`, the slip's braking share and
    /// the motor lag's underdamping. A path estimated from the
    /// lidar takes up part of an effect's size, not of its form, so the realignment follows the
    /// size alone to its fixed point.
    #[must_use]
    pub const fn form_params(self) -> &'static [usize] {
        match self {
            Effect::LidarWarmupDrift => &[1],
            Effect::LidarIncidenceAngle => &[2],
            Effect::OdometerWheelSlip | Effect::DriveMotorLag => &[1],
            _ => &[],
        }
    }

    /// The parameters its fit left free at `params` (indices into [`Effect::params`]): those of
    /// its [`Effect::shapes`] (all with none), and of alternative shapes the one `params` is
    /// in (a parameter of another shape departs from its absence); the rest were held at
    /// their absence and are not estimates.
    #[must_use]
    pub fn free(self, params: &[f64]) -> Vec<usize> {
        let shapes = self.shapes();
        if shapes.is_empty() {
            return (0..self.params().len()).collect();
        }
        let absent = self.absent(0.0);
        let mut free: Vec<usize> = Vec::new();
        let mut chosen: Vec<&[usize]> = shapes.to_vec();
        if !self.shapes_refined_together() {
            let departs = |shape: &[usize]| {
                shape
                    .iter()
                    .any(|&i| params.get(i) != absent.get(i) && !shapes[0].contains(&i))
            };
            chosen = vec![shapes
                .iter()
                .skip(1)
                .find(|s| departs(s))
                .copied()
                .unwrap_or(shapes[0])];
        }
        for shape in chosen {
            for &i in shape {
                if !free.contains(&i) {
                    free.push(i);
                }
            }
        }
        free.sort_unstable();
        free
    }

    /// Whether the best of [`Effect::shapes`] is refined with all parameters free. Not the
    /// incidence's: a beam diverges or is collimated over a unit's range, and the two terms
    /// together trade against each other (an independent simulator's range-independent error,
    /// fitted as κ = −0.0024 with c = 8 mm, raised the ranges' RMSE where c alone lowered it).
    #[must_use]
    pub fn shapes_refined_together(self) -> bool {
        self != Effect::LidarIncidenceAngle
    }

    /// The parameter values at which the effect is absent (what the nominal model assumes),
    /// given the declared sonar cone for the beam width and the declared calibration
    /// temperature (20 °C) for the speed of sound. The warm-up drift is absent at k = 0 for
    /// any τ, the incidence at κ = c = 0 for any power of `tan θ` (held at 1, the catalogue's
    /// first-order form).
    #[must_use]
    pub fn absent(self, declared_half_angle_deg: f64) -> Vec<f64> {
        match self {
            Effect::LidarWarmupDrift => vec![0.0, 10.0, 0.0],
            Effect::LidarIncidenceAngle => vec![0.0, 0.0, 1.0],
            Effect::SonarBeamWidth => vec![declared_half_angle_deg],
            Effect::SonarSpeedOfSound => vec![20.0],
            Effect::LidarMountOffset | Effect::LidarRangeBias => vec![0.0; 3],
            Effect::OdometerWheelRadius => vec![1.0, 1.0],
            Effect::DriveWheelBase => vec![1.0],
            Effect::OdometerWheelSlip => vec![0.0, 1.0],
            Effect::DriveMotorLag => vec![0.0, 0.0],
            // Half the returns lost only at the search's far end.
            Effect::LidarDropout => vec![50.0, 0.3],
            _ => vec![0.0],
        }
    }

    /// The smallest departure of the scored parameter (the first) from its absence that names
    /// the effect: below it the fitted model is the nominal one to within what the sensors
    /// resolve, so what it "explains" is noise the fit chased. Each is about one millimetre of
    /// range where the effect acts (or the model's own resolution):
    /// - incidence κ: 0.001 is 1 mm per metre at 45°, and its collimated term 1 mm at 45°;
    /// - reflectivity c: 1 mm on a surface of half the reference's reflectivity;
    /// - mixed pixels: a beam half-width of 0.1°, a third of a typical 0.3° direction noise;
    /// - motion skew: a revolution of 0.02 s, a tenth of the XV-11's 0.2 s;
    /// - warm-up k: 0.00025 /m, 1 mm at 2 m at power-on, and its constant term 1 mm;
    /// - sonar cone: 1°, four of the emulator's 0.25° rays;
    /// - speed of sound: 0.6 °C, 0.1 % of range (1 mm at 1 m);
    /// - wheel slip g: 0.01 s, the odometer's 2 mm floor over a 0.2 m/s change of speed
    ///   (slip's extra travel is g Δv);
    /// - motor lag τ: 0.02 s, two physics steps (the drive's resolution is 0.01 s);
    /// - mount yaw: 0.15°, 5 mm at 2 m, and its position 5 mm: the world's own tolerance (the
    ///   lidar's floor, `Floors`), below which a mount offset is as likely a wall a few
    ///   millimetres off;
    /// - latency: 5 ms, 1.5 mm of motion at 0.3 m/s;
    /// - wheel radius: a scale of 0.003: a rubber tyre's rolling radius changes by that much
    ///   under load (0.1 mm of deflection on a 35 mm wheel), and two simulators integrating a
    ///   wheel's arc differ by 0.1 % (an independent reality's faithful runs fit 0.999);
    /// - wheel base: a scale of 0.0005, 1 mm of turn per 2 m of wheel travel;
    /// - range bias: 1 mm at 2 m, or 1 mm at 0 and 4 m of its scale error or curvature; the
    ///   sonar's offset 1 mm;
    /// - dropout: half the returns lost nearer than 25 m (at the search's far end of 50 m a
    ///   room's readings are lost only in the logistic's tail, which the spread alone sets).
    ///
    /// An effect of several parameters that all describe its size (the mount, the two
    /// wheels, the warm-up's and the incidence's two terms, the range bias's three) departs when any of them does.
    #[must_use]
    pub fn departs(self, params: &[f64], declared_half_angle_deg: f64) -> bool {
        let Some(&value) = params.first() else {
            return false;
        };
        let absent = self.absent(declared_half_angle_deg);
        let beyond = |i: usize, least: f64| {
            params
                .get(i)
                .zip(absent.get(i))
                .is_some_and(|(v, a)| (v - a).abs() >= least)
        };
        match self {
            Effect::LidarMountOffset => {
                return beyond(0, MOUNT_YAW_RESOLUTION_DEG) || beyond(1, 0.005) || beyond(2, 0.005);
            }
            Effect::OdometerWheelRadius => return beyond(0, 0.003) || beyond(1, 0.003),
            Effect::LidarWarmupDrift => return beyond(0, 0.000_25) || beyond(2, 0.001),
            Effect::LidarIncidenceAngle => return beyond(0, 0.001) || beyond(1, 0.001),
            Effect::LidarRangeBias => {
                return beyond(0, 0.001) || beyond(1, 0.000_5) || beyond(2, 0.000_25);
            }
            _ => {}
        }
        let absent = absent[0];
        let least = match self {
            Effect::LidarReflectivity => 0.001,
            Effect::LidarMixedPixels => 0.1,
            Effect::LidarMotionSkew => 0.02,
            Effect::SonarBeamWidth => 1.0,
            Effect::SonarSpeedOfSound => 0.6,
            Effect::OdometerWheelSlip => 0.01,
            Effect::DriveMotorLag => 0.02,
            Effect::SensorLatency(_) => 0.005,
            Effect::DriveWheelBase => 0.000_5,
            Effect::SonarRangeBias => 0.001,
            Effect::LidarDropout => 25.0,
            // Returned above.
            Effect::LidarMountOffset
            | Effect::OdometerWheelRadius
            | Effect::LidarWarmupDrift
            | Effect::LidarIncidenceAngle
            | Effect::LidarRangeBias => 0.0,
        };
        (value - absent).abs() >= least
    }
}

impl Effect {
    /// The quantity the self-test scores a fit of `params` by: the first parameter's departure
    /// from its [`SelfTestRange::scored`](super::SelfTestRange::scored) centre; for the
    /// warm-up, its range error at 2 m at power-on, `c + k (2 m)²`, for the incidence at 2 m
    /// and 45°, `c + κ 2 m`, which either term alone may carry, and for the range bias its
    /// error at 2 m (its first parameter).
    #[must_use]
    pub fn scored(self, params: &[f64]) -> f64 {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        match self {
            Effect::LidarWarmupDrift | Effect::LidarIncidenceAngle => self
                .size_terms()
                .iter()
                .map(|&(i, weight)| weight * p(i))
                .sum(),
            _ => self
                .params()
                .first()
                .map_or(f64::NAN, |spec| spec.self_test.scored(p(0))),
        }
    }
}

impl Effect {
    /// The parameters that carry its size, each with its weight in the size
    /// ([`Effect::scored`]'s for the two-term effects): the warm-up's range error at 2 m at
    /// power-on is `c + k (2 m)²`, the incidence's at 2 m and 45° `c + κ 2 m`; any other
    /// effect's size is its first parameter.
    #[must_use]
    pub const fn size_terms(self) -> &'static [(usize, f64)] {
        match self {
            Effect::LidarWarmupDrift => &[(0, 4.0), (2, 1.0)],
            Effect::LidarIncidenceAngle => &[(0, 2.0), (1, 1.0)],
            _ => &[(0, 1.0)],
        }
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
}
