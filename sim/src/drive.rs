//! The drive program as wheel speed commands on the physics step grid.

use crate::scenario::Scenario;

/// Wheel speed command, m/s, positive forward.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WheelCommand {
    /// Left wheel speed.
    pub left_mps: f64,
    /// Right wheel speed.
    pub right_mps: f64,
}

/// One drive step turned into a constant command over a whole number of physics steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// First physics step of the segment.
    pub start_step: u64,
    /// Number of physics steps.
    pub steps: u64,
    /// The command held throughout.
    pub command: WheelCommand,
}

/// The scenario's drive program, ready to be sampled at each physics step.
#[derive(Debug, Clone, PartialEq)]
pub struct DriveProgram {
    segments: Vec<Segment>,
}

impl DriveProgram {
    /// Converts the drive steps into segments. Each step's duration is rounded to whole physics
    /// steps and the speed adjusted so that the commanded distance or angle is exact (the robot
    /// does what the program says; the rounding shows only in the command's last digits).
    #[must_use]
    pub fn new(scenario: &Scenario) -> Self {
        let dt = scenario.step_s();
        let half_base = scenario.robot.wheel_base_m / 2.0;
        let mut segments = Vec::with_capacity(scenario.drive.len());
        let mut start_step = 0;
        for step in &scenario.drive {
            // Validation guarantees one kind per step.
            let Some(duration_s) = step.duration_s(scenario.robot.turn_rate_deg_s) else {
                continue;
            };
            let steps = (duration_s / dt).round() as u64;
            let steps = if duration_s > 0.0 { steps.max(1) } else { 0 };
            if steps == 0 {
                continue;
            }
            let held_s = steps as f64 * dt;
            let command = match (step.speed_mps, step.distance_m, step.turn_deg) {
                (Some(v), Some(d), _) => {
                    let v = v.signum() * d / held_s;
                    WheelCommand {
                        left_mps: v,
                        right_mps: v,
                    }
                }
                (_, _, Some(deg)) => {
                    let omega = deg.to_radians() / held_s;
                    WheelCommand {
                        left_mps: -omega * half_base,
                        right_mps: omega * half_base,
                    }
                }
                _ => WheelCommand::default(),
            };
            segments.push(Segment {
                start_step,
                steps,
                command,
            });
            start_step += steps;
        }
        Self { segments }
    }

    /// The segments in order.
    #[must_use]
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// Physics steps until the program ends.
    #[must_use]
    pub fn total_steps(&self) -> u64 {
        self.segments.last().map_or(0, |s| s.start_step + s.steps)
    }

    /// The command in force during physics step `step`; zero after the program ends.
    #[must_use]
    pub fn command_at(&self, step: u64) -> WheelCommand {
        let i = self
            .segments
            .partition_point(|s| s.start_step + s.steps <= step);
        self.segments
            .get(i)
            .filter(|s| s.start_step <= step)
            .map_or_else(WheelCommand::default, |s| s.command)
    }
}

/// The run's length, which the drive program sets when the scenario gives no `duration_s`.
impl Scenario {
    /// The number of physics steps the drive program takes (each drive step rounded to whole
    /// physics steps).
    #[must_use]
    pub fn drive_steps(&self) -> u64 {
        DriveProgram::new(self).total_steps()
    }

    /// The run's length in physics steps: `duration_s` when set, else the drive program's end.
    #[must_use]
    pub fn run_steps(&self) -> u64 {
        match self.duration_s {
            Some(d) => (d * self.physics.step_hz).round() as u64,
            None => self.drive_steps(),
        }
    }
}
