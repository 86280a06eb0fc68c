//! The twin set against the log, reading for reading: each beam of each replayed scan paired
//! with the log's reading of that beam.

use std::path::Path;

use hilsim_lidar_emulator::Emulation;
use hilsim_recording::LidarSample;
use hilsim_sim::Scenario;

use crate::error::TwinError;
use crate::scans::open;

/// Readings compared are the log's valid ones at most this far, metres (the goal's range: a
/// wall's cell error grows with the heading error times the range).
pub const COMPARED_WITHIN_M: f64 = 8.0;

/// Bin of the differences' histograms, metres: well under a millimetre-quantised reading's
/// resolution, so medians are exact to it.
const BIN_M: f64 = 0.0005;
/// The histograms cover differences up to this, metres; larger ones are counted beyond it.
const SPAN_M: f64 = 2.0;

/// How close the twin's readings are to the log's.
#[derive(Debug, Clone, PartialEq)]
pub struct TwinFit {
    /// The log's valid readings within [`COMPARED_WITHIN_M`] of the scans replayed.
    pub compared: u64,
    /// Of those, the ones the twin also read (a valid reading of the same beam).
    pub paired: u64,
    /// Median |twin − log| over the paired readings, metres.
    pub median_abs_m: f64,
    /// 90th percentile of |twin − log|, metres.
    pub p90_abs_m: f64,
    /// Median of log − twin (a bias of the log's lidar against the map, or the map's), metres.
    pub median_m: f64,
    /// Robust spread of log − twin (1.4826 × the median absolute deviation), metres: the log's
    /// noise and the map's error together.
    pub spread_m: f64,
    /// The robust spread by the twin's range: (the bin's middle, metres; spread, metres;
    /// readings), bins of [`RANGE_BIN_M`] with at least [`MIN_BIN_READINGS`] readings.
    pub spread_by_range: Vec<(f64, f64, u64)>,
}

/// Width of the range bins the spread is measured in, metres.
pub const RANGE_BIN_M: f64 = 0.5;
/// Fewest readings a range bin's spread is measured from.
pub const MIN_BIN_READINGS: u64 = 200;

impl TwinFit {
    /// The lidar's noise as the papers' eq. 2 polynomial `β₀ + β₁ d + β₂ d²` (standard
    /// deviation, metres) fitted to the spread by range, less a map quantisation's variance
    /// `cell_m² / 12` (which the diagnosis carries itself), weighted by each bin's readings:
    /// of the forms with every coefficient non-negative, the closest. The spread is the log's
    /// noise and the map's error together: an upper bound of the lidar's own.
    #[must_use]
    pub fn noise_polynomial(&self, cell_m: f64) -> Vec<f64> {
        let quantisation = cell_m * cell_m / 12.0;
        let bins: Vec<(f64, f64, f64)> = self
            .spread_by_range
            .iter()
            .map(|&(d, sd, n)| (d, (sd * sd - quantisation).max(0.0).sqrt(), n as f64))
            .collect();
        let fallback = (self.spread_m * self.spread_m - quantisation)
            .max(0.0)
            .sqrt();
        let mut best: Option<(f64, Vec<f64>)> = None;
        for terms in [&[0usize][..], &[0, 2], &[0, 1], &[0, 1, 2]] {
            let Some(c) = weighted_fit(&bins, terms) else {
                continue;
            };
            if c.iter().any(|v| *v < 0.0) {
                continue;
            }
            let mut coeffs = vec![0.0; terms.iter().max().map_or(1, |m| m + 1)];
            for (t, v) in terms.iter().zip(&c) {
                coeffs[*t] = *v;
            }
            let sse: f64 = bins
                .iter()
                .map(|(d, sd, n)| {
                    let p: f64 = coeffs.iter().rev().fold(0.0, |acc, c| acc * d + c);
                    n * (sd - p).powi(2)
                })
                .sum();
            if best.as_ref().is_none_or(|(b, _)| sse < *b) {
                best = Some((sse, coeffs));
            }
        }
        let mut coeffs = best.map_or_else(|| vec![fallback], |(_, c)| c);
        // A millimetre at least: a noiseless declaration makes every reading's likelihood a spike.
        coeffs[0] = coeffs[0].max(0.001);
        coeffs.iter().map(|c| (c * 1e6).round() / 1e6).collect()
    }
}

