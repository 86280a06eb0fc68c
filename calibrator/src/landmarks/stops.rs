//! The stand-still stops: where the robot stood still long enough to average revolutions, and
//! where it nominally stood (the commanded displacement integrated from `commands.csv`, or the
//! odometry), in the start-pose frame.
//!
//! The paper takes its measurements "after the robot reached its new position (i.e., we are not
//! considering measurements recorded during transients)" (Sec. 3.1): a stop is an interval of
//! zero wheel commands from the moment the robot came to rest ([`super::rest`]), used when it
//! holds at least `min_revolutions` of the lidar's revolutions.

use hilsim_recording::{CommandSample, OdometrySample, Recording};

use super::options::{Nominal, StopOptions};
use super::rest::{rest_start, revolution_period_s, wheel_speed, RestFrom};
use crate::CalibrationError;
use hilsim_recording::{wrap_angle, Pose};

/// One stand-still stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stop {
    /// Start of the window whose readings are used (after the settling time), seconds.
    pub t_start_s: f64,
    /// End of the window, seconds.
    pub t_end_s: f64,
    /// The robot's nominal pose during the stop, start-pose frame.
    pub pose: Pose,
    /// Whether the robot was commanded to move before this stop: the stops before the first
    /// motion are at the start pose by definition, whatever the actuation error.
    pub moved_before: bool,
    /// How the start of rest was found.
    pub rest_from: RestFrom,
}

/// What the stop finder saw besides the stops, for the notes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StopReport {
    /// Candidate stops dropped because the odometry showed motion: their start and the speed.
    pub moving: Vec<(f64, f64)>,
    /// Candidate stops dropped for holding too few revolutions at rest: the interval's start and
    /// the revolutions it held.
    pub too_short: Vec<(f64, f64)>,
    /// The lidar's revolution period the stops were measured in, seconds.
    pub revolution_s: f64,
}

/// The stops of a recording, in time order.
///
/// # Errors
/// [`CalibrationError::Missing`] when the recording has neither commands nor odometry to find
/// stops in, or odometry is asked for and absent; [`CalibrationError::Invalid`] when the
/// odometry's time runs backwards.
pub fn find_stops(
    rec: &Recording,
    opts: &StopOptions,
) -> Result<(Vec<Stop>, StopReport), CalibrationError> {
    let end = rec.duration_s();
    let odometry = rec.odometry.as_deref().filter(|o| !o.is_empty());
    let mut report = StopReport::default();
    let intervals = if rec.commands.is_empty() {
        let odo = odometry.ok_or_else(|| {
            CalibrationError::Missing(
                "the recording has neither commands.csv rows nor odometry.csv to find the \
                 robot's stand-still stops in"
                    .into(),
            )
        })?;
        still_intervals_from_odometry(odo, opts)
    } else {
        zero_command_intervals(&rec.commands, end)
    };
    if opts.nominal == Nominal::Odometry && odometry.is_none() {
        return Err(CalibrationError::Missing(
            "nominal stop positions from odometry were asked for, but the recording has no \
             odometry.csv"
                .into(),
        ));
    }
    let use_commands = opts.nominal == Nominal::Commands && !rec.commands.is_empty();
    let lidar = rec.lidar.as_deref().filter(|l| !l.is_empty());
    report.revolution_s = lidar.map_or(revolution_period_s(&[]), revolution_period_s);
    // The robot stands at the start pose until the first interval that follows a motion.
    let t_ref = intervals.iter().find(|iv| !iv.2).map_or(0.0, |iv| iv.1);
    let mut stops = Vec::new();
    for (t0, t1, moved_before) in intervals {
        // Intervals found in the odometry are at rest from their start.
        let (a, rest_from) = if rec.commands.is_empty() {
            (t0, RestFrom::Odometry)
        } else {
            rest_start(
                (t0, t1),
                opts.settle_s,
                opts.still_speed_mps,
                odometry,
                lidar,
            )
        };
        let b = t1;
        let revolutions = (b - a) / report.revolution_s;
        // A whole revolution's readings span 359/360 of its period: 1 % slack.
        if revolutions < opts.min_revolutions * 0.99 {
            report.too_short.push((t0, revolutions.max(0.0)));
            continue;
        }
        if let Some(odo) = odometry {
            if let Some(speed) = wheel_speed(odo, (a, b)).filter(|v| *v > opts.still_speed_mps) {
                report.moving.push((a, speed));
                continue;
            }
        }
        let pose = match odometry {
            Some(odo) if !use_commands => {
                odometry_pose(odo, a, b, t_ref, rec.meta.robot.wheel_base_m)
            }
            _ => command_pose(&rec.commands, a, rec.meta.robot.wheel_base_m),
        };
        stops.push(Stop {
            t_start_s: a,
            t_end_s: b,
            pose,
            moved_before,
            rest_from,
        });
    }
    Ok((stops, report))
}

