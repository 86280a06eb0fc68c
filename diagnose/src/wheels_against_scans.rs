//! The encoders against the path matched from the lidar's own scans, span by span: the lidar's
//! delay against them, the wheels' effective base and their sizes. It is the odometry and
//! sensor calibration of Censi et al. ("Simultaneous calibration of odometry and sensor
//! parameters for mobile robots", IEEE T-RO 29(2), 2013), with the scan matcher's path for
//! their scan-to-scan displacements, and their latency beside it.
//!
//! Each span of the path (half a second or more) turns by as much as the wheels' travel apart
//! over the declared base `b`. As travel apart, its turn is `s·Δ + c·f`, where `Δ` and `f` are
//! the encoders' travel apart and mean travel over the same span δ earlier. With the wheels'
//! true travel their reported one times `m ∓ d` (left, right) and their contact points `B`
//! apart: `s = m b / B` and `c = 2 d b / B`, while the span's travel along the path is `m·f`.
//! So the wheels' mean size is the path's travel over the encoders', the base `B / b = m / s`,
//! and their sizes apart come from the turn that follows the travel (which is then read as
//! neither a base nor a delay).
//!
//! A lidar stamped δ late puts each heading of the path δ after the robot had it. Turns are what
//! a scan match measures best (a milliradian from a few walls) and what a skid spoils least in
//! timing: a skid changes how far the robot turns for the encoders' count, not when. So δ is
//! the minimum of the turn's profile (`s` and `c` refitted at every δ) on the training spans.
//! Every fit is robust (Huber weights, in the spans' own noise: the median absolute deviation
//! on the training spans), and each quantity is scored by its gain over its absence on the
//! held-out spans: a pseudo log-likelihood with Huber's loss, as for a mount read from the
//! path's sideways motion (`crab.rs`).

use hilsim_calibrator::stats::median;
use hilsim_recording::OdometrySample;

use crate::trajectory::{wrap, Trajectory};

/// A span's least duration, seconds: long enough that the matches' heading error at its ends
/// (about a milliradian) is small beside the turn a delay of a tenth of a second moves across
/// it, short enough that the turn rate changes within it (that change is what shows a delay).
const SPAN_S: f64 = 0.5;
/// A span longer than this many [`SPAN_S`] bridges scans that were not matched; not used.
const MAX_SPAN_MULTIPLE: f64 = 2.0;
/// Consecutive spans of one block; blocks alternate between the training and the held-out
/// halves (a turn lasts seconds, and its spans share its skid).
const BLOCK_SPANS: usize = 4;
/// The delay profile's grid step, seconds (a quarter of the catalogue's least delay drawn).
const GRID_STEP_S: f64 = 0.005;
/// Huber's k, in an equation's noise.
const HUBER_K: f64 = 2.0;
/// Fewest spans in each half.
const MIN_SPANS: usize = 20;
/// Iteratively reweighted fits.
const ITERATIONS: usize = 6;
/// How many standard errors from its absence a quantity must lie to be told from it: 3, as
/// the halves of a log are compared.
const MIN_SD: f64 = 3.0;
/// The median absolute deviation of a Gaussian over its standard deviation.
const MAD_PER_SD: f64 = 0.674_489_750_196_081_7;

/// One quantity read from the spans, and what it explains.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Reading {
    /// Its parameters, as its catalogue entry has them.
    pub value: Vec<f64>,
    /// Their standard errors.
    pub sd: Vec<f64>,
    /// The pseudo log-likelihood gain over its absence on the training spans, nats.
    pub train_gain: f64,
    /// The same on the held-out spans: the score.
    pub heldout_gain: f64,
    /// Held-out RMS of the spans' residual, without and with it, metres: their turn as travel
    /// apart for the delay and the base, their travel for the radii.
    pub rmse_before_m: f64,
    pub rmse_after_m: f64,
    /// That residual's noise, metres.
    pub noise_m: f64,
    /// Whether it lies [`MIN_SD`] standard errors from its absence in what the spans pin: the
    /// radii's mean or their difference, each known to its own error (the difference from
    /// the turn, far better than the mean from the travel).
    pub departs: bool,
}

impl Reading {
    /// `value` (its errors `sd`), scored by what it adds over its absence (`gain`) in an
    /// equation of noise `noise_m`.
    fn new(value: Vec<f64>, sd: Vec<f64>, gain: &Gain, noise_m: f64, departs: bool) -> Self {
        Reading {
            value,
            sd,
            train_gain: gain.train,
            heldout_gain: gain.held,
            rmse_before_m: gain.rmse_before_m,
            rmse_after_m: gain.rmse_after_m,
            noise_m,
            departs,
        }
    }
}

