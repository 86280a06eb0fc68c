//! `SetMotor` as the robot executes it: each wheel travels its distance, the farther one at the
//! requested speed and the nearer one scaled so that both finish together, then the wheels stop.
//! A new request replaces the motion in progress.
//!
//! The controller turns the motion into one wheel speed command per physics step. It is open
//! loop on the commands (the simulated wheels do exactly what they are told unless the scenario
//! has an actuation error), and the last step of a motion is scaled so that each wheel's
//! commanded travel equals its distance exactly.
//!
//! ```
//! use hilsim_hil::motion::{MotionController, MotorRequest};
//! let mut motion = MotionController::new();
//! // 100 mm left, 200 mm right at 100 mm/s: the right wheel sets the pace, 2 s in all.
//! motion.start(MotorRequest { left_mm: 100, right_mm: 200, speed_mm_s: 100 });
//! let mut travel = [0.0, 0.0];
//! for _ in 0..300 {
//!     let c = motion.next_step(0.01);
//!     travel[0] += c.left_mps * 0.01;
//!     travel[1] += c.right_mps * 0.01;
//! }
//! assert!((travel[0] - 0.1).abs() < 1e-9 && (travel[1] - 0.2).abs() < 1e-9);
//! assert!(!motion.is_moving());
//! ```

use hilsim_sim::WheelCommand;

/// A `SetMotor LWheelDist <mm> RWheelDist <mm> Speed <mm/s>` the robot accepted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MotorRequest {
    /// Left wheel travel, millimetres (negative: backwards).
    pub left_mm: i32,
    /// Right wheel travel, millimetres.
    pub right_mm: i32,
    /// Speed of the wheel with the farther distance, mm/s (the other is scaled).
    pub speed_mm_s: i32,
}

/// The motion in progress.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Motion {
    command: WheelCommand,
    duration_s: f64,
    /// Physics steps done (counted, not summed, so that rounding cannot accumulate).
    steps: u64,
}

/// Executes [`MotorRequest`]s on the physics step grid.
#[derive(Debug, Clone, Default)]
pub struct MotionController {
    motion: Option<Motion>,
}

/// A step fraction this close to whole is rounding, not a partial step.
const ROUNDING: f64 = 1e-9;

impl MotionController {
    /// A controller with the wheels at rest.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Starts `request`, replacing any motion in progress. Zero distances or a zero speed stop
    /// the wheels.
    pub fn start(&mut self, request: MotorRequest) {
        let left = f64::from(request.left_mm) / 1000.0;
        let right = f64::from(request.right_mm) / 1000.0;
        let speed = f64::from(request.speed_mm_s) / 1000.0;
        let farther = left.abs().max(right.abs());
        if farther == 0.0 || speed <= 0.0 {
            self.stop();
            return;
        }
        // The farther wheel moves at `speed`; both take the same time.
        let duration_s = farther / speed;
        self.motion = Some(Motion {
            command: WheelCommand {
                left_mps: left / duration_s,
                right_mps: right / duration_s,
            },
            duration_s,
            steps: 0,
        });
    }

    /// Stops the wheels at once.
    pub fn stop(&mut self) {
        self.motion = None;
    }

    /// Whether a motion is in progress.
    #[must_use]
    pub fn is_moving(&self) -> bool {
        self.motion.is_some()
    }

