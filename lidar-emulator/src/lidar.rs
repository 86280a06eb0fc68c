//! The Neato XV-11 triangulation lidar: a head spinning at ~300 rpm taking one reading per degree,
//! each at its own instant from the robot's pose at that instant.

use hilsim_recording::LidarSample;
use hilsim_sim::pose::wrap_angle;
use std::sync::Arc;

use hilsim_sim::scan_schedule::{Scan, ScanSchedule};
use hilsim_sim::scenario::LidarModel;
use hilsim_sim::{rng, scenario, StepState, World};
use rand::Rng as _;
use rand_distr::{Distribution, StandardNormal};

use crate::effects::{dropout_probability, BeamReturn, LidarEffects};
use crate::neato_packet::{rpm_to_fixed, MAX_DISTANCE_MM, READINGS_PER_REVOLUTION};
use crate::range_model::{ModelError, RangeModel};
use crate::unit_scans::UnitScans;
use hilsim_recording::Mount;

/// Error code for "no return": nothing within range, or the reading fell beyond the maximum.
/// The most frequent code in the real capture `xv11-hand-in-box.bin` (1,996 of ~2,800 invalid
/// readings), where much of the view looked out of the box's open side. The firmware's meanings
/// are undocumented; this assignment is hilsim's.
pub const ERROR_NO_RETURN: u8 = 0x52;
/// Error code for a reading nearer than the minimum range (seen on real units; meaning assumed).
pub const ERROR_TOO_CLOSE: u8 = 0x21;
/// Error code for a return too weak to range (seen on real units; meaning assumed).
pub const ERROR_WEAK_SIGNAL: u8 = 0x35;

/// Signal strength of a normal-incidence return from a surface of reflectivity 0.8 at 1 m.
/// Fitted to the real capture's valid readings: medians 685 at 0.25–0.4 m and 474 at 0.4–0.7 m
/// give a fall-off of d^-0.70 and 311 at 1 m (the XV-11 adapts its exposure, so the fall-off is
/// far shallower than the inverse square of a fixed-gain receiver).
const STRENGTH_AT_1M: f64 = 311.0;
/// Exponent of the strength's fall-off with distance (same fit).
const STRENGTH_FALLOFF: f64 = 0.70;
/// Reflectivity the strength reference was taken at.
const REFERENCE_REFLECTIVITY: f64 = 0.8;
/// Below this strength the unit sets the strength-warning flag: in the real capture no reading
/// without the flag is below 58, and most flagged ones are below 50.
pub const STRENGTH_WARNING_BELOW: u16 = 50;
/// Below this strength there is no usable return (flagged invalid with [`ERROR_WEAK_SIGNAL`]).
pub const STRENGTH_INVALID_BELOW: u16 = 10;
/// Relative spread of the strength between readings (speckle); a modelling choice.
const STRENGTH_SPREAD: f64 = 0.1;
/// Revolutions per period of the rpm wobble (about 2 s at 300 rpm: the motor's speed loop).
const WOBBLE_PERIOD_REVS: f64 = 10.0;

/// One emulated reading, with what the wire needs beyond the recording's columns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LidarReading {
    /// When the reading was taken, seconds.
    pub t_s: f64,
    /// Revolution counter.
    pub rev: u64,
    /// The reading's place in its revolution: the XV-11's whole degree 0..359 (its slot in the
    /// packets); for a lidar replaying a log's scans, the beam's index in its scan.
    pub index: u16,
    /// The beam's angle in the lidar's frame, degrees in [0, 360), counter-clockwise.
    pub angle_deg: f64,
    /// Reported distance in millimetres (0 when invalid).
    pub distance_mm: u16,
    /// The error code when the reading is invalid.
    pub error_code: Option<u8>,
    /// Signal strength.
    pub strength: u16,
    /// The strength-warning flag.
    pub warning: bool,
    /// The true range along the beam (`None`: nothing hit).
    pub true_range_m: Option<f64>,
    /// The rate of its revolution, Hz (what a unit's packets report).
    pub rev_hz: f64,
}