/// What the spans show of the encoders against the lidar's path.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Spans {
    /// How late the lidar's stamps are against the encoders', seconds (absent: 0).
    pub delay_s: Reading,
    /// The wheels' contact points apart over the declared base (absent: 1).
    pub base_scale: Reading,
    /// Each wheel's true travel over its reported one, left and right (absent: 1, 1).
    pub radius_scales: Reading,
    /// Spans in each half.
    pub train_n: usize,
    pub heldout_n: usize,
}

/// One span of the path: its ends' stamps, its turn as the wheels' travel apart, its travel
/// along the heading, and its half.
#[derive(Debug, Clone, Copy)]
struct Span {
    from_s: f64,
    to_s: f64,
    turn_m: f64,
    forward_m: f64,
    held_out: bool,
}

/// The encoders' travel apart (right less left) and mean travel over each span, its stamps
/// moved `delay_s` earlier; linear between readings.
fn encoder_travel(odometry: &[OdometrySample], spans: &[Span], delay_s: f64) -> Vec<[f64; 2]> {
    let at = |t: f64| -> [f64; 2] {
        let k = odometry
            .partition_point(|o| o.t_s <= t)
            .clamp(1, odometry.len() - 1);
        let (a, b) = (&odometry[k - 1], &odometry[k]);
        let dt = b.t_s - a.t_s;
        let u = if dt > 0.0 {
            ((t - a.t_s) / dt).clamp(0.0, 1.0)
        } else {
            1.0
        };
        [
            a.left_m + u * (b.left_m - a.left_m),
            a.right_m + u * (b.right_m - a.right_m),
        ]
    };
    spans
        .iter()
        .map(|s| {
            let (a, b) = (at(s.from_s - delay_s), at(s.to_s - delay_s));
            let (left, right) = (b[0] - a[0], b[1] - a[1]);
            [right - left, 0.5 * (right + left)]
        })
        .collect()
}

/// The path's spans of at least [`SPAN_S`], whose ends lie within the encoders' readings
/// under every delay in `delays` (so each delay is judged on the same spans). A span's travel
/// is each step's along the heading halfway through it (a chord of an arc lies along it), so
/// that a robot that backs up travels less.
fn spans(
    path: &Trajectory,
    wheel_base_m: f64,
    odometry: &[OdometrySample],
    delays: (f64, f64),
) -> Vec<Span> {
    let (times, poses) = (path.times(), path.poses());
    let (first, last) = match (odometry.first(), odometry.last()) {
        (Some(a), Some(b)) => (a.t_s, b.t_s),
        _ => return Vec::new(),
    };
    let mut out = Vec::new();
    let mut start = 0;
    let (mut turn, mut forward) = (0.0, 0.0);
    for k in 1..times.len() {
        let (a, b) = (poses[k - 1], poses[k]);
        let step_turn = wrap(b.yaw - a.yaw);
        let (sin, cos) = (a.yaw + 0.5 * step_turn).sin_cos();
        turn += step_turn;
        forward += (b.x - a.x) * cos + (b.y - a.y) * sin;
        let duration = times[k] - times[start];
        if duration < SPAN_S {
            continue;
        }
        let (from_s, to_s) = (times[start], times[k]);
        if duration <= MAX_SPAN_MULTIPLE * SPAN_S
            && from_s - delays.1 >= first
            && to_s - delays.0 <= last
        {
            out.push(Span {
                from_s,
                to_s,
                turn_m: turn * wheel_base_m,
                forward_m: forward,
                held_out: false,
            });
        }
        start = k;
        (turn, forward) = (0.0, 0.0);
    }
    for (i, s) in out.iter_mut().enumerate() {
        s.held_out = (i / BLOCK_SPANS) % 2 == 1;
    }
    out
}

/// A linear fit `y ≈ coef · x` of two regressors, each free or held at a value.
#[derive(Debug, Clone, Copy)]
struct Linear {
    coef: [f64; 2],
}

impl Linear {
    fn residuals(&self, y: &[f64], x: &[[f64; 2]]) -> Vec<f64> {
        y.iter()
            .zip(x)
            .map(|(y, x)| y - self.coef[0] * x[0] - self.coef[1] * x[1])
            .collect()
    }
}

