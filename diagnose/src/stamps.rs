//! How well a log's encoder readings are stamped. A delay of the encoders, or a slip that leads
//! their count by `g Δv`, moves each reading by a few tens of milliseconds of the robot's
//! motion; a log whose readings' stamps scatter by more than that about when they were counted
//! (a CARMEN log's `ODOM` lines carry the time IPC delivered them, which goes back and forth by
//! tenths of a second) cannot show such a lead: the speed at each reading, which the lead is
//! told by, is measured through those same stamps, so a fit of the lead is pulled towards zero
//! and its held-out gain is the stamps' noise. Such a lead is "not identifiable from this log".

use hilsim_calibrator::stats::median;
use hilsim_recording::OdometrySample;
use nalgebra::{Matrix3, Vector3};

use crate::catalogue::{Effect, Sensor};

/// Whether `effect` is a lead of the encoders on their count (their delay, or a slip's gain, its
/// mirror), which the scatter of their stamps bounds.
pub(crate) fn is_encoder_lead(effect: Effect) -> bool {
    effect.sensor() == Sensor::Odometer && effect.entry().sized_as_a_delay()
}

/// The readings either side of one that its stamp is judged against: a parabola through four
/// neighbours follows the motion's speed and its change over a few tenths of a second at a
/// logger's 5–10 Hz, with one reading to spare.
const NEIGHBOURS_EACH_SIDE: usize = 2;

/// The least speed at which a reading's stamp is judged, m/s: at rest the travel says nothing
/// of the time (a tenth of the slowest speeds the catalogue's robots drive at, 0.05 m/s, is
/// below an encoder's tick over a reading; a walking pace's fifth is well above it).
const MOVING_MPS: f64 = 0.1;

/// The speed bins the readings' offsets are measured in: an error of the travel (an encoder's
/// noise, a wheel's bump) offsets a reading's time by itself over the speed, a stamp's error by
/// itself at any speed, so the spread in bins of speed tells the two apart.
const SPEED_BINS: usize = 4;

/// The fewest judged readings a scatter is given for: a spread from fewer (ten a bin) is no
/// measure.
const MIN_JUDGED: usize = 10 * SPEED_BINS;

/// 1.4826 × the median absolute deviation is a normal spread's standard deviation.
const MAD_TO_SD: f64 = 1.4826;

/// The scatter of the encoders' stamps, seconds. Each moving reading's stamp is set against the
/// time at which a parabola through its [`NEIGHBOURS_EACH_SIDE`] neighbours either side reaches
/// its travel (the wheels' mean), scaled by the spread its own and its neighbours' errors give
/// it, so that stamps each off by an independent error of standard deviation σ measure σ. That
/// offset also holds the travel's own error over the speed: in [`SPEED_BINS`] bins of speed the
/// offsets' robust spread (1.4826 × the median absolute deviation) is fitted as
/// `σ_t² + σ_x² / v²` by least squares, and the stamps' scatter is `σ_t` (the whole spread
/// when it does not fall with the speed). `None` with fewer than [`MIN_JUDGED`] readings taken
/// while moving.
#[must_use]
pub(crate) fn encoder_scatter_s(samples: &[OdometrySample]) -> Option<f64> {
    let k = NEIGHBOURS_EACH_SIDE;
    if samples.len() < 2 * k + 1 {
        return None;
    }
    let travel = |s: &OdometrySample| 0.5 * (s.left_m + s.right_m);
    // (speed, offset) of each moving reading.
    let mut offsets: Vec<(f64, f64)> = (k..samples.len() - k)
        .filter_map(|i| {
            let t_i = samples[i].t_s;
            let around: Vec<(f64, f64)> = samples[i - k..=i + k]
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != k)
                .map(|(_, s)| (s.t_s - t_i, travel(s)))
                .collect();
            let (at, speed, weights_sq) = parabola(&around)?;
            // The reading's own error and the neighbours' share in the parabola's value, as
            // one stamp's error.
            let offset = (travel(&samples[i]) - at) / -speed / (1.0 + weights_sq).sqrt();
            (speed.abs() >= MOVING_MPS && offset.is_finite()).then_some((speed.abs(), offset))
        })
        .collect();
    if offsets.len() < MIN_JUDGED {
        return None;
    }
    offsets.sort_by(|a, b| a.0.total_cmp(&b.0));
    let per_bin = offsets.len() / SPEED_BINS;
    // (1 / v², the offsets' variance) of each bin.
    let bins: Vec<(f64, f64)> = offsets
        .chunks(per_bin)
        .take(SPEED_BINS)
        .map(|bin| {
            let mut speeds: Vec<f64> = bin.iter().map(|o| o.0).collect();
            let mut times: Vec<f64> = bin.iter().map(|o| o.1).collect();
            let speed = median(&mut speeds);
            let centre = median(&mut times);
            let mut deviations: Vec<f64> = times.iter().map(|o| (o - centre).abs()).collect();
            let sd = MAD_TO_SD * median(&mut deviations);
            (1.0 / (speed * speed), sd * sd)
        })
        .collect();
    let n = bins.len() as f64;
    let mean_x = bins.iter().map(|b| b.0).sum::<f64>() / n;
    let mean_y = bins.iter().map(|b| b.1).sum::<f64>() / n;
    let sxx: f64 = bins.iter().map(|b| (b.0 - mean_x).powi(2)).sum();
    let sxy: f64 = bins.iter().map(|b| (b.0 - mean_x) * (b.1 - mean_y)).sum();
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let stamps_variance = if slope > 0.0 {
        mean_y - slope * mean_x
    } else {
        mean_y
    };
    Some(stamps_variance.max(0.0).sqrt())
}

