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
}

/// The longest integration step of a second-order response, in units of 1/ωₙ: semi-implicit
/// Euler's phase error stays under a percent of a period.
const SECOND_ORDER_STEP: f64 = 0.05;

impl MotorLag {
    /// Wheels at rest, lagging with time constant `tau_s` (> 0).
    #[must_use]
    pub fn new(tau_s: f64) -> Self {
        Self {
            tau_s,
            second_order: None,
            speed: [0.0; 2],
            acceleration: [0.0; 2],
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
    /// [`MotorLag::step`] for a second-order response: semi-implicit Euler in sub-steps of at
    /// most [`SECOND_ORDER_STEP`]`/ωₙ`, the mean speed the sub-steps' mean.
    fn step_second_order(
        &mut self,
        target: WheelCommand,
        dt_s: f64,
        damping: f64,
        natural: f64,
    ) -> WheelCommand {
        let n = (dt_s * natural / SECOND_ORDER_STEP).ceil().max(1.0);
        let h = dt_s / n;
        let mut mean = [0.0; 2];
        for (i, u) in [target.left_mps, target.right_mps].into_iter().enumerate() {
            let (mut v, mut a) = (self.speed[i], self.acceleration[i]);
            for _ in 0..n as usize {
                let v0 = v;
                a += (natural * natural * (u - v) - 2.0 * damping * natural * a) * h;
                v += a * h;
                mean[i] += (v0 + v) / 2.0 / n;
            }
            self.speed[i] = v;
            self.acceleration[i] = a;
        }
        WheelCommand {
            left_mps: mean[0],
            right_mps: mean[1],
        }
    }
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
