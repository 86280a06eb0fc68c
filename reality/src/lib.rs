//! An independent reality: recordings of a scenario made by a generator that shares no model
//! code with hilsim's simulator (`hilsim-sim`) or sensor emulator (`hilsim-lidar-emulator`).
//! Its geometry and ray casting, its noise, its timing and its drive are written here from the
//! scenario format (`docs/formats/interfaces.md`, `scenarios/README.md`) and the papers' range
//! model; it uses `hilsim_sim::scenario` only for the scenario file's parsed form and
//! `hilsim-recording` for the output types. On top of the scenario it can conceal effects
//! (the diagnosis catalogue's physics, written again here, and physics outside it) and the
//! small differences between any two simulators that no catalogue is about ([`Nuisances`]).
//! `hilsim diagnose --self-test N --reality independent` proves the diagnosis on it.

mod concealed;
mod motion;
mod noise;
mod nuisance;
mod sensors;
mod world;

pub use concealed::Concealed;
pub use noise::Stream;
pub use nuisance::Nuisances;

use hilsim_recording::{Meta, Mount, Pose, Recording, RobotMeta, SonarMount};
use hilsim_sim::scenario::Scenario;

use crate::motion::Drive;
use crate::sensors::Run;
use crate::world::{World, WorldOffsets};

/// A recording of `scenario` by this generator, with `concealed` physics and `nuisances`,
/// its noise drawn from `seed`.
#[must_use]
pub fn record(
    scenario: &Scenario,
    concealed: &[Concealed],
    nuisances: Nuisances,
    seed: u64,
) -> Recording {
    let world = World::new(
        scenario,
        WorldOffsets {
            wall_shift_m: nuisances.wall_shift_m,
            radius_change_m: nuisances.radius_change_m,
        },
    );
    let spans = motion::program(scenario);
    let end_s = motion::run_length(scenario, &spans);
    let lag_s = concealed.iter().find_map(|c| match *c {
        Concealed::MotorLag { time_constant_s } => Some(time_constant_s),
        _ => None,
    });
    let start = Pose {
        x: scenario.robot.start.x,
        y: scenario.robot.start.y,
        yaw: scenario.robot.start.yaw_deg.to_radians(),
    };
    let mut drive_noise = Stream::new(seed, "reality-drive");
    let motion = motion::integrate(
        &spans,
        start,
        scenario.robot.wheel_base_m,
        end_s,
        Drive {
            lag_s,
            speed_noise: nuisances.speed_noise,
        },
        &mut drive_noise,
    );
    let run = Run {
        scenario,
        world: &world,
        motion: &motion,
        end_s,
        concealed,
        nuisances,
    };
    let s = &scenario.sensors;
    Recording {
        meta: Meta {
            robot: RobotMeta {
                wheel_base_m: scenario.robot.wheel_base_m,
            },
            lidar: s.lidar.as_ref().map(|l| Mount::from(l.mount)),
            sonar: s.sonar.as_ref().map(|u| SonarMount {
                x_m: u.mount.x_m,
                y_m: u.mount.y_m,
                yaw_deg: u.mount.yaw_deg,
                half_angle_deg: u.half_angle_deg,
            }),
            ..Meta::default()
        },
        commands: motion::commands(&spans, end_s),
        odometry: run.odometer(seed),
        lidar: run.lidar(seed),
        sonar: run.sonar(seed),
        truth: Some(run.truth(seed)),
    }
}
