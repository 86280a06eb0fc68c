//! The simulation: a fixed-step physics clock, the differential drive, ground truth at every step
//! and the log of collisions. Nothing here reads the wall clock: a run is a pure function of the
//! scenario (and the seed, for the sensors that draw noise).

use hilsim_recording::{CommandSample, TruthSample};
use rapier2d::prelude::*;

use crate::actuation::ActuationError;
use crate::drive::{DriveProgram, WheelCommand};
use crate::motor_lag::MotorLag;
use crate::scenario::Scenario;
use crate::world::{Obstacle, World};
use hilsim_recording::pose::Pose;

/// The robot touched an obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collision {
    /// When the contact started, seconds.
    pub t_s: f64,
    /// What the robot touched.
    pub obstacle: Obstacle,
    /// The robot's pose then.
    pub pose: Pose,
}

impl std::fmt::Display for Collision {
    /// `collision at t = 1.25 s with Wall(2)`, as run summaries print it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "collision at t = {:.2} s with {:?}",
            self.t_s, self.obstacle
        )
    }
}

/// What happened during one physics step, for the sensors to sample from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepState {
    /// Index of the step, from 0.
    pub index: u64,
    /// Time at the start of the step, seconds.
    pub t0: f64,
    /// Time at the end of the step, seconds.
    pub t1: f64,
    /// The robot's pose at `t0`.
    pub pose0: Pose,
    /// The robot's pose at `t1`.
    pub pose1: Pose,
    /// The command in force during the step.
    pub command: WheelCommand,
    /// True cumulative wheel travel (left, right) at `t0`, metres.
    pub wheels0: [f64; 2],
    /// True cumulative wheel travel (left, right) at `t1`, metres.
    pub wheels1: [f64; 2],
}

impl StepState {
    /// The robot's pose at time `t` within the step (clamped to it).
    #[must_use]
    pub fn pose_at(&self, t: f64) -> Pose {
        self.pose0.lerp(&self.pose1, self.fraction(t))
    }

    /// True cumulative wheel travel at time `t` within the step.
    #[must_use]
    pub fn wheels_at(&self, t: f64) -> [f64; 2] {
        let u = self.fraction(t);
        [
            self.wheels0[0] + (self.wheels1[0] - self.wheels0[0]) * u,
            self.wheels0[1] + (self.wheels1[1] - self.wheels0[1]) * u,
        ]
    }

    fn fraction(&self, t: f64) -> f64 {
        ((t - self.t0) / (self.t1 - self.t0)).clamp(0.0, 1.0)
    }
}

/// Where the wheel commands come from.
enum Driver {
    /// The scenario's drive program.
    Program(DriveProgram),
    /// Set from outside (firmware in the loop) with [`Simulation::set_command`].
    External(WheelCommand),
    /// A recorded path (`[robot] path`): the robot is put where the path says at every step,
    /// and the wheel commands are what would have moved it there.
    Path(std::sync::Arc<crate::recorded_path::RecordedPath>),
}

/// A running simulation of one scenario.
pub struct Simulation {
    world: World,
    driver: Driver,
    step_s: f64,
    /// The effective wheel base (the nominal one unless `[effects.drive_wheel_base]`).
    wheel_base_m: f64,
    /// `[effects.odometer_wheel_radius]`: each wheel's radius over nominal (1 when off).
    wheel_radius_scale: [f64; 2],
    steps_done: u64,
    end_step: Option<u64>,
    pose: Pose,
    wheels: [f64; 2],
    commands: Vec<CommandSample>,
    /// The command last logged: a row is logged only when the command changes, also after
    /// [`Simulation::drain_logs`] has handed the rows over.
    last_command: Option<WheelCommand>,
    truth: Vec<TruthSample>,
    collisions: Vec<Collision>,
    touching: Vec<ColliderHandle>,
    actuation: ActuationError,
    /// `[effects.drive_motor_lag]`, when switched on.
    lag: Option<MotorLag>,
}

impl Simulation {
    /// A simulation that runs the scenario's drive program until `duration_s` or the program's
    /// end. The actuation error (if the scenario has one) draws from `scenario.seed`.
    #[must_use]
    pub fn new(scenario: &Scenario) -> Self {
        let driver = match &scenario.files.path {
            Some(path) => Driver::Path(path.clone()),
            None => Driver::Program(DriveProgram::new(scenario)),
        };
        let mut sim = Self::build(scenario, driver);
        sim.end_step = Some(scenario.run_steps());
        sim
    }