impl LidarReading {
    /// The reading as a recording row. An invalid reading's range is 0 and, when nothing was
    /// hit, its true range is recorded as 0 too (the column must be numeric).
    #[must_use]
    pub fn to_sample(&self) -> LidarSample {
        LidarSample {
            t_s: hilsim_sim::exact_time_s(self.t_s),
            rev: self.rev,
            angle_deg: self.angle_deg,
            range_m: f64::from(self.distance_mm) / 1000.0,
            strength: self.strength,
            invalid: self.error_code.is_some(),
            warning: self.warning,
            true_range_m: Some(self.true_range_m.unwrap_or(0.0)),
        }
    }
}

/// The emulated XV-11.
pub struct Lidar {
    model: RangeModel,
    mount: Mount,
    angle_noise_rad: f64,
    rpm: f64,
    rpm_wobble: f64,
    wobble_phase: f64,
    min_mm: f64,
    max_mm: f64,
    rng: rng::Rng,
    rev: u64,
    index: u16,
    rev_start_s: f64,
    rev_rpm: f64,
    effects: LidarEffects,
    /// `[effects.sensor_latency]`: how late each reading is stamped, seconds (0 when off).
    latency_s: f64,
    /// `timing = "per_revolution"` without `[effects.lidar_motion_skew]`: every reading of a
    /// revolution from the lidar's pose at the revolution's start.
    snapshot: bool,
    /// The lidar's origin and 0° direction at the current revolution's start (snapshot only).
    rev_pose: Option<([f64; 2], f64)>,
    /// The motor's speed of each revolution while it spins up (`[link] spin_up_s`); empty when
    /// it starts at speed.
    spin_up_rpm: Vec<f64>,
    /// The scans taken instead of the XV-11's revolutions, and the next beam to take.
    scans: Option<(Scans, u32)>,
    /// Whether the unit reports its strength in one byte (every model but the XV-11).
    byte_strength: bool,
    /// The unit.
    unit: LidarModel,
    /// `[effects.lidar_dropout]` and the stream its losses are drawn from (a stream of its
    /// own, so that every other draw, and so every reading it keeps, is the nominal lidar's).
    dropout: Option<(scenario::LidarDropout, rng::Rng)>,
}

/// Where the scans come from when the lidar is not the XV-11 as it is.
enum Scans {
    /// `[sensors.lidar] schedule`: a log's scans, and the one being taken.
    Log(Arc<ScanSchedule>, usize),
    /// `[sensors.lidar] model`: another unit's revolutions (boxed: a lidar holds one).
    Unit(Box<UnitScans>),
}

impl Scans {
    /// The scan being taken (`None`: a log's scans are all taken).
    fn current(&self) -> Option<&Scan> {
        match self {
            Scans::Log(schedule, k) => schedule.scans().get(*k),
            Scans::Unit(unit) => Some(unit.current()),
        }
    }

    fn advance(&mut self) {
        match self {
            Scans::Log(_, k) => *k += 1,
            Scans::Unit(unit) => unit.advance(),
        }
    }

    /// The rate of the revolution being taken, Hz.
    fn rev_hz(&self) -> f64 {
        match self {
            Scans::Log(..) => self
                .current()
                .map_or(0.0, |s| 1.0 / (f64::from(s.beams) * s.beam_period_s)),
            Scans::Unit(unit) => unit.current_hz(),
        }
    }
}

impl Lidar {
    /// The lidar of a scenario, drawing from the run's `lidar` stream.
    ///
    /// # Errors
    /// A range model that makes no sense.
    pub fn new(config: &scenario::Lidar, seed: u64) -> Result<Self, ModelError> {
        Self::with_effects(config, &scenario::Effects::default(), seed)
    }

