//! What the simulation computes from a trajectory or a command log, for estimators that hold the
//! simulation against a recording (`hilsim diagnose`): the wheels' true travel between two poses,
//! and the trajectory a scenario's robot follows when it replays recorded wheel commands.

use hilsim_recording::{CommandSample, TruthSample};

use crate::drive::WheelCommand;
pub use crate::kinematics::wheel_travel;
use crate::scenario::Scenario;
use crate::simulation::Simulation;

/// The trajectory of the scenario's robot when its wheels are commanded by `commands` (each in
/// force from its `t_s` until the next), from t = 0 until `end_s`, at the physics step rate: the
/// scenario's world, start pose, actuation error and effects (motor lag) apply, its drive
/// program does not. The first sample is the start pose at t = 0.
///
/// ```
/// use hilsim_recording::CommandSample;
/// use hilsim_sim::{replay::replay_commands, Scenario};
/// let s = Scenario::from_toml(
///     "name = \"r\"\nduration_s = 1.0\n[robot]\nstart = { x = 0.0, y = 0.0 }\nwheel_base_m = 0.2\n",
///     "inline.toml".as_ref(),
/// )?;
/// let go = [CommandSample { t_s: 0.0, left_mps: 0.5, right_mps: 0.5 }];
/// let truth = replay_commands(&s, &go, 1.0);
/// assert_eq!(truth.len(), 101);
/// assert!((truth[100].x_m - 0.5).abs() < 1e-3);
/// # Ok::<(), hilsim_sim::ScenarioError>(())
/// ```
#[must_use]
pub fn replay_commands(
    scenario: &Scenario,
    commands: &[CommandSample],
    end_s: f64,
) -> Vec<TruthSample> {
    replay(scenario, commands, end_s).0
}

/// The intervals `(from, to)` of [`replay_commands`]'s run during which the robot touches an
/// obstacle: where the wheels' travel is the contact's doing, not the drive's.
///
/// ```
/// use hilsim_recording::CommandSample;
/// use hilsim_sim::{replay::replay_contacts, Scenario};
/// let s = Scenario::from_toml(
///     "name = \"r\"\nduration_s = 3.0\n[world]\nwalls = [{ from = [1.0, -1.0], to = [1.0, 1.0] }]\n\
///      [robot]\nstart = { x = 0.0, y = 0.0 }\nwheel_base_m = 0.2\n",
///     "inline.toml".as_ref(),
/// )?;
/// let into_the_wall = [CommandSample { t_s: 0.0, left_mps: 0.5, right_mps: 0.5 }];
/// let touching = replay_contacts(&s, &into_the_wall, 3.0);
/// assert_eq!(touching.len(), 1);
/// assert!(touching[0].0 > 1.0 && touching[0].0 < 2.0 && touching[0].1 > 2.9, "{touching:?}");
/// let away = [CommandSample { t_s: 0.0, left_mps: -0.5, right_mps: -0.5 }];
/// assert!(replay_contacts(&s, &away, 3.0).is_empty());
/// # Ok::<(), hilsim_sim::ScenarioError>(())
/// ```
#[must_use]
pub fn replay_contacts(
    scenario: &Scenario,
    commands: &[CommandSample],
    end_s: f64,
) -> Vec<(f64, f64)> {
    replay(scenario, commands, end_s).1
}

fn replay(
    scenario: &Scenario,
    commands: &[CommandSample],
    end_s: f64,
) -> (Vec<TruthSample>, Vec<(f64, f64)>) {
    let mut contacts: Vec<(f64, f64)> = Vec::new();
    let mut sim = Simulation::externally_driven(scenario);
    let dt = sim.step_s();
    let steps = (end_s / dt).round().max(0.0) as u64;
    let mut next = 0;
    for _ in 0..steps {
        // The command in force at the step's start (half a step of slack for the times' rounding).
        let t0 = sim.time_s();
        while next < commands.len() && commands[next].t_s <= t0 + dt / 2.0 {
            let c = commands[next];
            sim.set_command(WheelCommand {
                left_mps: c.left_mps,
                right_mps: c.right_mps,
            });
            next += 1;
        }
        let Some(step) = sim.step() else {
            break;
        };
        if sim.in_contact() {
            match contacts.last_mut() {
                Some(last) if last.1 >= step.t0 => last.1 = step.t1,
                _ => contacts.push((step.t0, step.t1)),
            }
        }
    }
    (sim.truth().to_vec(), contacts)
}