/// `y ≈ coef · x` by robust least squares (Huber weights in `noise`), the coefficients held
/// where `held` gives them.
fn robust_fit(y: &[f64], x: &[[f64; 2]], noise: f64, held: [Option<f64>; 2]) -> Linear {
    let mut fit = Linear {
        coef: [held[0].unwrap_or(1.0), held[1].unwrap_or(0.0)],
    };
    for _ in 0..ITERATIONS {
        let r = fit.residuals(y, x);
        let (mut a, mut b) = ([[0.0; 2]; 2], [0.0; 2]);
        for ((y, x), r) in y.iter().zip(x).zip(&r) {
            let z = (r / noise).abs();
            let w = if z <= HUBER_K { 1.0 } else { HUBER_K / z };
            // What the held coefficients explain is taken off first.
            let free_y = y
                - (0..2)
                    .filter_map(|i| held[i].map(|h| h * x[i]))
                    .sum::<f64>();
            for i in 0..2 {
                b[i] += w * x[i] * free_y;
                for j in 0..2 {
                    a[i][j] += w * x[i] * x[j];
                }
            }
        }
        let free: Vec<usize> = (0..2).filter(|&i| held[i].is_none()).collect();
        match free.as_slice() {
            [i] => {
                if a[*i][*i] <= 0.0 {
                    break;
                }
                fit.coef[*i] = b[*i] / a[*i][*i];
            }
            [_, _] => {
                let det = a[0][0] * a[1][1] - a[0][1] * a[0][1];
                if det.abs() <= f64::EPSILON * (a[0][0] * a[1][1]).abs().max(f64::MIN_POSITIVE) {
                    break;
                }
                fit.coef = [
                    (b[0] * a[1][1] - b[1] * a[0][1]) / det,
                    (a[0][0] * b[1] - a[0][1] * b[0]) / det,
                ];
            }
            _ => break,
        }
    }
    fit
}

fn robust_noise(residuals: &[f64]) -> f64 {
    let mut deviations: Vec<f64> = residuals.iter().map(|r| r.abs()).collect();
    (median(&mut deviations) / MAD_PER_SD).max(1e-9)
}

/// The noise of `y ≈ coef · x`, refined with the fit it weights.
fn own_noise(y: &[f64], x: &[[f64; 2]], held: [Option<f64>; 2]) -> f64 {
    let mut noise = 1.0;
    for _ in 0..4 {
        noise = robust_noise(&robust_fit(y, x, noise, held).residuals(y, x));
    }
    noise
}

fn loss(residuals: &[f64], noise: f64) -> f64 {
    residuals
        .iter()
        .map(|r| crate::stats::huber(r / noise, HUBER_K))
        .sum()
}

fn rms(residuals: &[f64]) -> f64 {
    (residuals.iter().map(|v| v * v).sum::<f64>() / residuals.len().max(1) as f64).sqrt()
}

/// One equation's training and held-out data at one delay.
struct Equation {
    train: (Vec<f64>, Vec<[f64; 2]>),
    held: (Vec<f64>, Vec<[f64; 2]>),
}

/// What a model adds over another, each trained on the training spans of its equation (the
/// same spans, at its own delay): its gains on either half in `noise`, and the held-out RMS
/// without and with it.
struct Gain {
    train: f64,
    held: f64,
    rmse_before_m: f64,
    rmse_after_m: f64,
}

impl Gain {
    fn of(without: (&Equation, &Linear), with: (&Equation, &Linear), noise: f64) -> Self {
        let r = |(e, fit): (&Equation, &Linear)| {
            (
                fit.residuals(&e.train.0, &e.train.1),
                fit.residuals(&e.held.0, &e.held.1),
            )
        };
        let ((train_0, held_0), (train_1, held_1)) = (r(without), r(with));
        Gain {
            train: loss(&train_0, noise) - loss(&train_1, noise),
            held: loss(&held_0, noise) - loss(&held_1, noise),
            rmse_before_m: rms(&held_0),
            rmse_after_m: rms(&held_1),
        }
    }
}

impl Equation {
    fn fit(&self, noise: f64, held: [Option<f64>; 2]) -> Linear {
        robust_fit(&self.train.0, &self.train.1, noise, held)
    }

