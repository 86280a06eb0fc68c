//! A stop's scan: the revolutions taken while the robot stood still, averaged beam by beam.
//!
//! A beam grazing a cylinder's edge sees sometimes the cylinder, sometimes the wall behind it (the
//! XV-11's beam jitters). When a beam's neighbours lie at clearly different ranges (further apart
//! than the jump threshold and three single-reading standard deviations of each), it is such an
//! edge beam:
//! it keeps only the readings on its majority's side of the midpoint between its neighbours, so
//! that it measures one surface, not a mixture of two. Splitting a beam's readings on their own
//! (e.g. two-means) would cut single surfaces in two: with the XV-11's ~5 % range noise and ten
//! readings, the best split of pure noise looks like two layers several percent of the time.

use hilsim_recording::LidarSample;

use super::options::DetectionOptions;
use super::stops::Stop;
use crate::stats::median;

/// Beams per revolution of the XV-11, one reading per degree (a scan's own count is
/// [`StopScan::beams`]'s length).
pub const BEAMS: usize = 360;

/// A lidar's beams: `count` a revolution, beam `i` at `offset_deg + i·step_deg` (lidar frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamGrid {
    /// Beams per revolution.
    pub count: usize,
    /// Degrees between neighbouring beams (360 / count).
    pub step_deg: f64,
    /// Beam 0's angle, degrees in [0, step).
    pub offset_deg: f64,
}

impl BeamGrid {
    /// The XV-11's: 360 beams, one per whole degree.
    pub const XV11: BeamGrid = BeamGrid {
        count: BEAMS,
        step_deg: 1.0,
        offset_deg: 0.0,
    };

    /// The grid of the readings: the spacing is the median step between consecutive readings
    /// of a revolution, made a whole fraction of a turn; the XV-11's when there are too few
    /// readings to tell.
    #[must_use]
    pub fn of(lidar: &[LidarSample]) -> Self {
        let mut steps: Vec<f64> = lidar
            .windows(2)
            .filter(|w| w[0].rev == w[1].rev)
            // The angle between neighbours, whichever way the lidar turns and across 0°.
            .map(|w| {
                let d = (w[1].angle_deg - w[0].angle_deg).rem_euclid(360.0);
                d.min(360.0 - d)
            })
            .filter(|d| *d > 1e-6)
            .collect();
        if steps.is_empty() {
            return Self::XV11;
        }
        let step = median(&mut steps);
        // At most a reading every 0.01° (36,000 a revolution): finer is not a lidar's grid.
        let count = ((360.0 / step).round() as usize).clamp(1, 36_000);
        let step_deg = 360.0 / count as f64;
        let offset_deg = lidar[0].angle_deg.rem_euclid(step_deg);
        // An offset of nearly a whole step is beam 0 itself.
        let offset_deg = if step_deg - offset_deg < 1e-6 {
            0.0
        } else {
            offset_deg
        };
        Self {
            count,
            step_deg,
            offset_deg,
        }
    }

    /// The beam a reading at `angle_deg` belongs to.
    #[must_use]
    pub fn index(&self, angle_deg: f64) -> usize {
        let i = ((angle_deg - self.offset_deg) / self.step_deg).round();
        (i.rem_euclid(self.count as f64) as usize) % self.count
    }

    /// Beam `i`'s angle, radians (`i` may run past a turn: segments are unwrapped).
    #[must_use]
    pub fn angle_rad(&self, i: usize) -> f64 {
        // The XV-11's (0 + i·1) is exactly the whole degree i.
        (self.offset_deg + i as f64 * self.step_deg).to_radians()
    }
}

/// One reading kept for a beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    /// Reported range, metres.
    pub range_m: f64,
    /// The simulator's true range along the beam, when the recording has it.
    pub true_range_m: Option<f64>,
}