    /// A simulation whose wheels are commanded from outside ([`Simulation::set_command`]), with
    /// no end of its own.
    #[must_use]
    pub fn externally_driven(scenario: &Scenario) -> Self {
        Self::build(scenario, Driver::External(WheelCommand::default()))
    }

    fn build(scenario: &Scenario, driver: Driver) -> Self {
        let mut world = World::new(scenario);
        if let Driver::Path(path) = &driver {
            world.place_robot(path.pose_at(0.0));
        }
        let pose = match &driver {
            // The path's own pose, not its f32 copy in the physics.
            Driver::Path(path) => path.pose_at(0.0),
            _ => world.robot_pose(),
        };
        Self {
            world,
            driver,
            step_s: scenario.step_s(),
            // `[effects.drive_wheel_base]`: the wheels push the body `scale` times the nominal
            // base apart, so the true body turn and the wheels' true travel both follow it.
            wheel_base_m: scenario.robot.wheel_base_m
                * scenario.effects.drive_wheel_base.map_or(1.0, |b| b.scale),
            wheel_radius_scale: scenario
                .effects
                .odometer_wheel_radius
                .map_or([1.0, 1.0], |r| [r.left_scale, r.right_scale]),
            steps_done: 0,
            end_step: None,
            pose,
            wheels: [0.0; 2],
            commands: Vec::new(),
            last_command: None,
            truth: vec![truth(0.0, pose)],
            collisions: Vec::new(),
            touching: Vec::new(),
            actuation: ActuationError::new(&scenario.robot.actuation, scenario.seed),
            lag: scenario
                .effects
                .drive_motor_lag
                .map(|lag| match lag.damping {
                    Some(damping) => MotorLag::second_order(lag.time_constant_s, damping),
                    None => MotorLag::new(lag.time_constant_s),
                }),
        }
    }

    /// Sets the wheel command of an externally driven simulation; ignored when the drive
    /// program drives.
    pub fn set_command(&mut self, command: WheelCommand) {
        if let Driver::External(current) = &mut self.driver {
            *current = command;
        }
    }

    /// The simulated time now, seconds.
    #[must_use]
    pub fn time_s(&self) -> f64 {
        exact_time_s(self.steps_done as f64 * self.step_s)
    }

    /// The physics step, seconds.
    #[must_use]
    pub fn step_s(&self) -> f64 {
        self.step_s
    }

    /// Whether the run has reached its end.
    #[must_use]
    pub fn finished(&self) -> bool {
        self.end_step.is_some_and(|end| self.steps_done >= end)
    }

    /// The world, for sensors to cast rays in.
    #[must_use]
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The robot's pose now.
    #[must_use]
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// Advances one physics step; `None` once the run has ended.
    pub fn step(&mut self) -> Option<StepState> {
        if self.finished() {
            return None;
        }
        let index = self.steps_done;
        let t0 = self.time_s();
        let placed = match &self.driver {
            Driver::Path(path) => {
                Some(path.pose_at(exact_time_s((index + 1) as f64 * self.step_s)))
            }
            _ => None,
        };
        let command = match (&self.driver, placed) {
            (Driver::Program(program), _) => program.command_at(index),
            (Driver::External(command), _) => *command,
            (Driver::Path(_), Some(to)) => {
                let [left, right] =
                    crate::kinematics::wheel_travel([0.0; 2], &self.pose, &to, self.wheel_base_m);
                WheelCommand {
                    left_mps: left / self.step_s,
                    right_mps: right / self.step_s,
                }
            }
            (Driver::Path(_), None) => WheelCommand::default(),
        };
        if self
            .last_command
            .is_none_or(|c| c.left_mps != command.left_mps || c.right_mps != command.right_mps)
        {
            self.last_command = Some(command);
            self.commands.push(CommandSample {
                t_s: t0,
                left_mps: command.left_mps,
                right_mps: command.right_mps,
            });
        }
        match placed {
            Some(to) => self.world.place_robot(to),
            None => self.apply(command),
        }
        self.world.physics.step();
        self.steps_done += 1;
        let t1 = self.time_s();
        let pose0 = self.pose;
        let pose1 = placed.unwrap_or_else(|| self.world.robot_pose());
        let wheels0 = self.wheels;
        self.wheels = self.wheel_travel(pose0, pose1);
        self.pose = pose1;
        self.truth.push(truth(t1, pose1));
        self.log_contacts(t1);
        Some(StepState {
            index,
            t0,
            t1,
            pose0,
            pose1,
            command,
            wheels0,
            wheels1: self.wheels,
        })
    }

