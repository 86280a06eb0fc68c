//! A LaserScan into lidar readings: one revolution a message, each reading's angle wrapped
//! into [0, 360) on a 1e-4° grid and its range kept as the decimal it was sent as. The hot
//! path of an import, so the angles shared by a lidar's scans are computed once.

use hilsim_recording::{
    decimal_of_f32, round_half_away, short_decimal_of_f32, LidarDecimals, LidarSample, SampleSink,
};

use super::clocks::{microseconds, seconds_of};
use super::{Converter, Fault};
use crate::msgs::LaserScan;
use crate::topics::Role;

/// Each reading's angle of a scan's `angle_min` and `angle_increment`, computed once for the
/// scans that share them (every scan of a lidar, usually) rather than once a reading.
#[derive(Default)]
pub(super) struct ScanAngles {
    /// The float32 fields' bits, as the message gave them.
    angle_min: u32,
    increment: u32,
    /// Ten-thousandths of a degree, [0, 3,600,000) ([`angle_e4_deg`]).
    e4_deg: Vec<u32>,
}

impl ScanAngles {
    /// The angles of the first `count` readings of a scan with these fields; `None` when either
    /// is not finite.
    fn of(&mut self, angle_min: f32, increment: f32, count: usize) -> Option<&[u32]> {
        if !(angle_min.is_finite() && increment.is_finite()) {
            return None;
        }
        let same = self.angle_min == angle_min.to_bits() && self.increment == increment.to_bits();
        if !same || self.e4_deg.len() < count {
            let (start, step) = (decimal_of_f32(angle_min), decimal_of_f32(increment));
            self.angle_min = angle_min.to_bits();
            self.increment = increment.to_bits();
            self.e4_deg.clear();
            self.e4_deg
                .extend((0..count).map(|i| angle_e4_deg(start + i as f64 * step)));
        }
        Some(&self.e4_deg[..count])
    }
}

impl Converter {
    /// One revolution: reading i at `angle_min + i·angle_increment` (wrapped into [0, 360)),
    /// taken at the stamp plus `i·time_increment`.
    pub(super) fn scan<S>(
        &mut self,
        scan: &LaserScan,
        log_ns: i64,
        sink: &mut S,
    ) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let ns = self.stamped(scan.header.stamp, log_ns);
        if scan.ranges.is_empty() {
            return Ok(());
        }
        let time_increment_ns = decimal_of_f32(scan.time_increment) * 1e9;
        let angles = self
            .scan_angles
            .of(scan.angle_min, scan.angle_increment, scan.ranges.len());
        let Some(angles) = angles.filter(|_| time_increment_ns.is_finite()) else {
            self.not_finite(Role::Lidar);
            return Ok(());
        };
        let (range_min, range_max) = (scan.range_min, scan.range_max);
        let from_start_ns = ns - *self.t0_ns.get_or_insert(ns);
        let clock = self.clocks.entry(Role::Lidar).or_default();
        for (i, (&range, &angle_e4_deg)) in scan.ranges.iter().zip(angles).enumerate() {
            let t_us = clock.order(microseconds(from_start_ns, i as f64 * time_increment_ns));
            // 0 is no echo too (drivers that leave range_min 0 send it for none).
            let valid =
                range.is_finite() && range > 0.0 && range >= range_min && range <= range_max;
            // The nearest whole strength (half away from zero, as `round`; exact in f64).
            let strength = scan
                .intensities
                .get(i)
                .filter(|s| s.is_finite())
                .map_or(0, |&s| (f64::from(s.clamp(0.0, 65_535.0)) + 0.5) as u16);
            let range_decimal = if valid {
                short_decimal_of_f32(range)
            } else {
                Some((0, 0))
            };
            if let Some((range_digits, range_scale)) = range_decimal {
                sink.lidar_decimals(&LidarDecimals {
                    t_us,
                    rev: self.rev,
                    angle_e4_deg,
                    range_digits,
                    range_scale,
                    strength,
                    invalid: !valid,
                    warning: false,
                })?;
            } else {
                // A range of more than 6 significant digits (a float lidar's noise).
                sink.lidar(&LidarSample {
                    t_s: seconds_of(t_us),
                    rev: self.rev,
                    angle_deg: f64::from(angle_e4_deg) / 1e4,
                    range_m: decimal_of_f32(range),
                    strength,
                    invalid: false,
                    warning: false,
                    true_range_m: None,
                })?;
            }
        }
        self.count(Role::Lidar, scan.ranges.len() as u64);
        self.rev += 1;
        Ok(())
    }
}

/// A LaserScan angle (radians, any turn) as a recording's degrees in [0, 360), to 1e-4°: the
/// float32 angle and increment put reading i of a 360-reading scan about 1e-5° off its nominal
/// angle, and no lidar resolves 1e-4°.
#[must_use]
pub fn angle_deg(angle_rad: f64) -> f64 {
    f64::from(angle_e4_deg(angle_rad)) / 1e4
}

