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

/// Over how long a wheel's speed is measured from its encoder, at least: a few of a log's
/// odometry samples (5–50 Hz), so that its counts' quantum does not read as changes of speed,
/// and two of a logger's bursts of stamps (every half second), within the second over which an
/// indoor robot changes its speed (0.3 m/s at 0.5 m/s² takes 0.6 s).
pub(crate) const WHEEL_SPEED_SPAN_S: f64 = 1.0;

/// How long a logger may fall silent for the wheels' speed to be followed through the gap (from
/// the samples either side), seconds: a sparse truth's longest span (`wheel_spans`). A longer
/// silence is a pause.
const SILENCE_S: f64 = 10.0;

/// The times every `step_s` from `odometry`'s first stamp at which the wheels' speed is taken
/// ([`wheel_speeds`]) to follow its changes: those within half [`WHEEL_SPEED_SPAN_S`] of a
/// sample or within a gap between samples of up to [`SILENCE_S`]. Across a longer gap the
/// logger paused, and a speed there is no measure; so their number stays within a few dozen per
/// sample whatever time the stamps span.
pub(crate) fn speed_times(odometry: &[OdometrySample], step_s: f64) -> Vec<f64> {
    let Some(first) = odometry.first() else {
        return Vec::new();
    };
    if !(step_s > 0.0 && step_s.is_finite()) {
        return Vec::new();
    }
    let half = 0.5 * WHEEL_SPEED_SPAN_S;
    let index = |t: f64| (t - first.t_s) / step_s;
    let mut times = Vec::new();
    // The next grid index not yet taken.
    let mut next = 0.0_f64;
    for (i, s) in odometry.iter().enumerate() {
        let lo = index(s.t_s - half).ceil().max(next);
        let reach = match odometry.get(i + 1) {
            Some(after) if after.t_s - s.t_s <= SILENCE_S => after.t_s.max(s.t_s + half),
            _ => s.t_s + half,
        };
        let hi = index(reach).floor();
        let mut k = lo;
        while k <= hi {
            times.push(first.t_s + k * step_s);
            k += 1.0;
        }
        next = next.max(hi + 1.0);
    }
    times
}

/// `values` (one per of `times`, in order) at `t_s`, linearly between their times: the first's
/// before them is none, the last's after them its own.
pub(crate) fn pair_at(times: &[f64], values: &[[f64; 2]], t_s: f64) -> [f64; 2] {
    let k = times.partition_point(|&t| t <= t_s);
    match (k.checked_sub(1), times.get(k), values.get(k)) {
        (None, ..) => [0.0; 2],
        (Some(i), Some(&next), Some(b)) => {
            let u = (t_s - times[i]) / (next - times[i]);
            let a = values[i];
            [a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])]
        }
        (Some(i), ..) => values.get(i).copied().unwrap_or([0.0; 2]),
    }
}

/// The share of a wheel's travel over a span that its stamps must explain (the squared
/// correlation) for the travel's own slope to be corrected for their scatter in full; below it
/// the correction is held at what it is here (twice the slope), so that a wheel that turns
/// back within the span, whose travel follows no slope, reads no speed beyond its travel's.
const WHEEL_SPEED_LEAST_FIT: f64 = 0.5;