    /// Differential drive: wheel speeds → body twist, held by setting the body's velocity each
    /// step; the physics then resolves contacts (a wall stops the robot).
    fn apply(&mut self, command: WheelCommand) {
        // A wheel turned at the commanded speed over its nominal radius moves the ground by its
        // real radius: `[effects.odometer_wheel_radius]` (scales of 1 when off).
        let [left_scale, right_scale] = self.wheel_radius_scale;
        let command = WheelCommand {
            left_mps: command.left_mps * left_scale,
            right_mps: command.right_mps * right_scale,
        };
        // The wheels achieve the command scaled by the actuation error (1 when it is off) …
        let factor = self.actuation.next_factor(self.step_s);
        let (v, omega) = match &mut self.lag {
            None => (
                factor * (command.left_mps + command.right_mps) / 2.0,
                factor * (command.right_mps - command.left_mps) / self.wheel_base_m,
            ),
            // … through a first-order lag when the scenario switches motor lag on.
            Some(lag) => {
                let target = WheelCommand {
                    left_mps: factor * command.left_mps,
                    right_mps: factor * command.right_mps,
                };
                let w = lag.step(target, self.step_s);
                (
                    (w.left_mps + w.right_mps) / 2.0,
                    (w.right_mps - w.left_mps) / self.wheel_base_m,
                )
            }
        };
        let (sin, cos) = self.pose.yaw.sin_cos();
        let body = &mut self.world.physics.bodies[self.world.robot];
        body.set_linvel(Vector::new((v * cos) as f32, (v * sin) as f32), true);
        body.set_angvel(omega as f32, true);
    }

    /// The wheels' true cumulative travel after moving from `p0` to `p1`: the body's forward
    /// displacement and turn, split onto the wheels. A robot pushed against a wall stalls its
    /// wheels: they report what the body did, not what was commanded.
    fn wheel_travel(&self, p0: Pose, p1: Pose) -> [f64; 2] {
        crate::kinematics::wheel_travel(self.wheels, &p0, &p1, self.wheel_base_m)
    }

    fn log_contacts(&mut self, t: f64) {
        let robot = self.world.robot_collider();
        let now: Vec<ColliderHandle> = self
            .world
            .physics
            .contact_pairs_with(robot)
            .filter(|pair| pair.has_any_active_contact())
            .map(|pair| {
                if pair.collider1 == robot {
                    pair.collider2
                } else {
                    pair.collider1
                }
            })
            .collect();
        for handle in &now {
            if !self.touching.contains(handle) {
                if let Some(obstacle) = self.world.obstacle(*handle) {
                    self.collisions.push(Collision {
                        t_s: t,
                        obstacle,
                        pose: self.pose,
                    });
                }
            }
        }
        self.touching = now;
    }

    /// Whether the robot touches an obstacle at the end of the last step.
    #[must_use]
    pub fn in_contact(&self) -> bool {
        !self.touching.is_empty()
    }

    /// Commands as issued so far, one row per change.
    #[must_use]
    pub fn commands(&self) -> &[CommandSample] {
        &self.commands
    }

    /// The true pose at every step so far, from t = 0.
    #[must_use]
    pub fn truth(&self) -> &[TruthSample] {
        &self.truth
    }

    /// Contacts the robot started with obstacles.
    #[must_use]
    pub fn collisions(&self) -> &[Collision] {
        &self.collisions
    }

    /// Hands over the command and truth rows logged since the last call (or the start), so that
    /// a caller writing them out as the run goes keeps memory flat in the run's length.
    /// The logs keep their capacity, so a run drained every step allocates nothing for them.
    pub fn drain_logs(
        &mut self,
    ) -> (
        std::vec::Drain<'_, CommandSample>,
        std::vec::Drain<'_, TruthSample>,
    ) {
        (self.commands.drain(..), self.truth.drain(..))
    }

    /// Hands over the logs, leaving the simulation's empty.
    pub fn take_logs(&mut self) -> (Vec<CommandSample>, Vec<TruthSample>, Vec<Collision>) {
        (
            std::mem::take(&mut self.commands),
            std::mem::take(&mut self.truth),
            std::mem::take(&mut self.collisions),
        )
    }
}

/// A time as a recording writes it: to the microsecond, so that it reads as the exact decimal
/// it is (`0.15`, not `0.15000000000000002`: the integer count of microseconds over a million is
/// the double nearest that decimal). A microsecond is far below any sensor's timing (the XV-11
/// takes a reading every 556 µs).
#[must_use]
pub fn exact_time_s(t: f64) -> f64 {
    (t * 1e6).round() / 1e6
}

fn truth(t_s: f64, pose: Pose) -> TruthSample {
    TruthSample {
        t_s,
        x_m: pose.x,
        y_m: pose.y,
        yaw_rad: pose.yaw,
    }
}
