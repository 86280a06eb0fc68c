//! `odometer_wheel_slip`: the wheels slip in proportion to their acceleration.
//!
//! Derivation. At small slip a wheel's traction force grows linearly with its slip, the linear
//! region of the traction–slip curve (Wong, *Theory of Ground Vehicles*, ch. 1-2); at the low
//! speeds of an indoor robot the slip is best measured as a velocity, `F = C v_slip`. The force
//! that accelerates the robot is `F = m a`, so `v_slip = (m / C) a = g a` with the gain g in
//! seconds: the wheel turns faster than the ground passes while the robot speeds up and slower
//! while it brakes. Integrated, the slip distance is `g (v − v₀)`: the encoders lead the true
//! travel by `g v` while the wheel moves at v and agree again at rest.

/// The encoder's extra travel `g v`, metres, of a wheel moving at `wheel_speed_mps` after starting
/// from rest.
///
/// ```
/// use hilsim_lidar_emulator::effects::slip_travel_m;
/// assert!((slip_travel_m(0.05, 0.3) - 0.015).abs() < 1e-15);
/// ```
#[must_use]
pub fn slip_travel_m(gain_s: f64, wheel_speed_mps: f64) -> f64 {
    gain_s * wheel_speed_mps
}