    /// The lidar of a scenario with the scenario's `[effects]` that concern it (incidence angle,
    /// reflectivity, mixed pixels, motion skew, warm-up drift, range bias), drawing from the run's `lidar`
    /// stream. The effects draw no random numbers: with all of them off the readings are those
    /// of [`Lidar::new`], bit for bit.
    ///
    /// # Errors
    /// A range model that makes no sense.
    pub fn with_effects(
        config: &scenario::Lidar,
        effects: &scenario::Effects,
        seed: u64,
    ) -> Result<Self, ModelError> {
        let lidar_effects = LidarEffects::from_scenario(effects);
        let model = RangeModel::builder()
            .bias(lidar_effects.bias(&config.bias))
            .noise(&config.noise)
            .build()?;
        let mut motor = rng::stream(seed, "lidar.motor");
        let mut lidar = Self {
            model,
            // `[effects.lidar_mount_offset]`: the rays leave from where the unit really is;
            // `meta.toml` keeps the declared mount.
            mount: crate::effects::real_mount(config.mount.into(), effects.lidar_mount_offset),
            latency_s: effects.sensor_latency.map_or(0.0, |l| l.lidar_s),
            angle_noise_rad: config.angle_noise_deg.to_radians(),
            rpm: config.rpm,
            rpm_wobble: config.rpm_wobble,
            wobble_phase: motor.random::<f64>() * std::f64::consts::TAU,
            min_mm: config.min_range_m * 1000.0,
            max_mm: config.max_range_m * 1000.0,
            rng: rng::stream(seed, "lidar"),
            dropout: effects
                .lidar_dropout
                .map(|d| (d, rng::stream(seed, "lidar.dropout"))),
            rev: 0,
            index: 0,
            rev_start_s: 0.0,
            rev_rpm: 0.0,
            effects: lidar_effects,
            snapshot: config.timing == scenario::LidarTiming::PerRevolution
                && effects.lidar_motion_skew.is_none(),
            rev_pose: None,
            spin_up_rpm: Vec::new(),
            byte_strength: config.model != LidarModel::Xv11,
            unit: config.model,
            scans: (config.model != LidarModel::Xv11).then(|| {
                (
                    Scans::Unit(Box::new(UnitScans::new(
                        config.model,
                        config.rpm,
                        config.rpm_wobble,
                        seed,
                    ))),
                    0,
                )
            }),
        };
        lidar.rev_rpm = lidar.rpm_of_revolution(0);
        Ok(lidar)
    }

    /// The lidar taking a log's scans (`[sensors.lidar] schedule`, read with the scenario)
    /// instead of the XV-11's revolutions: a reading at every beam of every scan, at the
    /// scan's times and angles.
    #[must_use]
    pub fn with_schedule(mut self, schedule: Option<Arc<ScanSchedule>>) -> Self {
        if let Some(schedule) = schedule {
            self.scans = Some((Scans::Log(schedule, 0), 0));
        }
        self
    }

    /// Whether the lidar takes a log's scans rather than a unit's revolutions (it then has no
    /// wire format).
    #[must_use]
    pub fn is_scheduled(&self) -> bool {
        matches!(self.scans, Some((Scans::Log(..), _)))
    }

    /// Readings in every revolution: the XV-11's 360; `None` for a unit or a log's scans, whose
    /// revolutions vary in length (a revolution is whole when the next one starts).
    #[must_use]
    pub fn readings_per_revolution(&self) -> Option<usize> {
        self.scans.is_none().then_some(READINGS_PER_REVOLUTION)
    }

    /// Whether the readings taken so far end with a whole revolution: the next reading starts
    /// one.
    #[must_use]
    pub fn revolution_done(&self) -> bool {
        match &self.scans {
            Some((_, beam)) => *beam == 0,
            None => self.index == 0,
        }
    }

    /// The unit (`[sensors.lidar] model`).
    #[must_use]
    pub fn unit(&self) -> LidarModel {
        self.unit
    }

    /// The range model.
    #[must_use]
    pub fn model(&self) -> &RangeModel {
        &self.model
    }

    /// The mount pose.
    #[must_use]
    pub fn mount(&self) -> Mount {
        self.mount
    }

    /// The effects switched on.
    #[must_use]
    pub fn effects(&self) -> &LidarEffects {
        &self.effects
    }

    /// Whether every reading of a revolution is taken from the pose at the revolution's start
    /// (`timing = "per_revolution"` without motion skew).
    #[must_use]
    pub fn is_snapshot(&self) -> bool {
        self.snapshot
    }

