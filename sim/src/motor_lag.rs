//! `[effects.drive_motor_lag]`: the wheels reach a commanded speed with a first-order lag, or
//! through a second-order response.
//!
//! A DC drive motor under speed control behaves, to first order, as `τ v̇ + v = u`: the
//! mechanical time constant τ = J R / (k_t k_e) of the armature and load (inertia J, winding
//! resistance R, torque and back-EMF constants k_t, k_e), lengthened by the speed loop's own
//! bandwidth (Franklin, Powell, Emami-Naeini, *Feedback Control of Dynamic Systems*, the DC motor
//! model of ch. 2). A step of the command `u` is approached as `v(t) = u + (v₀ − u) e^{−t/τ}`.
//! The lag has unit gain at rest, so a straight still ends where the program says once the robot
//! has settled; it only arrives later.
//!
//! Where the motor's electrical time constant L/R or the speed loop's integral action is not
//! negligible against the mechanical one, the response is second order,
//! `v̈ = ωₙ² (u − v) − 2 ζ ωₙ v̇` (the same chapter's armature model with its inductance): with
//! damping ζ < 1 the wheel overshoots its command before it settles. ωₙ is set so that a step
//! reaches `1 − 1/e` of itself at τ, as the first-order lag does, so τ keeps meaning the
//! response time whatever the damping; as ζ grows the response tends to the first-order one.

use crate::drive::WheelCommand;

/// The wheels' speeds as they lag behind the commands.
///
/// ```
/// use hilsim_sim::{MotorLag, WheelCommand};
/// let mut lag = MotorLag::new(0.5);
/// let go = WheelCommand { left_mps: 0.2, right_mps: 0.2 };
/// let mut travelled = 0.0;
/// for _ in 0..100 {
///     travelled += lag.step(go, 0.01).left_mps * 0.01;
/// }
/// // After one second (2 τ): v = 0.2 (1 − e^{−2}); travel = 0.2 (1 − τ (1 − e^{−2})).
/// let expected = 0.2 * (1.0 - 0.5 * (1.0 - (-2.0f64).exp()));
/// assert!((travelled - expected).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct MotorLag {
    tau_s: f64,
    /// The second-order response's ζ and ωₙ (rad/s); `None`: first order.
    second_order: Option<(f64, f64)>,
    speed: [f64; 2],
    /// Each wheel's acceleration (second order only), m/s².
    acceleration: [f64; 2],
    /// The second-order response's step, and its transition and mean-speed row over it
    /// ([`held_response`]), computed at the first step of that length.
    discrete: Option<(f64, Matrix2, [f64; 2])>,
}

impl MotorLag {
    /// Wheels at rest, lagging with time constant `tau_s` (> 0).
    #[must_use]
    pub fn new(tau_s: f64) -> Self {
        Self {
            tau_s,
            second_order: None,
            speed: [0.0; 2],
            acceleration: [0.0; 2],
            discrete: None,
        }
    }

    /// Wheels at rest, following their commands through a second-order response of damping
    /// `damping` (> 0) whose step reaches `1 − 1/e` at `tau_s`.
    ///
    /// ```
    /// use hilsim_sim::{MotorLag, WheelCommand};
    /// let go = WheelCommand { left_mps: 0.2, right_mps: 0.2 };
    /// let mut lag = MotorLag::second_order(0.3, 0.5);
    /// let speeds: Vec<f64> = (0..200)
    ///     .map(|_| {
    ///         lag.step(go, 0.01);
    ///         lag.speeds().left_mps
    ///     })
    ///     .collect();
    /// // 1 − 1/e of the step at τ = 0.3 s (the 30th step); an overshoot of e^{−πζ/√(1−ζ²)}, 16 %.
    /// assert!((speeds[29] - 0.2 * (1.0 - (-1.0f64).exp())).abs() < 0.004, "{}", speeds[29]);
    /// let peak = speeds.iter().copied().fold(0.0, f64::max);
    /// assert!((peak / 0.2 - 1.163).abs() < 0.01, "{peak}");
    /// ```
    #[must_use]
    pub fn second_order(tau_s: f64, damping: f64) -> Self {
        Self {
            second_order: Some((damping, response_time(damping) / tau_s)),
            ..Self::new(tau_s)
        }
    }