/// Weighted least squares of `sd = Σ c_t d^t` over `terms` (at most three); `None` when
/// singular.
fn weighted_fit(bins: &[(f64, f64, f64)], terms: &[usize]) -> Option<Vec<f64>> {
    let k = terms.len();
    let mut a = [[0.0; 3]; 3];
    let mut b = [0.0; 3];
    for &(d, sd, n) in bins {
        let x: Vec<f64> = terms.iter().map(|&t| d.powi(t as i32)).collect();
        for i in 0..k {
            b[i] += n * x[i] * sd;
            for j in 0..k {
                a[i][j] += n * x[i] * x[j];
            }
        }
    }
    // Gaussian elimination with partial pivoting on the k × k system.
    for col in 0..k {
        let pivot = (col..k).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-12 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let (pivot_row, pivot_b) = (a[col], b[col]);
        for (row, (a_row, b_row)) in a.iter_mut().zip(b.iter_mut()).enumerate().take(k) {
            if row != col {
                let f = a_row[col] / pivot_row[col];
                for (x, p) in a_row.iter_mut().zip(pivot_row).take(k).skip(col) {
                    *x -= f * p;
                }
                *b_row -= f * pivot_b;
            }
        }
    }
    Some((0..k).map(|i| b[i] / a[i][i]).collect())
}

impl TwinFit {
    /// The share of compared readings that were paired.
    #[must_use]
    pub fn paired_share(&self) -> f64 {
        if self.compared == 0 {
            0.0
        } else {
            self.paired as f64 / self.compared as f64
        }
    }
}

/// A histogram of differences with fixed bins: memory fixed whatever the log's length.
struct Histogram {
    counts: Vec<u64>,
    /// The value of bin 0.
    from_m: f64,
    below: u64,
    above: u64,
}

impl Histogram {
    fn new(from_m: f64, to_m: f64) -> Self {
        Self {
            counts: vec![0; ((to_m - from_m) / BIN_M).ceil() as usize + 1],
            from_m,
            below: 0,
            above: 0,
        }
    }

    fn add(&mut self, x: f64) {
        self.add_n(x, 1);
    }

    fn add_n(&mut self, x: f64, n: u64) {
        let k = ((x - self.from_m) / BIN_M).round();
        if k < 0.0 {
            self.below += n;
        } else if let Some(c) = self.counts.get_mut(k as usize) {
            *c += n;
        } else {
            self.above += n;
        }
    }

    /// The robust spread of the values: 1.4826 × their median absolute deviation.
    fn spread(&self) -> f64 {
        let median = self.quantile(0.5);
        let mut deviation = Histogram::new(0.0, 2.0 * (self.counts.len() as f64) * BIN_M);
        for (k, &c) in self.counts.iter().enumerate() {
            deviation.add_n((self.from_m + k as f64 * BIN_M - median).abs(), c);
        }
        deviation.above += self.below + self.above;
        1.4826 * deviation.quantile(0.5)
    }

    fn total(&self) -> u64 {
        self.below + self.above + self.counts.iter().sum::<u64>()
    }

    /// The value below which a share `q` of the values lie (the bin's centre); the range's
    /// ends when it lies beyond them.
    fn quantile(&self, q: f64) -> f64 {
        let n = self.total();
        if n == 0 {
            return f64::NAN;
        }
        let rank = ((q * n as f64).ceil() as u64).clamp(1, n);
        let mut seen = self.below;
        if seen >= rank {
            return self.from_m;
        }
        for (k, c) in self.counts.iter().enumerate() {
            seen += c;
            if seen >= rank {
                return self.from_m + k as f64 * BIN_M;
            }
        }
        self.from_m + self.counts.len() as f64 * BIN_M
    }
}