    /// How far a beam is cast: past the maximum range, so that a far target is seen as "beyond
    /// range" rather than "nothing".
    #[must_use]
    pub fn cast_limit_m(&self) -> f64 {
        (self.max_mm / 1000.0 * 2.0).min(self.largest_mm() / 1000.0)
    }

    /// The largest distance a reading carries, millimetres: the XV-11's 14-bit field, or for a
    /// log's scans (never on the XV-11's wire) the reading's 16 bits.
    fn largest_mm(&self) -> f64 {
        if self.is_scheduled() {
            f64::from(u16::MAX)
        } else {
            f64::from(MAX_DISTANCE_MM)
        }
    }

    /// The motor speed during revolution `rev`, as the packets report it: quantised to the
    /// packet field's 1/64 rpm and held within what the field carries (1/64 to 1023.98 rpm), so
    /// a decoder that times readings from the field reproduces the emulator's timing exactly,
    /// and time always runs forward, however deep a wobble dips during a spin-up.
    #[must_use]
    pub fn rpm_of_revolution(&self, rev: u64) -> f64 {
        let phase = std::f64::consts::TAU * rev as f64 / WOBBLE_PERIOD_REVS + self.wobble_phase;
        let speed = usize::try_from(rev)
            .ok()
            .and_then(|r| self.spin_up_rpm.get(r))
            .copied()
            .unwrap_or(self.rpm);
        let rpm = speed + self.rpm_wobble * phase.sin();
        f64::from(rpm_to_fixed(rpm).max(1)) / 64.0
    }

    /// The unit's motor as the scenario's `[link]` table has it: a spin-up from
    /// [`scenario::SPIN_UP_FROM_RPM`] to the lidar's speed, linear in time over `spin_up_s`
    /// (each revolution at the speed of its start), and the rpm wobble when the table sets it.
    #[must_use]
    pub fn with_link(mut self, faults: &scenario::LinkFaults) -> Self {
        if let Some(wobble) = faults.rpm_wobble {
            self.rpm_wobble = wobble;
        }
        self.spin_up_rpm.clear();
        if faults.spin_up_s > 0.0 && self.rpm > scenario::SPIN_UP_FROM_RPM {
            let (from, to) = (scenario::SPIN_UP_FROM_RPM, self.rpm);
            let mut t = 0.0;
            while t < faults.spin_up_s {
                let rpm = from + (to - from) * t / faults.spin_up_s;
                self.spin_up_rpm.push(rpm);
                t += 60.0 / rpm;
            }
        }
        self.rev_rpm = self.rpm_of_revolution(self.rev);
        if let Some((Scans::Unit(unit), _)) = &mut self.scans {
            **unit = unit
                .as_ref()
                .clone()
                .with_link(faults.spin_up_s, self.rpm_wobble);
        }
        self
    }

    /// Takes every reading whose instant falls in `[step.t0, step.t1)`.
    pub fn observe(&mut self, world: &World, step: &StepState, out: &mut Vec<LidarReading>) {
        let track = SensorTrack::new(step, self.mount);
        if self.scans.is_some() {
            self.observe_scans(world, step, &track, out);
            return;
        }
        loop {
            let t = reading_time_s(self.rev_start_s, self.index, self.rev_rpm);
            if t >= step.t1 {
                return;
            }
            if t >= step.t0 {
                let (origin, yaw) = if self.snapshot {
                    // The whole revolution from the pose at its start.
                    if self.index == 0 || self.rev_pose.is_none() {
                        self.rev_pose = Some(track.at(t));
                    }
                    self.rev_pose.unwrap_or_else(|| track.at(t))
                } else {
                    track.at(t)
                };
                let angle_deg = f64::from(self.index);
                out.push(self.read(world, origin, yaw, t, angle_deg));
            }
            self.index += 1;
            if usize::from(self.index) == READINGS_PER_REVOLUTION {
                self.index = 0;
                self.rev_start_s = next_revolution_start_s(self.rev_start_s, self.rev_rpm);
                self.rev += 1;
                self.rev_rpm = self.rpm_of_revolution(self.rev);
            }
        }
    }