    /// The wheels' speeds now, m/s.
    #[must_use]
    pub fn speeds(&self) -> WheelCommand {
        WheelCommand {
            left_mps: self.speed[0],
            right_mps: self.speed[1],
        }
    }

    /// Holds `target` for `dt_s` and returns the wheels' mean speeds over that interval, so the
    /// distance they cover is exact for a command held through the step: with `a = e^{−dt/τ}`,
    /// `v(dt) = u + (v₀ − u) a` and the mean is `u + (v₀ − u) τ (1 − a) / dt`.
    pub fn step(&mut self, target: WheelCommand, dt_s: f64) -> WheelCommand {
        if let Some((damping, natural)) = self.second_order {
            return self.step_second_order(target, dt_s, damping, natural);
        }
        let a = (-dt_s / self.tau_s).exp();
        let mean_factor = self.tau_s * (1.0 - a) / dt_s;
        let mut mean = [0.0; 2];
        for (i, u) in [target.left_mps, target.right_mps].into_iter().enumerate() {
            let v0 = self.speed[i];
            mean[i] = u + (v0 - u) * mean_factor;
            self.speed[i] = u + (v0 - u) * a;
        }
        WheelCommand {
            left_mps: mean[0],
            right_mps: mean[1],
        }
    }
}

impl MotorLag {
    /// [`MotorLag::step`] for a second-order response, exact for a command held through the
    /// step: the state `x = (v − u, v̇)` obeys `ẋ = A x`, `A = [[0, 1], [−ωₙ², −2ζωₙ]]`, so
    /// `x(dt) = e^{A dt} x₀` and the mean speed is `u + [1 0] (∫₀^dt e^{A s} ds) x₀ / dt`. Both
    /// matrices depend on the step alone, and are computed once for it.
    fn step_second_order(
        &mut self,
        target: WheelCommand,
        dt_s: f64,
        damping: f64,
        natural: f64,
    ) -> WheelCommand {
        let (transition, mean_row) = match self.discrete {
            Some((dt, transition, mean_row)) if dt == dt_s => (transition, mean_row),
            _ => {
                let (transition, integral) = held_response(damping, natural, dt_s);
                let mean_row = [integral[0][0] / dt_s, integral[0][1] / dt_s];
                self.discrete = Some((dt_s, transition, mean_row));
                (transition, mean_row)
            }
        };
        let mut mean = [0.0; 2];
        for (i, u) in [target.left_mps, target.right_mps].into_iter().enumerate() {
            let (e, a) = (self.speed[i] - u, self.acceleration[i]);
            mean[i] = u + mean_row[0] * e + mean_row[1] * a;
            self.speed[i] = u + transition[0][0] * e + transition[0][1] * a;
            self.acceleration[i] = transition[1][0] * e + transition[1][1] * a;
        }
        WheelCommand {
            left_mps: mean[0],
            right_mps: mean[1],
        }
    }
}

type Matrix2 = [[f64; 2]; 2];