    /// The free coefficients' standard errors by the delete-a-block jackknife over the
    /// training spans' blocks of [`BLOCK_SPANS`] (Künsch, "The jackknife and the bootstrap for
    /// general stationary observations", Ann. Stat. 17(3), 1989): a skid shared by a turn's
    /// spans, and spans noisier in turns than on straights, leave the least-squares errors too
    /// small, which a block of spans left out at a time does not.
    fn block_jackknife_sd(&self, noise: f64) -> [f64; 2] {
        let (y, x) = &self.train;
        let blocks = y.len().div_ceil(BLOCK_SPANS);
        if blocks < 2 {
            return [f64::INFINITY; 2];
        }
        let without: Vec<[f64; 2]> = (0..blocks)
            .map(|b| {
                let keep = |i: &usize| i / BLOCK_SPANS != b;
                let y: Vec<f64> = (0..y.len()).filter(keep).map(|i| y[i]).collect();
                let x: Vec<[f64; 2]> = (0..x.len()).filter(keep).map(|i| x[i]).collect();
                robust_fit(&y, &x, noise, [None, None]).coef
            })
            .collect();
        let n = blocks as f64;
        [0, 1].map(|j| {
            let mean = without.iter().map(|c| c[j]).sum::<f64>() / n;
            let spread: f64 = without.iter().map(|c| (c[j] - mean).powi(2)).sum();
            ((n - 1.0) / n * spread).sqrt()
        })
    }
}