    /// The scans' beams whose instant falls in `[step.t0, step.t1)`, each from the lidar's pose
    /// at its own instant (or, as a snapshot, at its scan's start).
    fn observe_scans(
        &mut self,
        world: &World,
        step: &StepState,
        track: &SensorTrack,
        out: &mut Vec<LidarReading>,
    ) {
        let Some((mut scans, mut beam)) = self.scans.take() else {
            return;
        };
        while let Some(scan) = scans.current() {
            let t = scan.beam_time_s(beam);
            if t >= step.t1 {
                break;
            }
            let (beams, rev, angle_deg) = (scan.beams, scan.rev, scan.beam_deg(beam));
            if t >= step.t0 {
                // A log's scans are replayed as they were taken, reading by reading.
                let snapshot = self.snapshot && matches!(scans, Scans::Unit(_));
                let (origin, yaw) = if snapshot {
                    if beam == 0 || self.rev_pose.is_none() {
                        self.rev_pose = Some(track.at(t));
                    }
                    self.rev_pose.unwrap_or_else(|| track.at(t))
                } else {
                    track.at(t)
                };
                self.rev = rev;
                self.index = u16::try_from(beam).unwrap_or(u16::MAX);
                self.rev_rpm = scans.rev_hz() * 60.0;
                out.push(self.read(world, origin, yaw, t, angle_deg));
            }
            beam += 1;
            if beam >= beams {
                beam = 0;
                scans.advance();
            }
        }
        self.scans = Some((scans, beam));
    }

    /// One reading at the current (rev, index) at `angle_deg` in the lidar's frame, from the
    /// lidar at `origin` with its 0° axis along `yaw` (world frame, radians, not necessarily
    /// wrapped).
    fn read(
        &mut self,
        world: &World,
        origin: [f64; 2],
        yaw: f64,
        t: f64,
        angle_deg: f64,
    ) -> LidarReading {
        let angle_noise: f64 = StandardNormal.sample(&mut self.rng);
        let beam = yaw + angle_deg.to_radians() + self.angle_noise_rad * angle_noise;
        let cast_limit = self.cast_limit_m();
        let mut reading = LidarReading {
            t_s: t + self.latency_s,
            rev: self.rev,
            index: self.index,
            angle_deg,
            distance_mm: 0,
            error_code: Some(ERROR_NO_RETURN),
            strength: 0,
            warning: false,
            true_range_m: None,
            rev_hz: self.rev_rpm / 60.0,
        };
        let Some(ret) = self.effects.beam_return(world, origin, beam, cast_limit) else {
            return reading;
        };
        let hit = ret.hit;
        let d = hit.distance;
        reading.true_range_m = Some(d);
        // The range model sees the distance the unit ranges: the true one unless an effect is on.
        let ranged = self.effects.ranged_m(&ret, t);
        let measured_mm = (self.model.sample(ranged, &mut self.rng) * 1000.0).round();
        let speckle: f64 = StandardNormal.sample(&mut self.rng);
        let strength = expected_strength(d, ret.cos_incidence, hit.reflectivity)
            * (1.0 + STRENGTH_SPREAD * speckle).max(0.0);
        let strength = strength.round().min(f64::from(u16::MAX)) as u16;
        let error = if strength < STRENGTH_INVALID_BELOW {
            Some(ERROR_WEAK_SIGNAL)
        } else if measured_mm < self.min_mm {
            Some(ERROR_TOO_CLOSE)
        } else if measured_mm > self.max_mm {
            Some(ERROR_NO_RETURN)
        } else if self.drops(&ret) {
            Some(ERROR_WEAK_SIGNAL)
        } else {
            None
        };
        reading.error_code = error;
        if error.is_none() {
            reading.distance_mm = measured_mm.min(self.largest_mm()) as u16;
            // A unit other than the XV-11 reports its strength in one byte.
            reading.strength = if self.byte_strength {
                strength.min(u16::from(u8::MAX))
            } else {
                strength
            };
            reading.warning = strength < STRENGTH_WARNING_BELOW;
        }
        reading
    }
}