/// [`angle_deg`] in ten-thousandths of a degree, [0, 3,600,000): the turn taken off in
/// integers, exactly (a float remainder leaves 269.99990000000003 for −90.0001); 0 for an
/// angle that is not finite.
fn angle_e4_deg(angle_rad: f64) -> u32 {
    const TURN: i64 = 3_600_000;
    let e4 = round_half_away(angle_rad.to_degrees() * 1e4);
    // Within ±2⁵³ every whole f64 is an exact i64.
    if e4.is_nan() || e4.abs() >= 9.0e15 {
        return 0;
    }
    u32::try_from((e4 as i64).rem_euclid(TURN)).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use hilsim_recording::{CommandSample, OdometrySample, SonarSample, TruthSample};

    use super::*;
    use crate::msgs::Time;
    use crate::topics::{Chosen, Kind};

    /// A scan whose angles or timing are not numbers is skipped and counted, not written as
    /// NaN; the readings of a good scan reach a sink as the decimals they were sent as.
    #[test]
    fn a_scan_of_nan_fields_is_skipped() {
        use crate::cdr::encode;
        use crate::msgs::Header;
        let chosen: Chosen = [(Role::Lidar, ("/scan".to_string(), Kind::LaserScan))].into();
        let mut converter = Converter::new(&chosen, 0.2, None);
        /// Keeps the lidar's readings (through `SampleSink::lidar_decimals`'s default).
        #[derive(Default)]
        struct Kept(Vec<LidarSample>);
        impl SampleSink for Kept {
            type Error = hilsim_recording::Error;
            fn command(&mut self, _: &CommandSample) -> Result<(), Self::Error> {
                Ok(())
            }
            fn odometry(&mut self, _: &OdometrySample) -> Result<(), Self::Error> {
                Ok(())
            }
            fn lidar(&mut self, r: &LidarSample) -> Result<(), Self::Error> {
                self.0.push(*r);
                Ok(())
            }
            fn sonar(&mut self, _: &SonarSample) -> Result<(), Self::Error> {
                Ok(())
            }
            fn truth(&mut self, _: &TruthSample) -> Result<(), Self::Error> {
                Ok(())
            }
        }
        let mut kept = Kept::default();
        let scan = |angle_min: f32, time_increment: f32| {
            let mut bytes = Vec::new();
            let message = LaserScan {
                header: Header {
                    stamp: Time { sec: 7, nanosec: 0 },
                    frame_id: "laser".into(),
                },
                angle_min,
                angle_increment: 0.5f32.to_radians(),
                time_increment,
                range_min: 0.1,
                range_max: 6.0,
                ranges: vec![1.234, 0.05, f32::NAN],
                ..LaserScan::default()
            };
            encode(&message, &mut bytes);
            bytes
        };
        for bytes in [scan(f32::NAN, 0.0), scan(0.0, f32::INFINITY)] {
            let converted = converter.message(Role::Lidar, Kind::LaserScan, 0, &bytes, &mut kept);
            assert!(converted.is_ok());
        }
        assert!(kept.0.is_empty());
        assert!(converter
            .notes()
            .iter()
            .any(|n| n.contains("2 lidar messages with a value that is not finite")));
        let good = scan(-0.5f32.to_radians(), 1e-4);
        let converted = converter.message(Role::Lidar, Kind::LaserScan, 0, &good, &mut kept);
        assert!(converted.is_ok());
        let row = |r: &LidarSample| (r.t_s, r.angle_deg, r.range_m, r.invalid);
        assert_eq!(
            kept.0.iter().map(row).collect::<Vec<_>>(),
            [
                (0.0, 359.5, 1.234, false),
                (0.0001, 0.0, 0.0, true),
                (0.0002, 0.5, 0.0, true)
            ]
        );
    }

    #[test]
    fn angles_wrap_and_round() {
        let step = (1.0f64.to_radians() as f32) as f64;
        assert_eq!(angle_deg(359.0 * step), 359.0);
        assert_eq!(angle_deg(-std::f64::consts::FRAC_PI_2), 270.0);
        assert_eq!(angle_deg(2.0 * std::f64::consts::PI), 0.0);
        assert_eq!(angle_deg(-1e-12).to_bits(), 0.0f64.to_bits());
        // The turn comes off exactly: on the 10⁻⁴° grid, not 269.99990000000003.
        assert_eq!(angle_deg((-90.0001f64).to_radians()), 269.9999);
        assert_eq!(angle_deg((725.5f64).to_radians()), 5.5);
        assert_eq!(angle_deg(f64::NAN), 0.0);
        let half = decimal_of_f32(0.5f64.to_radians() as f32);
        for i in 0..720 {
            assert_eq!(angle_deg(f64::from(i) * half), f64::from(i) * 0.5, "{i}");
        }
    }
}
