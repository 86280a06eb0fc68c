//! `lidar_mount_offset`: the lidar is turned and moved on the robot from where the scenario
//! declares it.

use hilsim_lidar_emulator::effects::real_mount;
use hilsim_recording::Mount;
use hilsim_sim::scenario::{self, Effects};

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// The least mount yaw named, degrees: 5 mm at 2 m, the world's own tolerance (see
/// [`Entry::least_departures`]).
pub(crate) const MOUNT_YAW_RESOLUTION_DEG: f64 = 0.15;

/// The least span of headings a run must turn through for a mount to be fitted through the
/// sonar and the encoders. The encoders see the mount's position only as the robot turns (an
/// offset `r` swings the inferred robot point through `r θ` in a turn of θ); without turns the
/// fit has only the sonar's ranges and a crab of the heading against the direction of travel
/// (`cos ψ` of each step), which mimic a wheel's radius: on a straight run in front of a board a
/// "mount" of degrees and decimetres fits. A quarter turn with a 1 cm offset is 16 mm of
/// travel.
const THROUGH_PATH_MIN_TURN_RAD: f64 = std::f64::consts::FRAC_PI_4;

/// The lidar's real mount under a `lidar_mount_offset` of `params` (in the order of
/// [`Entry::params`]) from the `declared` one: the simulator's own [`real_mount`].
pub(crate) fn mounted(declared: &Mount, params: &[f64]) -> Mount {
    let mut e = Effects::default();
    LidarMountOffset.apply(params, &mut e);
    real_mount(*declared, e.lidar_mount_offset)
}

/// `lidar_mount_offset`.
pub(crate) struct LidarMountOffset;

impl Entry for LidarMountOffset {
    fn name(&self) -> &'static str {
        "lidar_mount_offset"
    }

    fn sensor(&self) -> Sensor {
        Sensor::Lidar
    }

    /// The yaw turns every beam's direction, which moves a reading by its range; the position
    /// moves the beams' origin along each direction.
    fn variables(&self) -> &'static [Variable] {
        &[Variable::Bearing, Variable::Range]
    }

    /// Against a path estimated from the lidar a mount offset goes into the path: scan matching
    /// places the lidar, and the robot is inferred from it through the declared mount, so the
    /// lidar fits and the error shows in the sensors that look from the robot (the sonar's
    /// origin and axis; the encoders, as the inferred robot point swings about the real one
    /// while the robot turns): on a path that turns through [`THROUGH_PATH_MIN_TURN_RAD`].
    fn seen_through_path(&self, heading_span_rad: f64) -> bool {
        heading_span_rad >= THROUGH_PATH_MIN_TURN_RAD
    }

    /// The self-test draws a yaw of ±[1, 3]° and a position of ±[0.01, 0.03] m.
    fn params(&self) -> &'static [ParamSpec] {
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
        &MOUNT
    }

    fn absent(&self, _: f64) -> Vec<f64> {
        vec![0.0; 3]
    }

    /// Yaw: 0.15°, 5 mm at 2 m, and its position 5 mm: the world's own tolerance (the lidar's
    /// floor, `Floors`), below which a mount offset is as likely a wall a few millimetres off.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, MOUNT_YAW_RESOLUTION_DEG), (1, 0.005), (2, 0.005)]
    }

    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        effects.lidar_mount_offset = Some(scenario::LidarMountOffset {
            yaw_deg: p(0),
            x_m: p(1),
            y_m: p(2),
        });
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        format!(
            "The simulated lidar sits where the scenario says; the real one is turned \
             {:+.2}° and moved {:+.1} mm forward, {:+.1} mm left of that.",
            p(0),
            p(1) * 1000.0,
            p(2) * 1000.0
        )
    }
}