/// Intervals `(start, end, moved_before)` of zero wheel commands. A command holds until the next
/// row; before the first row the robot has not been told to move.
fn zero_command_intervals(commands: &[CommandSample], end: f64) -> Vec<(f64, f64, bool)> {
    let is_zero = |c: &CommandSample| c.left_mps.abs() < 1e-9 && c.right_mps.abs() < 1e-9;
    let mut out = Vec::new();
    let mut open: Option<f64> = Some(0.0);
    let mut moved = false;
    for c in commands {
        match (is_zero(c), open) {
            (true, None) => open = Some(c.t_s),
            (false, Some(t0)) => {
                if c.t_s > t0 {
                    out.push((t0, c.t_s, moved));
                }
                open = None;
                moved = true;
            }
            (false, None) => moved = true,
            (true, Some(_)) => {}
        }
    }
    if let Some(t0) = open {
        if end > t0 {
            out.push((t0, end, moved));
        }
    }
    out
}

/// Intervals where the wheels' speed, fitted over a sliding half-second, stays below the
/// stand-still threshold: the stops of a recording without commands.
fn still_intervals_from_odometry(
    odo: &[OdometrySample],
    opts: &StopOptions,
) -> Vec<(f64, f64, bool)> {
    let half = 0.25;
    let mut out = Vec::new();
    let mut open: Option<f64> = None;
    let mut moved = false;
    let mut last_t = 0.0;
    for s in odo {
        let still = wheel_speed(odo, (s.t_s - half, s.t_s + half))
            .is_none_or(|v| v <= opts.still_speed_mps);
        match (still, open) {
            (true, None) => open = Some(s.t_s),
            (false, Some(t0)) => {
                out.push((t0, last_t, moved));
                open = None;
                moved = true;
            }
            (false, None) => moved = true,
            (true, Some(_)) => {}
        }
        last_t = s.t_s;
    }
    if let Some(t0) = open {
        out.push((t0, last_t, moved));
    }
    out
}

/// The pose reached at `t` by integrating the commanded wheel speeds from the start pose, each
/// command held until the next (exact arcs of constant twist).
#[must_use]
pub fn command_pose(commands: &[CommandSample], t: f64, wheel_base_m: f64) -> Pose {
    let mut pose = Pose::default();
    for (i, c) in commands.iter().enumerate() {
        if c.t_s >= t {
            break;
        }
        let until = commands.get(i + 1).map_or(t, |n| n.t_s.min(t));
        let dt = until - c.t_s;
        if dt <= 0.0 {
            continue;
        }
        let v = (c.left_mps + c.right_mps) / 2.0;
        let omega = (c.right_mps - c.left_mps) / wheel_base_m;
        pose = advance(pose, v, omega, dt);
    }
    pose
}

/// Constant forward speed `v` and turn rate `omega` for `dt`.
fn advance(p: Pose, v: f64, omega: f64, dt: f64) -> Pose {
    let dyaw = omega * dt;
    if dyaw.abs() < 1e-9 {
        let yaw = p.yaw + dyaw / 2.0;
        Pose::new(
            p.x + v * dt * yaw.cos(),
            p.y + v * dt * yaw.sin(),
            p.yaw + dyaw,
        )
    } else {
        let r = v / omega;
        Pose::new(
            p.x + r * ((p.yaw + dyaw).sin() - p.yaw.sin()),
            p.y - r * ((p.yaw + dyaw).cos() - p.yaw.cos()),
            p.yaw + dyaw,
        )
    }
}