/// One beam's readings over a stop.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Beam {
    /// Enough readings survived the gate.
    pub valid: bool,
    /// Mean of the kept readings, metres.
    pub mean_m: f64,
    /// Sample standard deviation of one kept reading, metres (0 with fewer than two).
    pub sd_m: f64,
    /// The kept readings (the beam's main layer).
    pub readings: Vec<Reading>,
    /// Every valid reading's range, whichever layer, metres.
    pub all_m: Vec<f64>,
    /// How many times the beam was sampled during the stop (valid or not).
    pub samples: usize,
}

impl Beam {
    /// Standard error of the mean, metres.
    #[must_use]
    pub fn sem_m(&self) -> f64 {
        if self.readings.is_empty() {
            f64::INFINITY
        } else {
            self.sd_m / (self.readings.len() as f64).sqrt()
        }
    }
}

/// A stop's averaged scan, beam `i` at `grid.angle_rad(i)` in the lidar frame.
#[derive(Debug, Clone, PartialEq)]
pub struct StopScan {
    /// The beams of one revolution (`grid.count`).
    pub beams: Vec<Beam>,
    /// Where each beam points.
    pub grid: BeamGrid,
    /// Revolutions (complete or not) that contributed.
    pub revolutions: usize,
}

/// Averages the readings of `lidar` (in time order) taken during `stop`.
#[must_use]
pub fn average_stop(lidar: &[LidarSample], stop: &Stop, opts: &DetectionOptions) -> StopScan {
    let first = lidar.partition_point(|s| s.t_s < stop.t_start_s);
    let last = lidar.partition_point(|s| s.t_s <= stop.t_end_s);
    let window = &lidar[first..last];
    let grid = BeamGrid::of(window);
    let beams_n = grid.count;
    let mut raw: Vec<Vec<Reading>> = vec![Vec::new(); beams_n];
    let mut sampled = vec![0usize; beams_n];
    let mut revs: Vec<u64> = Vec::new();
    for s in window {
        if revs.last() != Some(&s.rev) {
            revs.push(s.rev);
        }
        let i = grid.index(s.angle_deg);
        sampled[i] += 1;
        if !s.invalid && s.range_m > 0.0 && s.range_m.is_finite() {
            raw[i].push(Reading {
                range_m: s.range_m,
                true_range_m: s.true_range_m,
            });
        }
    }
    revs.dedup();
    // First pass: each beam's robust level (median) and single-reading spread (1.4826 MAD, the
    // Gaussian σ), insensitive to a minority of readings from another surface.
    let levels: Vec<Option<(f64, f64)>> = raw
        .iter()
        .zip(&sampled)
        .map(|(r, &n)| {
            if r.len() < needed(n, opts) {
                return None;
            }
            let mut v: Vec<f64> = r.iter().map(|x| x.range_m).collect();
            let med = median(&mut v);
            let mut dev: Vec<f64> = v.iter().map(|x| (x - med).abs()).collect();
            Some((med, 1.4826 * median(&mut dev)))
        })
        .collect();
    // Second pass: a beam between two neighbours at clearly different ranges (an edge) keeps the
    // readings on its majority's side of the midpoint between them.
    let beams = (0..beams_n)
        .map(|i| {
            let prev = levels[(i + beams_n - 1) % beams_n];
            let next = levels[(i + 1) % beams_n];
            let split = match (prev, next) {
                (Some((a, sa)), Some((b, sb))) => {
                    let (lo, hi) = (a.min(b), a.max(b));
                    let tol = (opts.jump_abs_m + opts.jump_rel * lo).max(3.0 * (sa + sb));
                    (hi - lo > tol).then_some((lo + hi) / 2.0)
                }
                _ => None,
            };
            average(raw[i].clone(), sampled[i], split, opts)
        })
        .collect();
    StopScan {
        beams,
        grid,
        revolutions: revs.len(),
    }
}

/// Readings a beam needs to be used.
fn needed(sampled: usize, opts: &DetectionOptions) -> usize {
    (opts.min_valid_fraction * sampled as f64).ceil().max(1.0) as usize
}