    /// The wheel command for the next physics step of `dt_s` seconds (the same for every
    /// step of a motion). The step in which a motion ends gets the command scaled by the
    /// fraction of the step the motion still had, so the commanded travel is exact.
    pub fn next_step(&mut self, dt_s: f64) -> WheelCommand {
        let Some(motion) = &mut self.motion else {
            return WheelCommand::default();
        };
        let remaining_s = motion.duration_s - motion.steps as f64 * dt_s;
        let fraction = remaining_s / dt_s;
        let fraction = if fraction >= 1.0 - ROUNDING {
            1.0
        } else {
            fraction.max(0.0)
        };
        motion.steps += 1;
        let command = WheelCommand {
            left_mps: motion.command.left_mps * fraction,
            right_mps: motion.command.right_mps * fraction,
        };
        if fraction < 1.0 || remaining_s <= dt_s * (1.0 + ROUNDING) {
            self.motion = None;
        }
        command
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drive(motion: &mut MotionController, steps: usize, dt: f64) -> ([f64; 2], usize) {
        let mut travel = [0.0; 2];
        let mut moving_steps = 0;
        for _ in 0..steps {
            let c = motion.next_step(dt);
            if c != WheelCommand::default() {
                moving_steps += 1;
            }
            travel[0] += c.left_mps * dt;
            travel[1] += c.right_mps * dt;
        }
        (travel, moving_steps)
    }

    #[test]
    fn each_wheel_travels_its_distance_exactly_and_the_farther_one_sets_the_pace() {
        let mut m = MotionController::new();
        // 333 mm at 200 mm/s: 1.665 s, not a whole number of 10 ms steps.
        m.start(MotorRequest {
            left_mm: -111,
            right_mm: 333,
            speed_mm_s: 200,
        });
        let first = m.clone().next_step(0.01);
        assert!((first.right_mps - 0.2).abs() < 1e-12, "{first:?}");
        assert!((first.left_mps + 0.2 / 3.0).abs() < 1e-12, "{first:?}");
        let (travel, steps) = drive(&mut m, 1000, 0.01);
        assert!((travel[0] + 0.111).abs() < 1e-9, "{travel:?}");
        assert!((travel[1] - 0.333).abs() < 1e-9, "{travel:?}");
        // Both wheels finish together, in the step containing 1.665 s.
        assert_eq!(steps, 167);
        assert!(!m.is_moving());
    }

    #[test]
    fn a_new_request_replaces_the_motion_and_zero_stops() {
        let mut m = MotionController::new();
        m.start(MotorRequest {
            left_mm: 1000,
            right_mm: 1000,
            speed_mm_s: 100,
        });
        drive(&mut m, 50, 0.01); // 50 mm done
        m.start(MotorRequest {
            left_mm: 20,
            right_mm: 20,
            speed_mm_s: 100,
        });
        let (travel, steps) = drive(&mut m, 100, 0.01);
        assert!(
            (travel[0] - 0.02).abs() < 1e-12 && steps == 20,
            "{travel:?} {steps}"
        );
        m.start(MotorRequest {
            left_mm: 500,
            right_mm: 500,
            speed_mm_s: 100,
        });
        m.start(MotorRequest {
            left_mm: 0,
            right_mm: 0,
            speed_mm_s: 0,
        });
        assert!(!m.is_moving());
        assert_eq!(m.next_step(0.01), WheelCommand::default());
        m.start(MotorRequest {
            left_mm: 500,
            right_mm: 500,
            speed_mm_s: 100,
        });
        m.stop();
        assert_eq!(m.next_step(0.01), WheelCommand::default());
    }

    #[test]
    fn a_turn_in_place_runs_the_wheels_in_opposite_directions() {
        let mut m = MotionController::new();
        m.start(MotorRequest {
            left_mm: 100,
            right_mm: -100,
            speed_mm_s: 100,
        });
        let (travel, steps) = drive(&mut m, 200, 0.01);
        assert_eq!(steps, 100);
        assert!((travel[0] - 0.1).abs() < 1e-9 && (travel[1] + 0.1).abs() < 1e-9);
        // A whole number of steps: every step at full speed, none scaled by rounding.
        m.start(MotorRequest {
            left_mm: 300,
            right_mm: 300,
            speed_mm_s: 300,
        });
        let commands: Vec<WheelCommand> = (0..101).map(|_| m.next_step(0.01)).collect();
        assert!(
            commands[..100].iter().all(|c| c.left_mps == 0.3),
            "{commands:?}"
        );
        assert_eq!(commands[100], WheelCommand::default());
    }
}
