//! A lidar turned on its mount, seen in the path matched from its own scans: the robot's
//! heading there is the lidar's less the declared mount, so a lidar turned by ψ puts every
//! heading ψ off while the robot still drives along its true one. Wheels cannot move sideways,
//! yet the path does: each step of travel `f` carries a sideways part `−f tan ψ` in the
//! path's own frame (the robot "crabs"). The encoders' travel cannot show it (a step's length
//! changes by `1 − cos ψ`, a thousandth at 2.5°), and a map built from the same scans turns
//! with them; the crab is what is left. It is the lidar–odometry mount calibration of Censi et
//! al. ("Simultaneous calibration of odometry and sensor parameters for mobile robots", IEEE
//! T-RO 29(2), 2013) reduced to the mount's yaw: their lidar displacement in the robot frame,
//! against wheels that drive straight along their heading.
//!
//! The yaw is fitted by robust least squares (Huber weights) on the path's steps of the
//! training half and scored by its gain on the held-out half, in the steps' own noise
//! (measured on the training steps, as the median absolute deviation): a pseudo log-likelihood
//! with Huber's loss, so that a skid in a turn or a poor match does not carry it.

use hilsim_calibrator::stats::median;

use crate::trajectory::{wrap, Trajectory};

/// The travel a step gathers, metres. A turned lidar's sideways motion grows with the travel;
/// a step's own sideways error is its two ends' matches (a few millimetres) plus the skids
/// gathered along it, which grow with it too: on the CoreSLAM rover's log 11, 16, 25 and 61 mm
/// over steps of 15, 25, 50 and 100 cm of its twin's path, so the shortest steps whose ends'
/// error is still small beside that read the yaw best.
const STEP_M: f64 = 0.15;
/// A step whose net travel along its heading is shorter than this is not used, metres: its
/// direction is the matches' own error (a step that went and came back).
const MIN_STEP_M: f64 = 0.05;
/// A step turning through more than this is not used, radians (30°).
const MAX_STEP_TURN_RAD: f64 = 0.52;
/// Consecutive steps of one block; blocks alternate between the training and the held-out
/// halves (neighbouring matches share their errors, so a half is not every other step).
const BLOCK_STEPS: usize = 5;
/// Huber's k, in the steps' noise.
const HUBER_K: f64 = 2.0;
/// Fewest steps in each half.
const MIN_STEPS: usize = 20;
/// Iteratively reweighted fits.
const ITERATIONS: usize = 8;
/// The median absolute deviation of a Gaussian over its standard deviation.
const MAD_PER_SD: f64 = 0.674_489_750_196_081_7;

/// A fitted mount yaw from the path's sideways motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Crab {
    /// The lidar's yaw beyond the declared mount, radians (counter-clockwise).
    pub yaw_rad: f64,
    /// Its standard error, radians.
    pub yaw_sd_rad: f64,
    /// The pseudo log-likelihood gain over no turn on the training steps, nats.
    pub train_gain: f64,
    /// The same on the held-out steps: the score.
    pub heldout_gain: f64,
    /// Steps in each half.
    pub train_n: usize,
    pub heldout_n: usize,
    /// Held-out RMS of the steps' sideways motion before and after the fit, metres.
    pub rmse_before_m: f64,
    pub rmse_after_m: f64,
    /// The steps' sideways noise, metres.
    pub noise_m: f64,
}

/// One step of the path: its travel along the heading halfway through it, its sideways motion,
/// and which half it is in.
#[derive(Debug, Clone, Copy)]
struct Step {
    forward_m: f64,
    sideways_m: f64,
    held_out: bool,
}

/// The path's steps: runs of consecutive poses of at least [`STEP_M`] of travel (a chord
/// of an arc lies along the heading halfway through it, so a turn leaves no sideways part),
/// less those that turn through more than [`MAX_STEP_TURN_RAD`] (a pivot's chord is short and
/// its mid heading poorly known).
fn steps(path: &Trajectory) -> Vec<Step> {
    let poses = path.poses();
    let mut ends = vec![0];
    let mut travelled = 0.0;
    for (k, w) in poses.windows(2).enumerate() {
        travelled += (w[1].x - w[0].x).hypot(w[1].y - w[0].y);
        if travelled >= STEP_M {
            ends.push(k + 1);
            travelled = 0.0;
        }
    }
    ends.windows(2)
        .filter_map(|w| {
            let (a, b) = (poses[w[0]], poses[w[1]]);
            let turn = wrap(b.yaw - a.yaw);
            let heading = a.yaw + turn / 2.0;
            let (sin, cos) = heading.sin_cos();
            let (dx, dy) = (b.x - a.x, b.y - a.y);
            let forward_m = dx * cos + dy * sin;
            (forward_m.abs() >= MIN_STEP_M && turn.abs() <= MAX_STEP_TURN_RAD)
                .then_some((forward_m, dy * cos - dx * sin))
        })
        .enumerate()
        .map(|(i, (forward_m, sideways_m))| Step {
            forward_m,
            sideways_m,
            held_out: (i / BLOCK_STEPS) % 2 == 1,
        })
        .collect()
}

fn huber(r: f64) -> f64 {
    crate::stats::huber(r, HUBER_K)
}

