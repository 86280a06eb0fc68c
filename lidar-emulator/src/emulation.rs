//! In-process delivery: a simulation with its sensors attached, yielding the samples of each
//! physics step as they are taken. `hilsim record` writes exactly these samples.

use hilsim_recording::{
    CommandSample, LidarSample, Meta, OdometrySample, Recording, RobotMeta, SampleSink, SonarMount,
    SonarSample, SourceMeta, Tables, TruthSample, WorldMeta,
};
use hilsim_sim::{Collision, Scenario, Simulation, StepState};

use crate::lidar::{Lidar, LidarReading};
use crate::neato_packet::READINGS_PER_REVOLUTION;
use crate::odometer::Odometer;
use crate::range_model::ModelError;
use crate::sonar::Sonar;

/// The samples taken during one physics step.
#[derive(Debug, Clone, Default)]
pub struct StepSamples {
    /// The step (times, poses, command).
    pub step: Option<StepState>,
    /// Lidar readings, in time order.
    pub lidar: Vec<LidarReading>,
    /// Sonar pings.
    pub sonar: Vec<SonarSample>,
    /// Odometer readings.
    pub odometry: Vec<OdometrySample>,
}

/// A running emulation: the world, the robot and its sensors.
///
/// ```
/// use hilsim_lidar_emulator::Emulation;
/// use hilsim_sim::Scenario;
/// let scenario = Scenario::from_toml(
///     r#"
///     name = "spin"
///     duration_s = 0.5
///     [world]
///     walls = [{ from = [2.0, -2.0], to = [2.0, 2.0] }]
///     [robot]
///     start = { x = 0.0, y = 0.0 }
///     wheel_base_m = 0.23
///     [sensors.lidar]
///     "#,
///     "inline.toml".as_ref(),
/// )?;
/// let mut emulation = Emulation::new(&scenario, scenario.seed)?;
/// let mut readings = 0;
/// while let Some(samples) = emulation.step() {
///     readings += samples.lidar.len();
/// }
/// assert_eq!(readings, 900); // 0.5 s at 1,800 readings/s
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Emulation {
    scenario_name: String,
    seed: u64,
    sim: Simulation,
    lidar: Option<Lidar>,
    sonar: Option<Sonar>,
    odometer: Option<Odometer>,
    samples: StepSamples,
    meta: Meta,
}

impl Emulation {
    /// The scenario's world and sensors, with every random stream derived from `seed`.
    ///
    /// # Errors
    /// A sensor's range model makes no sense.
    pub fn new(scenario: &Scenario, seed: u64) -> Result<Self, ModelError> {
        Self::with_simulation(scenario, seed, Simulation::new(scenario))
    }

    /// As [`Emulation::new`], around a simulation built by the caller (e.g. one driven from
    /// outside by firmware in the loop).
    ///
    /// # Errors
    /// A sensor's range model makes no sense.
    pub fn with_simulation(
        scenario: &Scenario,
        seed: u64,
        sim: Simulation,
    ) -> Result<Self, ModelError> {
        let s = &scenario.sensors;
        // The scenario's `[effects]` (all off by default) reach every sensor; motor lag is the
        // simulation's.
        let e = &scenario.effects;
        let lidar = s
            .lidar
            .as_ref()
            .map(|c| {
                Lidar::with_effects(c, e, seed)
                    .map(|l| l.with_schedule(scenario.files.schedule.clone()))
            })
            .transpose()?
            // Validation has checked the table: its faults resolve.
            .map(|l| l.with_link(&scenario.link.faults().unwrap_or_default()));
        let sonar = s
            .sonar
            .as_ref()
            .map(|c| Sonar::with_effects(c, e, seed))
            .transpose()?;
        let odometer = s
            .odometer
            .as_ref()
            .map(|c| Odometer::with_effects(c, e, seed));
        let meta = meta(scenario, seed, &sim, lidar.as_ref());
        Ok(Self {
            scenario_name: scenario.name.clone(),
            seed,
            sim,
            lidar,
            sonar,
            odometer,
            samples: StepSamples::default(),
            meta,
        })
    }