/// `(e^{A h}, ∫₀^h e^{A s} ds)` for the second-order response's `A` (damping ζ, natural
/// frequency ωₙ): the blocks of the exponential of the augmented `[[A h, I h], [0, 0]]`
/// (Van Loan 1978), by scaling and squaring a Taylor series. Valid for any damping: the
/// under-, critically and over-damped closed forms need no cases here.
fn held_response(damping: f64, natural: f64, h: f64) -> (Matrix2, Matrix2) {
    let mut m = [[0.0; 4]; 4];
    m[0][1] = h;
    m[1][0] = -natural * natural * h;
    m[1][1] = -2.0 * damping * natural * h;
    m[0][2] = h;
    m[1][3] = h;
    // Scaled until its norm is under ½, where 16 terms reach double precision.
    let norm = m
        .iter()
        .map(|row| row.iter().map(|v: &f64| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let squarings = if norm > 0.5 {
        (norm / 0.5).log2().ceil() as i32
    } else {
        0
    };
    let scale = 0.5f64.powi(squarings);
    m.iter_mut().flatten().for_each(|v| *v *= scale);
    let mut sum = identity4();
    let mut term = identity4();
    for k in 1..=16 {
        term = product4(&term, &m);
        term.iter_mut().flatten().for_each(|v| *v /= f64::from(k));
        for (s, t) in sum.iter_mut().flatten().zip(term.iter().flatten()) {
            *s += t;
        }
    }
    for _ in 0..squarings {
        sum = product4(&sum, &sum);
    }
    (
        [[sum[0][0], sum[0][1]], [sum[1][0], sum[1][1]]],
        [[sum[0][2], sum[0][3]], [sum[1][2], sum[1][3]]],
    )
}

fn identity4() -> [[f64; 4]; 4] {
    let mut m = [[0.0; 4]; 4];
    (0..4).for_each(|i| m[i][i] = 1.0);
    m
}

fn product4(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut c = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            c[i][j] = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

/// `ωₙ t` at which the step response of damping ζ first reaches `1 − 1/e`: its closed form
/// (under-, critically or over-damped) scanned from rest and the crossing bisected.
fn response_time(damping: f64) -> f64 {
    let z = damping;
    let step = |x: f64| -> f64 {
        if (z - 1.0).abs() < 1e-9 {
            1.0 - (1.0 + x) * (-x).exp()
        } else if z < 1.0 {
            let wd = (1.0 - z * z).sqrt();
            1.0 - (-z * x).exp() * ((wd * x).cos() + z / wd * (wd * x).sin())
        } else {
            let r = (z * z - 1.0).sqrt();
            let (p1, p2) = (z - r, z + r);
            1.0 - (p2 * (-p1 * x).exp() - p1 * (-p2 * x).exp()) / (p2 - p1)
        }
    };
    let level = 1.0 - (-1.0f64).exp();
    // The response first reaches the level within 4ζ + 2 (the slow pole's time constant, 2ζ,
    // twice over), scanned in steps of 0.01.
    let mut hi = 0.01;
    while step(hi) < level && hi < 4.0 * z + 2.0 {
        hi += 0.01;
    }
    let mut lo = hi - 0.01;
    for _ in 0..50 {
        let mid = (lo + hi) / 2.0;
        if step(mid) < level {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo + hi) / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The held step is exact: from rest, each step's speed is the closed-form step response
    /// `1 − e^{−ζωₙt} (cos ω_d t + ζ/√(1−ζ²) sin ω_d t)` (ω_d = ωₙ√(1−ζ²)), and the travel the
    /// means add up to is its integral, `t − 2ζ/ωₙ + e^{−ζωₙt} (2ζ/ωₙ cos ω_d t + (2ζ² − 1)/ω_d
    /// sin ω_d t)`, whatever the step's length against the response.
    #[test]
    fn a_held_step_follows_the_closed_form() {
        for (damping, tau, dt) in [(0.4, 0.3, 0.01), (0.7, 0.05, 0.02), (0.2, 0.02, 0.004)] {
            let mut lag = MotorLag::second_order(tau, damping);
            let natural = response_time(damping) / tau;
            let wd = natural * (1.0 - damping * damping).sqrt();
            let go = WheelCommand {
                left_mps: 1.0,
                right_mps: 1.0,
            };
            let mut travel = 0.0;
            for k in 1..=300 {
                travel += lag.step(go, dt).left_mps * dt;
                let t = f64::from(k) * dt;
                let decay = (-damping * natural * t).exp();
                let (sin, cos) = (wd * t).sin_cos();
                let speed = 1.0 - decay * (cos + damping * natural / wd * sin);
                let integral = t - 2.0 * damping / natural
                    + decay
                        * (2.0 * damping / natural * cos
                            + (2.0 * damping * damping - 1.0) / wd * sin);
                assert!((lag.speeds().left_mps - speed).abs() < 1e-12, "{t}");
                assert!((travel - integral).abs() < 1e-12, "{t}");
            }
        }
    }
}