/// The mount yaw `path` (matched from the lidar's scans) shows by moving sideways; `None`
/// with too few steps of travel in either half.
pub(crate) fn fit(path: &Trajectory) -> Option<Crab> {
    let all = steps(path);
    let (train, held): (Vec<Step>, Vec<Step>) = all.iter().partition(|s| !s.held_out);
    if train.len() < MIN_STEPS || held.len() < MIN_STEPS {
        return None;
    }
    // The sideways motion a yaw ψ leaves, as `slope = −tan ψ` times the travel.
    let residual = |s: &Step, slope: f64| s.sideways_m - slope * s.forward_m;
    let noise_of = |slope: f64| {
        let mut deviations: Vec<f64> = train.iter().map(|s| residual(s, slope).abs()).collect();
        median(&mut deviations) / MAD_PER_SD
    };
    let mut slope = 0.0;
    let mut noise = noise_of(slope).max(1e-6);
    let mut information = 0.0;
    for _ in 0..ITERATIONS {
        let (mut sfx, mut sff) = (0.0, 0.0);
        for s in &train {
            let r = residual(s, slope) / noise;
            let w = if r.abs() <= HUBER_K {
                1.0
            } else {
                HUBER_K / r.abs()
            };
            sfx += w * s.forward_m * s.sideways_m;
            sff += w * s.forward_m * s.forward_m;
        }
        if sff <= 0.0 {
            return None;
        }
        slope = sfx / sff;
        noise = noise_of(slope).max(1e-6);
        information = sff / (noise * noise);
    }
    let gain = |steps: &[Step]| -> f64 {
        steps
            .iter()
            .map(|s| huber(s.sideways_m / noise) - huber(residual(s, slope) / noise))
            .sum()
    };
    let rms = |f: &dyn Fn(&Step) -> f64| {
        (held.iter().map(|s| f(s).powi(2)).sum::<f64>() / held.len() as f64).sqrt()
    };
    // tan ψ = −slope; its standard error through d(atan)/dx = 1 / (1 + x²).
    let yaw_rad = (-slope).atan();
    Some(Crab {
        yaw_rad,
        yaw_sd_rad: information.recip().sqrt() / (1.0 + slope * slope),
        train_gain: gain(&train),
        heldout_gain: gain(&held),
        train_n: train.len(),
        heldout_n: held.len(),
        rmse_before_m: rms(&|s| s.sideways_m),
        rmse_after_m: rms(&|s| residual(s, slope)),
        noise_m: noise,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use hilsim_recording::TruthSample;

    /// A robot driving a slalom at 0.5 m/s, seen through a lidar turned by `yaw_rad`: the path
    /// matched from it has every heading `yaw_rad` off, with the matches' noise (3 mm, fixed
    /// pseudo-random sequence) on each position.
    fn crabbing(yaw_rad: f64) -> Trajectory {
        let (mut x, mut y, mut heading) = (0.0, 0.0, 0.0_f64);
        let mut state = 12_345_u64;
        let mut noise = || {
            // A linear congruential sequence, uniform in ±√3 × 3 mm (s.d. 3 mm).
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * 3f64.sqrt() * 0.003
        };
        let samples: Vec<TruthSample> = (0..600)
            .map(|i| {
                let t = f64::from(i) * 0.1;
                heading += 0.1 * (0.3 * t).sin() * 0.1;
                x += 0.05 * heading.cos();
                y += 0.05 * heading.sin();
                TruthSample {
                    t_s: t,
                    x_m: x + noise(),
                    y_m: y + noise(),
                    yaw_rad: heading + yaw_rad,
                }
            })
            .collect();
        Trajectory::new(&samples).unwrap()
    }

    /// A lidar turned by 2° is found within 0.3° (its standard error is about 0.15° over the
    /// training half's 15 m in steps of 15 cm with 3 mm of noise on each end: √2 × 3 mm /
    /// 15 cm / √100 rad), and gains on the held-out steps three times the 10 nats that name an
    /// effect; a lidar as declared gains nothing there beyond chance.
    #[test]
    fn a_turned_lidar_is_read_from_the_path_moving_sideways() {
        let turned = fit(&crabbing(2f64.to_radians())).unwrap();
        assert!(
            (turned.yaw_rad.to_degrees() - 2.0).abs() < 0.3,
            "{turned:?}"
        );
        assert!(turned.heldout_gain > 30.0, "{turned:?}");
        assert!(turned.yaw_sd_rad.to_degrees() < 0.2, "{turned:?}");
        let straight = fit(&crabbing(0.0)).unwrap();
        assert!(straight.yaw_rad.to_degrees().abs() < 0.3, "{straight:?}");
        assert!(straight.heldout_gain < 10.0, "{straight:?}");
    }

    /// A path that stands still has no steps to read a yaw from.
    #[test]
    fn a_path_standing_still_says_nothing() {
        let samples: Vec<TruthSample> = (0..100)
            .map(|i| TruthSample {
                t_s: f64::from(i) * 0.1,
                x_m: 1.0,
                y_m: 2.0,
                yaw_rad: 0.5,
            })
            .collect();
        assert!(fit(&Trajectory::new(&samples).unwrap()).is_none());
    }
}