    /// Advances one physics step and returns the samples taken during it; `None` at the end.
    pub fn step(&mut self) -> Option<&StepSamples> {
        self.advance().then_some(&self.samples)
    }

    /// Advances one physics step, leaving its samples in `self.samples`; `false` at the end.
    fn advance(&mut self) -> bool {
        let Some(step) = self.sim.step() else {
            return false;
        };
        let s = &mut self.samples;
        s.step = Some(step);
        s.lidar.clear();
        s.sonar.clear();
        s.odometry.clear();
        let world = self.sim.world();
        if let Some(lidar) = &mut self.lidar {
            lidar.observe(world, &step, &mut s.lidar);
        }
        if let Some(sonar) = &mut self.sonar {
            sonar.observe(world, &step, &mut s.sonar);
        }
        if let Some(odometer) = &mut self.odometer {
            odometer.observe(&step, &mut s.odometry);
        }
        true
    }

    /// The simulation (pose, time, collisions, wheel commands).
    #[must_use]
    pub fn simulation(&self) -> &Simulation {
        &self.sim
    }

    /// The simulation, mutably (to set wheel commands from outside).
    pub fn simulation_mut(&mut self) -> &mut Simulation {
        &mut self.sim
    }

    /// The lidar, when the robot has one.
    #[must_use]
    pub fn lidar(&self) -> Option<&Lidar> {
        self.lidar.as_ref()
    }

    /// The recording's metadata.
    #[must_use]
    pub fn meta(&self) -> &Meta {
        &self.meta
    }

    /// The scenario's name and the run's seed.
    #[must_use]
    pub fn source(&self) -> (&str, u64) {
        (&self.scenario_name, self.seed)
    }

    /// Runs to the end, collecting every sample into a recording (truth included). The lidar
    /// table holds whole revolutions only, as a real unit delivers them.
    #[must_use]
    pub fn run(self) -> Run {
        self.run_with(|_, _| {})
    }

    /// As [`Emulation::run`], also handing each lidar reading and the motor speed of its
    /// revolution to `on_lidar` as it is taken (e.g. to stream it over a serial link).
    pub fn run_with(self, on_lidar: impl FnMut(&LidarReading, f64)) -> Run {
        let mut recording = Recording {
            meta: self.meta.clone(),
            commands: Vec::new(),
            odometry: self.odometer.as_ref().map(|_| Vec::new()),
            lidar: self.lidar.as_ref().map(|_| Vec::new()),
            sonar: self.sonar.as_ref().map(|_| Vec::new()),
            truth: Some(Vec::new()),
        };
        // A recording in memory takes every sample.
        let Ok(collisions) = self.drive_into(&mut recording, on_lidar);
        Run {
            recording,
            collisions,
        }
    }

    /// The tables a recording of this emulation has (`commands.csv` always).
    #[must_use]
    pub fn tables(&self) -> Tables {
        Tables {
            odometry: self.odometer.is_some(),
            lidar: self.lidar.is_some(),
            sonar: self.sonar.is_some(),
            truth: true,
        }
    }

    /// Runs to the end, handing every sample to `sink` as it is taken, as [`Emulation::run`]
    /// collects them: what `hilsim record` writes, in memory flat in the run's length (a
    /// [`hilsim_recording::RecordingStream`]). Returns the collisions.
    ///
    /// # Errors
    /// The sink's, which stops the run.
    pub fn record_into<S: SampleSink>(self, sink: &mut S) -> Result<Vec<Collision>, S::Error> {
        self.drive_into(sink, |_, _| {})
    }

