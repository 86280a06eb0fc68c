//! The robot's motion: the drive program turned into wheel commands, and the commands into a
//! trajectory by differential-drive kinematics (exact arcs over 1 ms steps), with an optional
//! motor lag (first-order, or another response: [`DriveResponse`]) and white noise of the wheels' speed around what they are commanded.

use hilsim_recording::{CommandSample, Pose};
use hilsim_sim::scenario::Scenario;

use crate::form::DriveResponse;
use crate::noise::Stream;

/// Integration step, seconds.
pub const STEP_S: f64 = 0.001;
/// Rate at which commands are issued (and written), Hz.
pub const COMMAND_HZ: f64 = 50.0;

/// One span of constant wheel commands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    pub from_s: f64,
    pub to_s: f64,
    pub left_mps: f64,
    pub right_mps: f64,
}

/// The drive program as spans of constant commands. Each step lasts a whole number of
/// command periods and its speed is scaled so that its distance or angle is exact.
#[must_use]
pub fn program(scenario: &Scenario) -> Vec<Span> {
    let period = 1.0 / COMMAND_HZ;
    let half_base = scenario.robot.wheel_base_m / 2.0;
    let mut spans = Vec::new();
    let mut t = 0.0;
    for step in &scenario.drive {
        let (duration, left, right) = if let (Some(v), Some(d)) = (step.speed_mps, step.distance_m)
        {
            let n = (d / v.abs() / period).round().max(1.0);
            let v = v.signum() * d / (n * period);
            (n * period, v, v)
        } else if let Some(turn) = step.turn_deg {
            let rate = scenario.robot.turn_rate_deg_s.to_radians();
            let angle = turn.to_radians();
            let n = (angle.abs() / rate / period).round().max(1.0);
            let w = angle / (n * period);
            (n * period, -w * half_base, w * half_base)
        } else {
            let stop = step.stop_s.unwrap_or(0.0);
            ((stop / period).round() * period, 0.0, 0.0)
        };
        if duration > 0.0 {
            spans.push(Span {
                from_s: t,
                to_s: t + duration,
                left_mps: left,
                right_mps: right,
            });
            t += duration;
        }
    }
    spans
}

/// The run's length: the scenario's `duration_s`, else the program's.
#[must_use]
pub fn run_length(scenario: &Scenario, spans: &[Span]) -> f64 {
    scenario
        .duration_s
        .unwrap_or_else(|| spans.last().map_or(0.0, |s| s.to_s))
}

/// The commands as issued, one row per command period.
#[must_use]
pub fn commands(spans: &[Span], end_s: f64) -> Vec<CommandSample> {
    let n = (end_s * COMMAND_HZ).floor() as usize;
    (0..=n)
        .map(|k| {
            let t = k as f64 / COMMAND_HZ;
            let (l, r) = command_at(spans, t);
            CommandSample {
                t_s: t,
                left_mps: l,
                right_mps: r,
            }
        })
        .collect()
}

fn command_at(spans: &[Span], t: f64) -> (f64, f64) {
    spans
        .iter()
        .find(|s| t >= s.from_s - 1e-9 && t < s.to_s - 1e-9)
        .map_or((0.0, 0.0), |s| (s.left_mps, s.right_mps))
}

/// The trajectory on the integration grid.
pub struct Motion {
    /// Pose at `k · STEP_S`.
    pub poses: Vec<Pose>,
    /// Each wheel's cumulative travel there, metres.
    pub travel: Vec<[f64; 2]>,
    /// Each wheel's speed there, m/s.
    pub speed: Vec<[f64; 2]>,
}

/// How the wheels follow their commands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drive {
    /// How each wheel's speed lags its command: the response time, seconds, and the form
    /// (`None`: at once).
    pub lag: Option<(f64, DriveResponse)>,
    /// Relative standard deviation of white noise on each wheel's speed, held 10 ms.
    pub speed_noise: f64,
    /// Each wheel's radius over nominal: the motor turns it at the command over the nominal
    /// radius, so the ground moves this many times the command.
    pub radius_scale: [f64; 2],
}

impl Default for Drive {
    fn default() -> Self {
        Self {
            lag: None,
            speed_noise: 0.0,
            radius_scale: [1.0; 2],
        }
    }
}