/// The mean odometry pose over `[a, b]`, dead-reckoned in the start-pose frame.
///
/// The encoders' noise is per reading, not cumulative, so the heading is taken from the wheels'
/// cumulative difference (exact, no drift) and the start pose is the mean over the readings
/// before `t_ref` (the robot standing at the start): referencing one reading would carry its
/// noise into every later heading (2 mm on each wheel is 0.5° over a 0.23 m base, 5 mm sideways
/// after 0.6 m).
fn odometry_pose(odo: &[OdometrySample], a: f64, b: f64, t_ref: f64, wheel_base_m: f64) -> Pose {
    let reference: Vec<&OdometrySample> = odo.iter().take_while(|s| s.t_s <= t_ref).collect();
    let reference = if reference.is_empty() {
        vec![&odo[0]]
    } else {
        reference
    };
    let n0 = reference.len() as f64;
    let l0 = reference.iter().map(|s| s.left_m).sum::<f64>() / n0;
    let r0 = reference.iter().map(|s| s.right_m).sum::<f64>() / n0;
    let heading = |s: &OdometrySample| ((s.right_m - r0) - (s.left_m - l0)) / wheel_base_m;
    // Dead-reckon every reading, then shift so that the reference readings average the origin.
    let mut poses = Vec::with_capacity(odo.len());
    let mut pose = Pose::new(0.0, 0.0, heading(&odo[0]));
    poses.push(pose);
    for w in odo.windows(2) {
        let ds = ((w[1].left_m - w[0].left_m) + (w[1].right_m - w[0].right_m)) / 2.0;
        let (h0, h1) = (heading(&w[0]), heading(&w[1]));
        let mid = h0 + wrap_angle(h1 - h0) / 2.0;
        pose = Pose::new(pose.x + ds * mid.cos(), pose.y + ds * mid.sin(), h1);
        poses.push(pose);
    }
    let mean = |sel: &dyn Fn(&OdometrySample) -> bool| {
        let (mut sx, mut sy, mut ss, mut sc, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (s, p) in odo.iter().zip(&poses) {
            if sel(s) {
                sx += p.x;
                sy += p.y;
                ss += p.yaw.sin();
                sc += p.yaw.cos();
                n += 1.0;
            }
        }
        (n > 0.0).then(|| Pose::new(sx / n, sy / n, wrap_angle(ss.atan2(sc))))
    };
    let origin = mean(&|s| s.t_s <= t_ref.max(odo[0].t_s)).unwrap_or_default();
    let at = mean(&|s| s.t_s >= a && s.t_s <= b).unwrap_or(poses[poses.len() - 1]);
    Pose::new(at.x - origin.x, at.y - origin.y, at.yaw)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cmd(t_s: f64, l: f64, r: f64) -> CommandSample {
        CommandSample {
            t_s,
            left_mps: l,
            right_mps: r,
        }
    }

    #[test]
    fn zero_intervals_include_the_start_and_the_tail() {
        let c = [cmd(0.0, 0.0, 0.0), cmd(2.0, 0.1, 0.1), cmd(5.0, 0.0, 0.0)];
        let iv = zero_command_intervals(&c, 7.0);
        assert_eq!(iv, vec![(0.0, 2.0, false), (5.0, 7.0, true)]);
    }

    #[test]
    fn commands_integrate_straight_and_turning() {
        let c = [cmd(0.0, 0.1, 0.1), cmd(3.0, 0.0, 0.0)];
        let p = command_pose(&c, 10.0, 0.23);
        assert!((p.x - 0.3).abs() < 1e-12 && p.y.abs() < 1e-12);
        // A quarter turn in place then 1 m forward ends at (0, 1).
        let w = std::f64::consts::FRAC_PI_2 * 0.115;
        let c = [cmd(0.0, -w, w), cmd(1.0, 1.0, 1.0), cmd(2.0, 0.0, 0.0)];
        let p = command_pose(&c, 5.0, 0.23);
        assert!(p.x.abs() < 1e-9 && (p.y - 1.0).abs() < 1e-9, "{p:?}");
    }
}