impl Lidar {
    /// Whether `[effects.lidar_dropout]` loses the return `ret` (never when it is off: no
    /// number is drawn then).
    fn drops(&mut self, ret: &BeamReturn) -> bool {
        let Some((dropout, rng)) = self.dropout.as_mut() else {
            return false;
        };
        let lost = dropout_probability(
            dropout,
            ret.hit.distance,
            ret.cos_incidence,
            ret.hit.reflectivity,
        );
        rng.random::<f64>() < lost
    }
}

/// The strength the unit reports on average for a surface of `reflectivity` at `range_m`, met
/// at `|cos θ|` = `cos_incidence`: a diffuse return, proportional to the reflectivity and to the
/// cosine of the incidence, falling with the range as the real capture's (before speckle).
#[must_use]
pub fn expected_strength(range_m: f64, cos_incidence: f64, reflectivity: f64) -> f64 {
    STRENGTH_AT_1M
        * (reflectivity / REFERENCE_REFLECTIVITY)
        * cos_incidence
        * range_m.max(0.05).powf(-STRENGTH_FALLOFF)
}

/// The lidar's pose through one physics step: the robot's pose interpolated as
/// [`StepState::pose_at`] does, composed with the mount.
///
/// The heading is left unwrapped: a beam direction needs no wrapping, and `pose_at` followed by
/// `Mount::in_world` wrapped it three times per reading (each a floating-point remainder, about a
/// tenth of the lidar's time in a sparse world). The step's heading change is wrapped once here.
struct SensorTrack {
    t0: f64,
    t1: f64,
    from: [f64; 3],
    delta: [f64; 3],
    mount: Mount,
    /// The mount's yaw in radians, converted once per step rather than per reading.
    mount_yaw_rad: f64,
}

impl SensorTrack {
    fn new(step: &StepState, mount: Mount) -> Self {
        let (p0, p1) = (step.pose0, step.pose1);
        Self {
            t0: step.t0,
            t1: step.t1,
            from: [p0.x, p0.y, p0.yaw],
            delta: [p1.x - p0.x, p1.y - p0.y, wrap_angle(p1.yaw - p0.yaw)],
            mount,
            mount_yaw_rad: mount.yaw_rad(),
        }
    }

    /// The lidar's origin and the direction of its 0° axis at `t` (clamped to the step).
    fn at(&self, t: f64) -> ([f64; 2], f64) {
        let u = ((t - self.t0) / (self.t1 - self.t0)).clamp(0.0, 1.0);
        let [x, y, yaw] = [0, 1, 2].map(|i| self.from[i] + self.delta[i] * u);
        let m = &self.mount;
        let origin = if m.x_m == 0.0 && m.y_m == 0.0 {
            [x, y]
        } else {
            let (sin, cos) = yaw.sin_cos();
            [x + cos * m.x_m - sin * m.y_m, y + sin * m.x_m + cos * m.y_m]
        };
        (origin, yaw + self.mount_yaw_rad)
    }
}

/// Seconds between two readings at `rpm`.
#[must_use]
pub fn reading_period_s(rpm: f64) -> f64 {
    60.0 / (rpm * READINGS_PER_REVOLUTION as f64)
}

/// When reading `index` of a revolution that started at `rev_start_s` and turns at `rpm` is
/// taken. The emulator and every decoder of its stream compute times with this one function, so
/// timestamps rebuilt from the wire equal the emulator's bit for bit.
#[must_use]
pub fn reading_time_s(rev_start_s: f64, index: u16, rpm: f64) -> f64 {
    rev_start_s + f64::from(index) * reading_period_s(rpm)
}

/// When the revolution after one that started at `rev_start_s` at `rpm` starts.
#[must_use]
pub fn next_revolution_start_s(rev_start_s: f64, rpm: f64) -> f64 {
    rev_start_s + READINGS_PER_REVOLUTION as f64 * reading_period_s(rpm)
}