/// The lidar's delay against `odometry` (searched over `delays`, seconds), the wheels' base and
/// their sizes, as the spans of `path` (matched from the lidar's scans, the robot's
/// heading through the declared mount) show them; `None` with too few spans in either half.
pub(crate) fn fit(
    path: &Trajectory,
    wheel_base_m: f64,
    odometry: &[OdometrySample],
    delays: (f64, f64),
) -> Option<Spans> {
    let usable = wheel_base_m > 0.0 && delays.1 > delays.0;
    if odometry.len() < 2 || !usable {
        return None;
    }
    let all = spans(path, wheel_base_m, odometry, delays);
    let train: Vec<Span> = all.iter().filter(|s| !s.held_out).copied().collect();
    let held: Vec<Span> = all.iter().filter(|s| s.held_out).copied().collect();
    if train.len() < MIN_SPANS || held.len() < MIN_SPANS {
        return None;
    }
    let turns = |spans: &[Span]| spans.iter().map(|s| s.turn_m).collect::<Vec<f64>>();
    // The turn equation `s·Δ + c·f` and the travel equation `k·f`, at a delay.
    let turn_at = |delay_s: f64| Equation {
        train: (turns(&train), encoder_travel(odometry, &train, delay_s)),
        held: (turns(&held), encoder_travel(odometry, &held, delay_s)),
    };
    let free = [None, None];
    let steps = ((delays.1 - delays.0) / GRID_STEP_S).round().max(1.0) as usize;
    let grid: Vec<f64> = (0..=steps)
        .map(|j| delays.0 + (delays.1 - delays.0) * j as f64 / steps as f64)
        .collect();
    let turn_train: Vec<Vec<[f64; 2]>> = grid
        .iter()
        .map(|&d| encoder_travel(odometry, &train, d))
        .collect();
    let y = turns(&train);
    // The profile's minimum in a fixed noise: first the noise under no delay, then under the
    // delay that one finds, so the loss is compared across delays in one scale.
    let profile = |noise: f64| -> Vec<f64> {
        turn_train
            .iter()
            .map(|x| loss(&robust_fit(&y, x, noise, free).residuals(&y, x), noise))
            .collect()
    };
    let argmin = |p: &[f64]| {
        p.iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map_or(0, |(j, _)| j)
    };
    let first = argmin(&profile(own_noise(&y, &turn_train[0], free)));
    let turn_noise = own_noise(&y, &turn_train[first], free);
    let p = profile(turn_noise);
    let j = argmin(&p);
    // A parabola through the minimum and its neighbours: the delay between grid points, and
    // the curvature its standard error comes from (the loss is a negative log-likelihood).
    let (delay_s, curvature) = if j > 0 && j + 1 < p.len() {
        let (a, b, c) = (p[j - 1], p[j], p[j + 1]);
        let bend = a - 2.0 * b + c;
        let shift = if bend > 0.0 {
            0.5 * (a - c) / bend
        } else {
            0.0
        };
        (
            grid[j] + shift * GRID_STEP_S,
            bend / (GRID_STEP_S * GRID_STEP_S),
        )
    } else {
        (grid[j], f64::NAN)
    };
    let delay_sd_s = if curvature > 0.0 {
        curvature.recip().sqrt()
    } else {
        f64::INFINITY
    };
    let (turn, on_time) = (turn_at(delay_s), turn_at(delays.0));
    let full_turn = turn.fit(turn_noise, free);
    let [s, c] = full_turn.coef;
    let [s_sd, c_sd] = turn.block_jackknife_sd(turn_noise);
    // The path's travel over the encoders' (`m`), as the ratio of their sums: over every span
    // for its value, over the training spans for its gain. A span's travel departs from the
    // encoders' by a skid that does not cancel between neighbours (the rover's spans: 39 mm
    // each, their correlation −0.09), so its error is that noise over the root of the spans.
    let ratio = |spans: &[Span]| {
        let encoders_m: f64 = encoder_travel(odometry, spans, delay_s)
            .iter()
            .map(|t| t[1])
            .sum();
        let path_m: f64 = spans.iter().map(|s| s.forward_m).sum();
        (encoders_m.abs() > 0.0 && path_m / encoders_m > 0.0)
            .then(|| (path_m / encoders_m, encoders_m))
    };
    let (m, encoders_m) = ratio(&all)?;
    let m_train = ratio(&train).map_or(m, |(m, _)| m);
    let travel_of = |spans: &[Span]| -> (Vec<f64>, Vec<[f64; 2]>) {
        (
            spans.iter().map(|s| s.forward_m).collect(),
            encoder_travel(odometry, spans, delay_s)
                .iter()
                .map(|t| [t[1], 0.0])
                .collect(),
        )
    };
    let travel = Equation {
        train: travel_of(&train),
        held: travel_of(&held),
    };
    let travel_noise = robust_noise(
        &Linear {
            coef: [m_train, 0.0],
        }
        .residuals(&travel.train.0, &travel.train.1),
    );
    let m_sd = travel_noise * (all.len() as f64).sqrt() / encoders_m.abs();
    // The delay: its gain over no delay, the wheels' coefficients refitted at either.
    let delay = {
        let gain = Gain::of(
            (&on_time, &on_time.fit(turn_noise, free)),
            (&turn, &full_turn),
            turn_noise,
        );
        let departs = delay_s > MIN_SD * delay_sd_s;
        Reading::new(vec![delay_s], vec![delay_sd_s], &gain, turn_noise, departs)
    };
    // The base: B / b = m / s, against the turn with s held at m.
    let base = {
        let declared = turn.fit(turn_noise, [Some(m), None]);
        let gain = Gain::of((&turn, &declared), (&turn, &full_turn), turn_noise);
        let scale = m / s;
        let sd = scale * ((s_sd / s).powi(2) + (m_sd / m).powi(2)).sqrt();
        let departs = (scale - 1.0).abs() > MIN_SD * sd;
        Reading::new(vec![scale], vec![sd], &gain, turn_noise, departs)
    };
    // The radii: their mean m against the travel at 1, and their difference d = c m / (2 s)
    // against the turn with c held at 0.
    let radii = {
        let mean = Gain::of(
            (&travel, &Linear { coef: [1.0, 0.0] }),
            (
                &travel,
                &Linear {
                    coef: [m_train, 0.0],
                },
            ),
            travel_noise,
        );
        let apart = Gain::of(
            (&turn, &turn.fit(turn_noise, [None, Some(0.0)])),
            (&turn, &full_turn),
            turn_noise,
        );
        let d = c * m / (2.0 * s);
        let d_sd = c_sd * m / (2.0 * s).abs();
        let sd = m_sd.hypot(d_sd);
        // Scored on both equations, sized on the travel's.
        let gain = Gain {
            train: mean.train + apart.train,
            held: mean.held + apart.held,
            ..mean
        };
        let departs = (m - 1.0).abs() > MIN_SD * m_sd || d.abs() > MIN_SD * d_sd;
        Reading::new(
            vec![m - d, m + d],
            vec![sd, sd],
            &gain,
            travel_noise,
            departs,
        )
    };
    Some(Spans {
        delay_s: delay,
        base_scale: base,
        radius_scales: radii,
        train_n: train.len(),
        heldout_n: held.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use hilsim_recording::TruthSample;

    const WHEEL_BASE_M: f64 = 0.33;

    /// A robot weaving at 0.5 m/s for 90 s (its turn rate two sines, up to 1.1 rad/s), its
    /// encoders read at 50 Hz from wheels 8 % farther apart than declared, the left one
    /// reporting 1 % more than it travels and the right one 1 % less, and the path matched from
    /// its lidar at 10 Hz with 3 mm of noise on each position and 1.2 mrad on each heading (the
    /// rover's own matches': a fixed pseudo-random sequence), the lidar's stamps `delay_s`
    /// late.
    fn weaving(delay_s: f64) -> (Trajectory, Vec<OdometrySample>) {
        let rate = |t: f64| 0.8 * (0.7 * t).sin() + 0.3 * (1.9 * t).sin();
        let dt = 0.002;
        let (mut x, mut y, mut heading) = (0.0_f64, 0.0_f64, 0.0_f64);
        let (mut left, mut right) = (0.0, 0.0);
        let mut poses = Vec::new();
        let mut odometry = Vec::new();
        let mut state = 99_u64;
        let mut noise = |sd: f64| {
            // A linear congruential sequence, uniform with standard deviation `sd`.
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * 3f64.sqrt() * sd
        };
        for i in 0..45_000 {
            let t = f64::from(i) * dt;
            if i % 50 == 0 {
                poses.push((t, x, y, heading));
            }
            if i % 10 == 0 {
                odometry.push(OdometrySample {
                    t_s: t,
                    left_m: left * 1.01,
                    right_m: right * 0.99,
                });
            }
            let turn = rate(t) * dt;
            heading += turn;
            x += 0.5 * dt * heading.cos();
            y += 0.5 * dt * heading.sin();
            // Wheels 8 % farther apart travel 8 % farther apart for the same turn.
            let apart = turn * WHEEL_BASE_M * 1.08;
            left += 0.5 * dt - 0.5 * apart;
            right += 0.5 * dt + 0.5 * apart;
        }
        let samples: Vec<TruthSample> = poses
            .iter()
            .map(|&(t, x, y, yaw)| TruthSample {
                t_s: t + delay_s,
                x_m: x + noise(0.003),
                y_m: y + noise(0.003),
                yaw_rad: yaw + noise(0.0012),
            })
            .collect();
        (Trajectory::new(&samples).unwrap(), odometry)
    }

    /// A lidar 120 ms late is found within 10 ms (its standard error is under a millisecond:
    /// 0.6 mm of noise on each span's travel apart, against a turn rate that changes by up to
    /// 0.5 rad/s across a span, 20 mm of travel apart over 0.12 s), and gains on the held-out
    /// spans many times the 10 nats that name an effect, though the wheels' base and radii are
    /// off; a lidar on time gains nothing there beyond chance. Either way the base and each
    /// wheel's size are read within a fifth of their 8 % and 1 %.
    #[test]
    fn a_late_lidar_and_the_wheels_are_read_from_the_paths_spans() {
        let (path, odometry) = weaving(0.12);
        let late = fit(&path, WHEEL_BASE_M, &odometry, (0.0, 0.3)).unwrap();
        let delay = &late.delay_s;
        assert!((delay.value[0] - 0.12).abs() < 0.01, "{late:?}");
        assert!(delay.sd[0] < 0.005, "{late:?}");
        assert!(delay.heldout_gain > 50.0, "{late:?}");
        let (path, odometry) = weaving(0.0);
        let on_time = fit(&path, WHEEL_BASE_M, &odometry, (0.0, 0.3)).unwrap();
        assert!(on_time.delay_s.value[0] < 0.01, "{on_time:?}");
        assert!(on_time.delay_s.heldout_gain < 10.0, "{on_time:?}");
        for spans in [&late, &on_time] {
            let base = &spans.base_scale;
            assert!((base.value[0] - 1.08).abs() < 0.005, "{spans:?}");
            assert!(base.heldout_gain > 10.0, "{spans:?}");
            let radii = &spans.radius_scales;
            assert!((radii.value[0] - 1.0 / 1.01).abs() < 0.002, "{spans:?}");
            assert!((radii.value[1] - 1.0 / 0.99).abs() < 0.002, "{spans:?}");
            assert!(radii.heldout_gain > 10.0, "{spans:?}");
        }
    }

    /// A path too short for twenty spans in each half says nothing.
    #[test]
    fn a_short_path_says_nothing() {
        let (path, odometry) = weaving(0.1);
        let short: Vec<TruthSample> = path.samples().into_iter().take(100).collect();
        let short = Trajectory::new(&short).unwrap();
        assert!(fit(&short, WHEEL_BASE_M, &odometry, (0.0, 0.3)).is_none());
    }
}