/// The wheels' speeds `[left, right]` at time `t_s`, m/s: each wheel's travel against the
/// stamps over the samples from the last stamped more than half [`WHEEL_SPEED_SPAN_S`] before
/// `t_s` to the first stamped more than half after it (the log's first or last where none is);
/// 0 where the wheel did not move. The least-squares slope of the travel in the stamps, divided
/// by the squared correlation of the two (at least [`WHEEL_SPEED_LEAST_FIT`]): that is the
/// inverse of the stamps' slope in the travel, which an error of the stamps leaves without
/// bias, where the travel's slope in the stamps shrinks by that share. A logger that stamps its
/// samples as they arrive stamps them in bursts (the Intel lab's: several within a millisecond,
/// then none for half a second), so the error is in the stamps; two samples' travel over their
/// time apart is no speed there at all. `odometry` in time order.
pub(crate) fn wheel_speeds(odometry: &[OdometrySample], t_s: f64) -> [f64; 2] {
    let half = 0.5 * WHEEL_SPEED_SPAN_S;
    let first = odometry
        .partition_point(|s| s.t_s < t_s - half)
        .saturating_sub(1);
    let last = odometry
        .partition_point(|s| s.t_s <= t_s + half)
        .min(odometry.len().saturating_sub(1));
    let Some(window) = odometry.get(first..=last) else {
        return [0.0; 2];
    };
    let n = window.len() as f64;
    let t_mean = window.iter().map(|s| s.t_s).sum::<f64>() / n;
    let time_spread: f64 = window.iter().map(|s| (s.t_s - t_mean).powi(2)).sum();
    let speed = |x: fn(&OdometrySample) -> f64| {
        let x_mean = window.iter().map(x).sum::<f64>() / n;
        let (spread, with_time, lo, hi) = window.iter().fold(
            (0.0, 0.0, f64::INFINITY, f64::NEG_INFINITY),
            |(xx, xt, lo, hi), s| {
                let dx = x(s) - x_mean;
                (
                    xx + dx * dx,
                    xt + dx * (s.t_s - t_mean),
                    lo.min(x(s)),
                    hi.max(x(s)),
                )
            },
        );
        // None when the wheel stood (its travel the same to a micrometre: the mean's rounding
        // is no motion) or the stamps do not spread.
        if hi - lo <= 1e-6 || time_spread <= 0.0 {
            return 0.0;
        }
        let explained = with_time * with_time / (spread * time_spread);
        with_time / time_spread / explained.max(WHEEL_SPEED_LEAST_FIT)
    };
    [speed(|s| s.left_m), speed(|s| s.right_m)]
}

/// The share of a log's readings that, stamped within a tenth of the mean time between readings
/// of the one before, mark its stamps as their arrivals in bursts rather than when they counted:
/// a tenth of them. The Intel lab's CARMEN log has a third of its readings within 21 ms of the
/// one before (five readings a second on average); a logger that stamps when it reads has none.
const BURST_SHARE: f64 = 0.1;

/// Whether `odometry`'s stamps are their arrivals in bursts ([`BURST_SHARE`]): several readings
/// stamped together, then none for a while. A parabola through a reading's neighbours (the
/// scatter's measure, [`encoder_scatter_s`]) sees a burst's readings as one motion's.
pub(crate) fn stamped_in_bursts(odometry: &[OdometrySample]) -> bool {
    let (Some(first), Some(last)) = (odometry.first(), odometry.last()) else {
        return false;
    };
    let gaps = odometry.len() - 1;
    if gaps < 2 {
        return false;
    }
    let mean_gap_s = (last.t_s - first.t_s) / gaps as f64;
    let together = odometry
        .windows(2)
        .filter(|w| w[1].t_s - w[0].t_s < 0.1 * mean_gap_s)
        .count();
    together as f64 >= BURST_SHARE * gaps as f64
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

    /// The speed's times follow the samples: every step within half a speed's span of one or
    /// through a short gap, none across a logger's pause, however long (a day here: five, not
    /// 350,000).
    #[test]
    fn the_speeds_times_skip_a_silence_however_long() {
        let at = |t_s: f64| OdometrySample {
            t_s,
            left_m: 0.0,
            right_m: 0.0,
        };
        let times = speed_times(&[at(10.0), at(10.2), at(86_410.0)], 0.25);
        assert_eq!(
            times,
            vec![10.0, 10.25, 10.5, 86_409.5, 86_409.75, 86_410.0, 86_410.25, 86_410.5]
        );
        assert!(speed_times(&[at(0.0)], 0.0).is_empty());
        let values = [[0.0, 2.0], [1.0, 4.0]];
        assert_eq!(pair_at(&[1.0, 2.0], &values, 1.5), [0.5, 3.0]);
        assert_eq!(pair_at(&[1.0, 2.0], &values, 0.5), [0.0, 0.0]);
        assert_eq!(pair_at(&[1.0, 2.0], &values, 9.0), [1.0, 4.0]);
    }

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
