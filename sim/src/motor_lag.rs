//! `[effects.drive_motor_lag]`: the wheels reach a commanded speed with a first-order lag.
//!
//! A DC drive motor under speed control behaves, to first order, as `τ v̇ + v = u`: the
//! mechanical time constant τ = J R / (k_t k_e) of the armature and load (inertia J, winding
//! resistance R, torque and back-EMF constants k_t, k_e), lengthened by the speed loop's own
//! bandwidth (Franklin, Powell, Emami-Naeini, *Feedback Control of Dynamic Systems*, the DC motor
//! model of ch. 2). A step of the command `u` is approached as `v(t) = u + (v₀ − u) e^{−t/τ}`.
//! The lag has unit gain at rest, so a straight still ends where the program says once the robot
//! has settled; it only arrives later.

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
    speed: [f64; 2],
}

impl MotorLag {
    /// Wheels at rest, lagging with time constant `tau_s` (> 0).
    #[must_use]
    pub fn new(tau_s: f64) -> Self {
        Self {
            tau_s,
            speed: [0.0; 2],
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