/// Runs the twin scenario and sets its lidar's readings against the log's at `recording`.
///
/// # Errors
/// The scenario's sensors cannot be built, or the recording cannot be read.
pub fn compare(scenario: &Scenario, recording: &Path) -> Result<TwinFit, TwinError> {
    let dir = open(recording)?;
    let mut log = dir
        .lidar()?
        .ok_or_else(|| TwinError::Input(format!("{}: no lidar.csv", recording.display())))?;
    let mut emulation =
        Emulation::new(scenario, scenario.seed).map_err(|e| TwinError::Model(e.to_string()))?;
    let mut abs = Histogram::new(0.0, SPAN_M);
    let mut signed = Histogram::new(-SPAN_M, SPAN_M);
    let range_bins = (COMPARED_WITHIN_M / RANGE_BIN_M).ceil() as usize;
    let mut by_range: Vec<Histogram> = (0..range_bins)
        .map(|_| Histogram::new(-SPAN_M, SPAN_M))
        .collect();
    let (mut compared, mut paired) = (0_u64, 0_u64);
    // The log's reading being paired and its index within its revolution.
    let mut pending: Option<(LidarSample, u64)> = None;
    let mut position: Option<(u64, u64)> = None;
    let mut next_log = |pending: &mut Option<(LidarSample, u64)>| -> Result<(), TwinError> {
        *pending = match log.next().transpose()? {
            Some(r) => {
                let index = match position {
                    Some((rev, i)) if rev == r.rev => i + 1,
                    _ => 0,
                };
                position = Some((r.rev, index));
                Some((r, index))
            }
            None => None,
        };
        Ok(())
    };
    next_log(&mut pending)?;
    while let Some(samples) = emulation.step() {
        for twin in &samples.lidar {
            let key = (twin.rev, u64::from(twin.index));
            // The log's readings before this beam have no twin (their scan was not replayed).
            while pending.as_ref().is_some_and(|(r, i)| (r.rev, *i) < key) {
                next_log(&mut pending)?;
            }
            let Some((r, i)) = pending.as_ref() else {
                break;
            };
            if (r.rev, *i) != key {
                continue;
            }
            if !r.invalid && r.range_m > 0.0 && r.range_m <= COMPARED_WITHIN_M {
                compared += 1;
                if twin.error_code.is_none() {
                    paired += 1;
                    let d = r.range_m - f64::from(twin.distance_mm) / 1000.0;
                    abs.add(d.abs());
                    signed.add(d);
                    let bin = (f64::from(twin.distance_mm) / 1000.0 / RANGE_BIN_M) as usize;
                    if let Some(h) = by_range.get_mut(bin) {
                        h.add(d);
                    }
                }
            }
            next_log(&mut pending)?;
        }
    }
    let median_m = signed.quantile(0.5);
    let spread_by_range = by_range
        .iter()
        .enumerate()
        .filter(|(_, h)| h.total() >= MIN_BIN_READINGS)
        .map(|(k, h)| ((k as f64 + 0.5) * RANGE_BIN_M, h.spread(), h.total()))
        .collect();
    Ok(TwinFit {
        compared,
        paired,
        median_abs_m: abs.quantile(0.5),
        p90_abs_m: abs.quantile(0.9),
        median_m,
        spread_m: signed.spread(),
        spread_by_range,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn histogram_quantiles_are_exact_to_a_bin() {
        let mut h = Histogram::new(0.0, 1.0);
        for k in 1..=100 {
            h.add(f64::from(k) * 0.001);
        }
        assert!((h.quantile(0.5) - 0.050).abs() <= BIN_M);
        assert!((h.quantile(0.9) - 0.090).abs() <= BIN_M);
        h.add(5.0);
        assert_eq!(h.total(), 101);
    }

    #[test]
    fn a_noise_growing_with_range_is_fitted_as_the_papers_polynomial() {
        // 3 mm + 2 mm/m² × d², the landmark paper's XV-11 noise form, measured in six bins.
        let spread_by_range = (1..=6)
            .map(|k| {
                let d = f64::from(k) - 0.25;
                (d, 0.003 + 0.002 * d * d, 1000)
            })
            .collect();
        let fit = TwinFit {
            compared: 6000,
            paired: 6000,
            median_abs_m: 0.01,
            p90_abs_m: 0.03,
            median_m: 0.0,
            spread_m: 0.02,
            spread_by_range,
        };
        let c = fit.noise_polynomial(0.0);
        let at = |d: f64| c.iter().rev().fold(0.0, |acc, v| acc * d + v);
        assert!(
            (at(1.0) - 0.005).abs() < 2e-4 && (at(5.0) - 0.053).abs() < 5e-4,
            "{c:?}"
        );
        assert!(c.iter().all(|v| *v >= 0.0), "{c:?}");
    }
}