/// Averages a beam's readings; with a `split` range, only its majority side (ties: the nearer).
fn average(
    mut readings: Vec<Reading>,
    sampled: usize,
    split: Option<f64>,
    opts: &DetectionOptions,
) -> Beam {
    let need = needed(sampled, opts);
    let all_m: Vec<f64> = readings.iter().map(|x| x.range_m).collect();
    if let Some(split) = split {
        let near = all_m.iter().filter(|r| **r < split).count();
        let keep_near = 2 * near >= all_m.len();
        readings.retain(|x| (x.range_m < split) == keep_near);
    }
    if readings.len() < need {
        return Beam {
            all_m,
            samples: sampled,
            ..Beam::default()
        };
    }
    let n = readings.len() as f64;
    let mean = readings.iter().map(|x| x.range_m).sum::<f64>() / n;
    let sd = if readings.len() > 1 {
        (readings
            .iter()
            .map(|x| (x.range_m - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0))
            .sqrt()
    } else {
        0.0
    };
    Beam {
        valid: true,
        mean_m: mean,
        sd_m: sd,
        readings,
        all_m,
        samples: sampled,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn revolution(angles: impl Iterator<Item = f64>) -> Vec<LidarSample> {
        angles
            .map(|angle_deg| LidarSample {
                t_s: 0.0,
                rev: 0,
                angle_deg,
                range_m: 1.0,
                strength: 1,
                invalid: false,
                warning: false,
                true_range_m: None,
            })
            .collect()
    }

    #[test]
    fn the_beam_grid_is_the_lidars_own() {
        assert_eq!(
            BeamGrid::of(&revolution((0..360).map(f64::from))),
            BeamGrid::XV11
        );
        let half = BeamGrid::of(&revolution((0..720).map(|i| f64::from(i) * 0.5)));
        assert_eq!(
            (half.count, half.step_deg, half.offset_deg),
            (720, 0.5, 0.0)
        );
        assert_eq!(half.index(359.5), 719);
        assert_eq!(half.index(359.9), 0);
        // 1,080 readings a third of a degree apart, starting a sixth of a degree off 0; a lost
        // reading (a step of two) does not change the grid.
        let third = 360.0 / 1080.0;
        let angles = (0..1080)
            .filter(|i| *i != 7)
            .map(|i| (f64::from(i) + 0.5) * third);
        let grid = BeamGrid::of(&revolution(angles));
        assert_eq!(grid.count, 1080);
        assert!((grid.offset_deg - third / 2.0).abs() < 1e-9);
        assert_eq!(grid.index((8.5) * third), 8);
        // A lidar turning clockwise from 180° (a LaserScan from +π with a negative increment).
        let clockwise = (0..720).map(|i| (180.0 - f64::from(i) * 0.5).rem_euclid(360.0));
        assert_eq!(BeamGrid::of(&revolution(clockwise)).count, 720);
        assert!((grid.angle_rad(8) - (8.5 * third).to_radians()).abs() < 1e-12);
    }

    #[test]
    fn an_edge_beam_keeps_its_majority_surface() {
        let mk = |r: f64| Reading {
            range_m: r,
            true_range_m: None,
        };
        let opts = DetectionOptions::default();
        let readings = vec![mk(1.0), mk(1.01), mk(0.99), mk(2.5), mk(1.0), mk(2.6)];
        let b = average(readings, 6, Some(1.75), &opts);
        assert!(b.valid);
        assert_eq!((b.readings.len(), b.all_m.len()), (4, 6));
        assert!((b.mean_m - 1.0).abs() < 1e-12);
        // Half and half: the nearer surface wins the tie.
        let readings = vec![mk(3.0), mk(3.1), mk(2.9), mk(1.5), mk(1.55), mk(1.45)];
        assert!((average(readings, 6, Some(2.2), &opts).mean_m - 1.5).abs() < 1e-12);
        // Without an edge nothing is dropped.
        let readings: Vec<Reading> = [4.0, 4.3, 3.8, 4.1, 3.7].into_iter().map(mk).collect();
        assert_eq!(average(readings, 5, None, &opts).readings.len(), 5);
    }
}