    /// The run's loop: each step's samples to `sink`, each lidar reading also to `on_lidar`.
    /// A real unit only ever delivers whole revolutions: readings reach `sink` a revolution at a
    /// time, and the one the run ends inside is not part of the recording (so the in-process
    /// and serial paths carry the same data).
    fn drive_into<S: SampleSink>(
        mut self,
        sink: &mut S,
        mut on_lidar: impl FnMut(&LidarReading, f64),
    ) -> Result<Vec<Collision>, S::Error> {
        let mut revolution: Vec<LidarSample> = Vec::with_capacity(READINGS_PER_REVOLUTION);
        while self.advance() {
            let s = &self.samples;
            if let Some(sensor) = &self.lidar {
                let whole = sensor.readings_per_revolution();
                for reading in &s.lidar {
                    on_lidar(reading, sensor.rpm_of_revolution(reading.rev));
                    // A unit's revolution or a log's scan is whole when the next one starts
                    // (their readings vary in number).
                    if whole.is_none() && revolution.first().is_some_and(|r| r.rev != reading.rev) {
                        for r in revolution.drain(..) {
                            sink.lidar(&r)?;
                        }
                    }
                    revolution.push(reading.to_sample());
                    if whole == Some(revolution.len()) {
                        for r in revolution.drain(..) {
                            sink.lidar(&r)?;
                        }
                    }
                }
            }
            for p in &s.sonar {
                sink.sonar(p)?;
            }
            for o in &s.odometry {
                sink.odometry(o)?;
            }
            let (commands, truth) = self.sim.drain_logs();
            log_into(sink, commands, truth)?;
        }
        // A log's last scan ends before the run does (its duration covers the schedule); a
        // unit's last revolution counts when the run ended just as it was done.
        if self
            .lidar
            .as_ref()
            .is_some_and(|l| l.is_scheduled() || l.revolution_done())
        {
            for r in revolution.drain(..) {
                sink.lidar(&r)?;
            }
        }
        let (commands, truth, collisions) = self.sim.take_logs();
        log_into(sink, commands, truth)?;
        Ok(collisions)
    }
}

/// The simulation's command and truth rows, to `sink`.
fn log_into<S: SampleSink>(
    sink: &mut S,
    commands: impl IntoIterator<Item = CommandSample>,
    truth: impl IntoIterator<Item = TruthSample>,
) -> Result<(), S::Error> {
    for c in commands {
        sink.command(&c)?;
    }
    for t in truth {
        sink.truth(&t)?;
    }
    Ok(())
}

/// A finished run.
#[derive(Debug, Clone)]
pub struct Run {
    /// Everything the sensors reported, with the truth.
    pub recording: Recording,
    /// Contacts the robot started with obstacles.
    pub collisions: Vec<Collision>,
}

fn meta(scenario: &Scenario, seed: u64, sim: &Simulation, lidar: Option<&Lidar>) -> Meta {
    let s = &scenario.sensors;
    let radii: Vec<f64> = scenario.world.cylinders.iter().map(|c| c.radius).collect();
    let landmark_radius_m = radii
        .first()
        .copied()
        .filter(|r| radii.iter().all(|x| x == r));
    // What the lidar's forward beam sees at t = 0: the EM calibrator's known start distance.
    let target_start_distance_m = lidar.and_then(|l| {
        let p = l.mount().in_world(&sim.pose());
        sim.world()
            .cast_ray([p.x, p.y], p.yaw, 16.0)
            .map(|hit| hit.distance)
    });
    Meta {
        format: hilsim_recording::FORMAT.to_string(),
        robot: RobotMeta {
            wheel_base_m: scenario.robot.wheel_base_m,
            wheel_radius_m: Some(scenario.robot.wheel_radius_m),
        },
        lidar: s.lidar.as_ref().map(|l| l.mount.into()),
        sonar: s.sonar.as_ref().map(|u| SonarMount {
            x_m: u.mount.x_m,
            y_m: u.mount.y_m,
            yaw_deg: u.mount.yaw_deg,
            half_angle_deg: u.half_angle_deg,
        }),
        world: WorldMeta {
            landmark_radius_m,
            target_start_distance_m,
        },
        source: Some(SourceMeta {
            generator: format!("hilsim {}", env!("CARGO_PKG_VERSION")),
            scenario: Some(scenario.name.clone()),
            seed: Some(seed),
        }),
    }
}