/// The least-squares parabola through `points` (time from the judged reading, travel): its
/// value and its slope at time 0, and the sum of the squares of the points' weights in that
/// value (the share of one point's error it carries). A parabola, not a line, so that a change
/// of speed within the neighbours is the motion's, not a stamp's error. `None` when the times do
/// not spread.
fn parabola(points: &[(f64, f64)]) -> Option<(f64, f64, f64)> {
    let basis = |t: f64| Vector3::new(1.0, t, t * t);
    let normal: Matrix3<f64> = points
        .iter()
        .map(|&(t, _)| basis(t) * basis(t).transpose())
        .sum();
    let inverse = normal.try_inverse()?;
    let moments: Vector3<f64> = points.iter().map(|&(t, x)| basis(t) * x).sum();
    let coefficients = inverse * moments;
    let weights_sq: f64 = points
        .iter()
        .map(|&(t, _)| (inverse.row(0) * basis(t))[0].powi(2))
        .sum();
    (coefficients.iter().all(|c| c.is_finite()) && weights_sq.is_finite())
        .then(|| (coefficients[0], coefficients[1], weights_sq))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_distr::StandardNormal;
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// A robot whose speed swings between 0.2 and 0.6 m/s every 4 s, read every `step_s`, each
    /// reading stamped `jitter_s` × a standard normal draw off when it was counted.
    fn encoders(step_s: f64, jitter_s: f64) -> Vec<OdometrySample> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let pi = std::f64::consts::PI;
        let travel = |t: f64| 0.4 * t + 0.8 / pi * (pi * t / 4.0).sin();
        (0..(240.0 / step_s) as usize)
            .map(|k| {
                let t = k as f64 * step_s;
                OdometrySample {
                    t_s: t + jitter_s * rng.sample::<f64, _>(StandardNormal),
                    left_m: travel(t),
                    right_m: travel(t),
                }
            })
            .collect()
    }

    /// Clean stamps at 5 Hz scatter by milliseconds (the motion's own changes of speed);
    /// stamps drawn 30 or 80 ms off are measured within 20 % (the tolerance: 1,200 readings
    /// give the median absolute deviation to about 4 %; the rest is the speed's own error in
    /// the neighbours' parabola, left in), seed fixed.
    #[test]
    fn the_scatter_of_jittered_stamps_is_measured_and_clean_ones_have_none() {
        let clean = encoders(0.2, 0.0);
        let scatter = encoder_scatter_s(&clean).expect("moving");
        assert!(scatter < 0.005, "{scatter}");
        for jitter in [0.03, 0.08] {
            let mut jittered = encoders(0.2, jitter);
            jittered.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
            let scatter = encoder_scatter_s(&jittered).expect("moving");
            assert!((scatter / jitter - 1.0).abs() < 0.2, "{jitter}: {scatter}");
        }
    }

    /// Exact stamps at 5 Hz on encoders whose travel carries 3 mm of noise (a foreign
    /// simulator's, a bumpy floor's): the noise offsets each reading by itself over the speed,
    /// which the bins of speed take out, so the stamps scatter by under 5 ms (the tolerance: the
    /// 3 mm over the 0.2–0.6 m/s speeds offsets each reading by 5–15 ms, which must not be read
    /// as the stamps'); with the stamps drawn 40 ms off as well, 40 ms is measured within 25 %
    /// (the first test's tolerance and the bins' fit of two terms from four spreads), seed fixed.
    #[test]
    fn noise_in_the_travel_is_not_read_as_the_stamps_scatter() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let noisy: Vec<OdometrySample> = encoders(0.2, 0.0)
            .into_iter()
            .map(|s| {
                let e: f64 = 0.003 * rng.sample::<f64, _>(StandardNormal);
                OdometrySample {
                    left_m: s.left_m + e,
                    right_m: s.right_m + e,
                    ..s
                }
            })
            .collect();
        let scatter = encoder_scatter_s(&noisy).expect("moving");
        assert!(scatter < 0.005, "{scatter}");
        let mut both = noisy;
        for (s, j) in both.iter_mut().zip(encoders(0.2, 0.04)) {
            s.t_s = j.t_s;
        }
        let scatter = encoder_scatter_s(&both).expect("moving");
        assert!((scatter / 0.04 - 1.0).abs() < 0.25, "{scatter}");
    }

    /// A robot at rest, or too few readings, gives no scatter.
    #[test]
    fn no_scatter_without_motion() {
        let rest: Vec<OdometrySample> = (0..100)
            .map(|k| OdometrySample {
                t_s: f64::from(k) * 0.1,
                left_m: 1.0,
                right_m: 1.0,
            })
            .collect();
        assert_eq!(encoder_scatter_s(&rest), None);
        assert_eq!(encoder_scatter_s(&encoders(0.2, 0.0)[..10]), None);
    }
}
