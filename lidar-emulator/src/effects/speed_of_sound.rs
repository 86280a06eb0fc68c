//! `sonar_speed_of_sound`: the air's temperature scales every sonar range.
//!
//! A sonar measures the echo's round-trip time `t = 2 d / c_air` and converts it with the speed
//! of sound it was calibrated for, reporting `c_cal t / 2 = d c_cal / c_air`. The speed of sound
//! in dry air, an ideal gas, grows with the square root of the absolute temperature:
//! `c(T) = 331.3 √(1 + T / 273.15)` m/s, T in °C (331.3 m/s at 0 °C; e.g. Kinsler, Frey et al.,
//! *Fundamentals of Acoustics*). A sonar calibrated at 20 °C (343.2 m/s) reads 3.6 % long in air
//! at 0 °C.

/// The speed of sound in dry air at `celsius`, m/s.
///
/// ```
/// use hilsim_lidar_emulator::effects::speed_of_sound_mps;
/// assert!((speed_of_sound_mps(0.0) - 331.3).abs() < 1e-12);
/// assert!((speed_of_sound_mps(20.0) - 343.2).abs() < 0.05);
/// ```
#[must_use]
pub fn speed_of_sound_mps(celsius: f64) -> f64 {
    331.3 * (1.0 + celsius / 273.15).sqrt()
}

/// The factor `c(calibrated_at_c) / c(air_temperature_c)` by which every range is scaled.
#[must_use]
pub fn sonar_range_scale(air_temperature_c: f64, calibrated_at_c: f64) -> f64 {
    speed_of_sound_mps(calibrated_at_c) / speed_of_sound_mps(air_temperature_c)
}