/// Integrates the commands of `spans` from `start` to `end_s`.
#[must_use]
pub fn integrate(
    spans: &[Span],
    start: Pose,
    wheel_base_m: f64,
    end_s: f64,
    drive: Drive,
    noise: &mut Stream,
) -> Motion {
    let n = (end_s / STEP_S).ceil() as usize + 1;
    let mut poses = Vec::with_capacity(n);
    let mut travel = Vec::with_capacity(n);
    let mut speed = Vec::with_capacity(n);
    let mut pose = start;
    let mut wheels = [0.0f64; 2];
    let mut v = [0.0f64; 2];
    let mut acceleration = [0.0f64; 2];
    let mut jitter = [0.0f64; 2];
    let natural_rad_s = match drive.lag {
        Some((tau, DriveResponse::SecondOrder { damping })) => {
            second_order_rise(damping) / tau.max(STEP_S)
        }
        _ => 0.0,
    };
    for k in 0..n {
        poses.push(pose);
        travel.push(wheels);
        speed.push(v);
        let t = k as f64 * STEP_S;
        let delay = match drive.lag {
            Some((tau, DriveResponse::DeadTime { share })) => share * tau,
            _ => 0.0,
        };
        let (l, r) = command_at(spans, t - delay);
        let u = [l, r];
        // The speed noise is redrawn every 10 ms (one motor-controller period).
        if k % 10 == 0 {
            jitter = [
                drive.speed_noise * noise.normal(),
                drive.speed_noise * noise.normal(),
            ];
        }
        for w in 0..2 {
            let target = u[w] * drive.radius_scale[w] * (1.0 + jitter[w]);
            v[w] = match drive.lag {
                None => target,
                // τ v̇ + v = u, exactly over one step.
                Some((tau, DriveResponse::FirstOrder)) => {
                    target + (v[w] - target) * (-STEP_S / tau).exp()
                }
                Some((tau, DriveResponse::DeadTime { share })) => {
                    let rest = (tau * (1.0 - share)).max(STEP_S);
                    target + (v[w] - target) * (-STEP_S / rest).exp()
                }
                Some((_, DriveResponse::SlewLimited { accel_mps2 })) => {
                    let step = accel_mps2 * STEP_S;
                    v[w] + (target - v[w]).clamp(-step, step)
                }
                // Semi-implicit Euler, stable for ωₙ Δt < 2: any response time above 2 ms.
                Some((_, DriveResponse::SecondOrder { damping })) => {
                    let w2 = natural_rad_s * natural_rad_s;
                    acceleration[w] += (w2 * (target - v[w])
                        - 2.0 * damping * natural_rad_s * acceleration[w])
                        * STEP_S;
                    v[w] + acceleration[w] * STEP_S
                }
            };
        }
        let ds = (v[0] + v[1]) / 2.0 * STEP_S;
        let dth = (v[1] - v[0]) / wheel_base_m * STEP_S;
        // The exact arc: the chord at the mean heading, its length 2 sin(dθ/2)/dθ · ds.
        let chord = if dth.abs() > 1e-12 {
            2.0 * (dth / 2.0).sin() / dth * ds
        } else {
            ds
        };
        let mid = pose.yaw + dth / 2.0;
        pose = Pose {
            x: pose.x + chord * mid.cos(),
            y: pose.y + chord * mid.sin(),
            yaw: pose.yaw + dth,
        };
        wheels[0] += v[0] * STEP_S;
        wheels[1] += v[1] * STEP_S;
    }
    Motion {
        poses,
        travel,
        speed,
    }
}

/// `ωₙ t` at which a second-order system of damping ζ, from rest, reaches `1 − 1/e` of a
/// step: so that its response time is comparable to a first-order lag's τ.
#[must_use]
pub fn second_order_rise(damping: f64) -> f64 {
    let target = 1.0 - (-1.0f64).exp();
    let dt = 1e-4;
    let (mut x, mut v, mut t) = (0.0f64, 0.0f64, 0.0f64);
    while x < target && t < 50.0 {
        v += ((1.0 - x) - 2.0 * damping * v) * dt;
        x += v * dt;
        t += dt;
    }
    t
}

impl Motion {
    fn at<T: Copy>(v: &[T], t: f64, mix: impl Fn(T, T, f64) -> T) -> T {
        let x = (t / STEP_S).max(0.0);
        let k = (x.floor() as usize).min(v.len() - 1);
        let f = x - k as f64;
        if k + 1 >= v.len() {
            return v[v.len() - 1];
        }
        mix(v[k], v[k + 1], f)
    }

    /// The pose at `t`.
    #[must_use]
    pub fn pose(&self, t: f64) -> Pose {
        Self::at(&self.poses, t, |a, b, f| Pose {
            x: a.x + f * (b.x - a.x),
            y: a.y + f * (b.y - a.y),
            yaw: a.yaw + f * (b.yaw - a.yaw),
        })
    }

    /// Each wheel's travel at `t`.
    #[must_use]
    pub fn travel(&self, t: f64) -> [f64; 2] {
        Self::at(&self.travel, t, |a, b, f| {
            [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
        })
    }

    /// Each wheel's speed at `t`.
    #[must_use]
    pub fn speed(&self, t: f64) -> [f64; 2] {
        Self::at(&self.speed, t, |a, _, _| a)
    }
}
