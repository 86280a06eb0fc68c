//! Counts over accepted packets: what `hilsim decode` reports besides the decoder's own counts.

use std::collections::BTreeMap;

use super::packet::{Packet, READINGS_PER_PACKET};

/// Reading flags and motor speed statistics over a stream of accepted packets.
///
/// Memory stays bounded on an endless live stream: speeds are kept as a histogram of the
/// wire's fixed-point values (at most 65,536 distinct), which also makes the median exact.
///
/// ```
/// use hilsim_lidar_protocols::xv11::{Packet, PacketSummary};
///
/// let mut summary = PacketSummary::new();
/// assert_eq!(summary.rpm_median(), 0.0); // no packets: 0.0, never NaN
/// for rpm in [290.0, 300.0, 310.0, 500.0] {
///     summary.add(&Packet { rpm_fixed: (rpm * 64.0) as u16, ..Packet::default() });
/// }
/// assert_eq!(summary.readings(), 16);
/// assert_eq!((summary.rpm_min(), summary.rpm_median(), summary.rpm_max()), (290.0, 305.0, 500.0));
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PacketSummary {
    packets: u64,
    invalid: u64,
    strength_warning: u64,
    rpm_fixed_counts: BTreeMap<u16, u64>,
}

impl PacketSummary {
    /// A summary of no packets.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            packets: 0,
            invalid: 0,
            strength_warning: 0,
            rpm_fixed_counts: BTreeMap::new(),
        }
    }

    /// Counts one accepted packet.
    pub fn add(&mut self, packet: &Packet) {
        self.packets += 1;
        for reading in &packet.readings {
            self.invalid += u64::from(reading.invalid);
            self.strength_warning += u64::from(reading.strength_warning);
        }
        *self.rpm_fixed_counts.entry(packet.rpm_fixed).or_insert(0) += 1;
    }

    /// Packets counted.
    #[must_use]
    pub const fn packets(&self) -> u64 {
        self.packets
    }

    /// Readings counted: 4 per packet.
    #[must_use]
    pub const fn readings(&self) -> u64 {
        self.packets * READINGS_PER_PACKET as u64
    }

    /// Readings with the *invalid data* flag.
    #[must_use]
    pub const fn invalid(&self) -> u64 {
        self.invalid
    }

    /// Readings with the *strength warning* flag.
    #[must_use]
    pub const fn strength_warning(&self) -> u64 {
        self.strength_warning
    }

    /// The lowest motor speed in rpm; 0.0 when no packet was counted.
    #[must_use]
    pub fn rpm_min(&self) -> f64 {
        self.rpm_fixed_counts
            .keys()
            .next()
            .map_or(0.0, |&fixed| fixed_to_rpm(fixed))
    }

    /// The highest motor speed in rpm; 0.0 when no packet was counted.
    #[must_use]
    pub fn rpm_max(&self) -> f64 {
        self.rpm_fixed_counts
            .keys()
            .next_back()
            .map_or(0.0, |&fixed| fixed_to_rpm(fixed))
    }

    /// The median motor speed in rpm (the mean of the two middle values for an even count);
    /// 0.0 when no packet was counted.
    #[must_use]
    pub fn rpm_median(&self) -> f64 {
        if self.packets == 0 {
            return 0.0;
        }
        // 0-based ranks of the middle value(s): equal for an odd count.
        let low_rank = (self.packets - 1) / 2;
        let high_rank = self.packets / 2;
        let (mut low, mut high) = (None, None);
        let mut seen = 0;
        for (&fixed, &count) in &self.rpm_fixed_counts {
            seen += count;
            if low.is_none() && seen > low_rank {
                low = Some(fixed);
            }
            if seen > high_rank {
                high = Some(fixed);
                break;
            }
        }
        match (low, high) {
            (Some(low), Some(high)) => (fixed_to_rpm(low) + fixed_to_rpm(high)) / 2.0,
            // Unreachable: the counts sum to `packets`, so both ranks are found.
            _ => 0.0,
        }
    }
}

fn fixed_to_rpm(fixed: u16) -> f64 {
    f64::from(fixed) / 64.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::xv11::Reading;

    fn packet_at(rpm_fixed: u16) -> Packet {
        Packet {
            rpm_fixed,
            ..Packet::default()
        }
    }

    #[test]
    fn empty_summary_reports_zeros_not_nan() {
        let summary = PacketSummary::new();
        assert_eq!(summary.readings(), 0);
        assert_eq!(summary.rpm_min(), 0.0);
        assert_eq!(summary.rpm_median(), 0.0);
        assert_eq!(summary.rpm_max(), 0.0);
    }

    #[test]
    fn median_of_odd_and_even_counts_with_repeats() {
        let mut summary = PacketSummary::new();
        for fixed in [640, 64, 64, 6400, 128] {
            summary.add(&packet_at(fixed));
        }
        assert_eq!(summary.rpm_median(), 2.0); // 1, 1, 2, 10, 100
        summary.add(&packet_at(640));
        assert_eq!(summary.rpm_median(), 6.0); // 1, 1, 2 | 10, 10, 100
        assert_eq!((summary.rpm_min(), summary.rpm_max()), (1.0, 100.0));
    }

    #[test]
    fn flags_are_counted_per_reading() {
        let mut summary = PacketSummary::new();
        summary.add(&Packet {
            readings: [
                Reading::error(0x21),
                Reading::error(0x52),
                Reading {
                    strength_warning: true,
                    ..Reading::error(0x35)
                },
                Reading {
                    strength_warning: true,
                    ..Reading::distance(500, 3)
                },
            ],
            ..Packet::default()
        });
        assert_eq!((summary.invalid(), summary.strength_warning()), (3, 2));
        assert_eq!((summary.packets(), summary.readings()), (1, 4));
    }
}
