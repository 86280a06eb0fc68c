//! Small differences between any two simulators, or a simulator and a robot, that no catalogue
//! effect is about. A run draws its own: each is on with probability ½, at a
//! size drawn from a range a real setup shows.

use crate::noise::Stream;

/// The nuisances of one run. `Nuisances::default()` has none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nuisances {
    /// A lidar reading is valid by its true distance, not by the value it reports.
    pub validity_by_true_range: bool,
    /// The unit's real maximum range over the declared one.
    pub max_range_factor: f64,
    /// Correlation of the two encoders' noise.
    pub encoder_correlation: f64,
    /// Relative standard deviation of the wheels' speed around the command.
    pub speed_noise: f64,
    /// Degrees of freedom of the Student-t range noise (0: Gaussian).
    pub tail_dof: f64,
    /// Share of lidar readings that are spurious (uniform over the range).
    pub spurious_share: f64,
    /// Lidar range resolution, metres (the scenario's is 1 mm).
    pub lidar_resolution_m: f64,
    /// Sonar range resolution, metres (0: none).
    pub sonar_resolution_m: f64,
    /// Sonar and encoder rates over the declared ones.
    pub rate_factor: f64,
    /// Phase of the sonar's and the encoders' sampling, seconds.
    pub sample_phase_s: f64,
    /// Share of lidar revolutions dropped whole, and of 4-reading packets dropped.
    pub dropped_revolutions: f64,
    pub dropped_packets: f64,
    /// Standard deviation of timestamp jitter, seconds.
    pub timestamp_jitter_s: f64,
    /// Intensity scale.
    pub intensity_scale: f64,
    /// Truth rate, Hz, and motion-capture noise (metres, radians).
    pub truth_hz: f64,
    pub truth_noise_m: f64,
    pub truth_noise_rad: f64,
    /// Each reading's geometry taken this share of a reading period later than its slot.
    pub reading_phase: f64,
    /// The first wall moved along its normal, and every cylinder's radius changed, metres.
    pub wall_shift_m: f64,
    pub radius_change_m: f64,
}

impl Default for Nuisances {
    fn default() -> Self {
        Self {
            validity_by_true_range: false,
            max_range_factor: 1.0,
            encoder_correlation: 0.0,
            speed_noise: 0.0,
            tail_dof: 0.0,
            spurious_share: 0.0,
            lidar_resolution_m: 0.001,
            sonar_resolution_m: 0.001,
            rate_factor: 1.0,
            sample_phase_s: 0.0,
            dropped_revolutions: 0.0,
            dropped_packets: 0.0,
            timestamp_jitter_s: 0.0,
            intensity_scale: 1.0,
            truth_hz: 100.0,
            truth_noise_m: 0.0,
            truth_noise_rad: 0.0,
            reading_phase: 0.0,
            wall_shift_m: 0.0,
            radius_change_m: 0.0,
        }
    }
}

impl Nuisances {
    /// A run's nuisances: each on with probability ½, its size uniform in the range given
    /// ("a few" mm, ms, packets).
    #[must_use]
    pub fn draw(s: &mut Stream) -> Self {
        let mut n = Self::default();
        let on = |s: &mut Stream| s.chance(0.5);
        if on(s) {
            n.validity_by_true_range = true;
        }
        if on(s) {
            n.max_range_factor = s.between(0.9, 1.1);
        }
        if on(s) {
            n.encoder_correlation = s.between(0.5, 1.0);
        }
        if on(s) {
            n.speed_noise = s.between(0.005, 0.03);
        }
        if on(s) {
            n.tail_dof = s.between(4.0, 10.0).round();
        }
        if on(s) {
            n.spurious_share = s.between(0.0005, 0.003);
        }
        if on(s) {
            n.lidar_resolution_m = if s.chance(0.5) { 0.002 } else { 0.0005 };
        }
        if on(s) {
            n.sonar_resolution_m = if s.chance(0.5) { 0.01 } else { 0.0 };
        }
        if on(s) {
            n.rate_factor = s.between(0.8, 1.25);
            n.sample_phase_s = s.between(0.0, 0.02);
        }
        if on(s) {
            n.dropped_revolutions = s.between(0.0, 0.02);
            n.dropped_packets = s.between(0.0, 0.01);
        }
        if on(s) {
            n.timestamp_jitter_s = s.between(0.0005, 0.003);
        }
        if on(s) {
            n.intensity_scale = s.between(0.3, 3.0);
        }
        if on(s) {
            n.truth_hz = s.between(30.0, 200.0);
            n.truth_noise_m = s.between(0.0, 0.001);
            n.truth_noise_rad = s.between(0.0, 0.002);
        }
        if on(s) {
            n.reading_phase = s.between(-0.5, 0.5);
        }
        if on(s) {
            n.wall_shift_m = s.between(-0.004, 0.004);
            n.radius_change_m = s.between(-0.003, 0.003);
        }
        n
    }
}
