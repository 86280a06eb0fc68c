//! `odometer_wheel_slip`: the wheels slip in proportion to their acceleration.
//!
//! Derivation. At small slip a wheel's traction force grows linearly with its slip, the linear
//! region of the traction–slip curve (Wong, *Theory of Ground Vehicles*, ch. 1-2); at the low
//! speeds of an indoor robot the slip is best measured as a velocity, `F = C v_slip`. The force
//! that accelerates the robot is `F = m a`, so `v_slip = (m / C) a = g a` with the gain g in
//! seconds: the wheel turns faster than the ground passes while the robot speeds up and slower
//! while it brakes. Integrated, the slip distance is `g (v − v₀)`: the encoders lead the true
//! travel by `g v` while the wheel moves at v and agree again at rest.
//!
//! Driving and braking are not the same contact. A driven wheel pushes through its tread while a
//! braked one drags it, the traction–slip curve is steeper on one side than the other (Wong,
//! ch. 1, the braking skid `i_s` beside the driving slip `i`), and a motor controller may brake
//! by coasting: the gain while braking, `g_b`, is the unit's own. With `S_b` the wheel's changes
//! of speed while braking summed since rest, the slip distance is
//! `g (v − S_b) + g_b S_b = g v + (g_b − g) S_b`: equal gains give back on braking what was led
//! on speeding up; `g_b = 0` slips only while speeding up; `g_b = −g` gains `g |Δv|` at every
//! change of speed.

use hilsim_sim::scenario::OdometerWheelSlip;

/// The part of a wheel's change of speed from `from_mps` to `to_mps` that is braking (its
/// speed's magnitude falling), signed as the change: all of it when the speed falls towards
/// rest, none when it grows, and the fall to rest when it reverses.
///
/// ```
/// use hilsim_lidar_emulator::effects::braking_change_mps;
/// assert_eq!(braking_change_mps(0.5, 0.25), -0.25);
/// assert_eq!(braking_change_mps(0.25, 0.5), 0.0);
/// assert_eq!(braking_change_mps(-0.5, -0.25), 0.25);
/// assert_eq!(braking_change_mps(0.25, -0.125), -0.25);
/// ```
#[must_use]
pub fn braking_change_mps(from_mps: f64, to_mps: f64) -> f64 {
    if from_mps * to_mps < 0.0 {
        -from_mps
    } else if to_mps.abs() < from_mps.abs() {
        to_mps - from_mps
    } else {
        0.0
    }
}

/// The encoder's extra travel `g v + (g_b − g) S_b`, metres, of a wheel moving at
/// `wheel_speed_mps` after starting from rest, `braking_mps` its changes of speed while braking
/// summed since ([`braking_change_mps`]).
///
/// ```
/// use hilsim_lidar_emulator::effects::slip_travel_m;
/// use hilsim_sim::scenario::OdometerWheelSlip;
/// let even = OdometerWheelSlip { gain_s: 0.05, braking_gain_s: None };
/// assert!((slip_travel_m(&even, 0.3, -0.1) - 0.015).abs() < 1e-15);
/// // Up to 0.4 m/s, braked to 0.3 m/s: slipping only while speeding up, the encoders keep the
/// // 0.4 m/s's lead.
/// let driving = OdometerWheelSlip { gain_s: 0.05, braking_gain_s: Some(0.0) };
/// assert!((slip_travel_m(&driving, 0.3, -0.1) - 0.02).abs() < 1e-15);
/// ```
#[must_use]
pub fn slip_travel_m(slip: &OdometerWheelSlip, wheel_speed_mps: f64, braking_mps: f64) -> f64 {
    // Even gains add exactly nothing for the braking: `g v` as the first-order model.
    slip.gain_s * wheel_speed_mps + (slip.braking_gain() - slip.gain_s) * braking_mps
}
