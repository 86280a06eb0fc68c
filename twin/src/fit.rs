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
                }
            }
            next_log(&mut pending)?;
        }
    }
    let median_m = signed.quantile(0.5);
    // The median absolute deviation, from the signed histogram's bins.
    let mut deviation = Histogram::new(0.0, 2.0 * SPAN_M);
    for (k, &c) in signed.counts.iter().enumerate() {
        deviation.add_n((signed.from_m + k as f64 * BIN_M - median_m).abs(), c);
    }
    deviation.above += signed.below + signed.above;
    Ok(TwinFit {
        compared,
        paired,
        median_abs_m: abs.quantile(0.5),
        p90_abs_m: abs.quantile(0.9),
        median_m,
        spread_m: 1.4826 * deviation.quantile(0.5),
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
}
