//! Between the emulated lidar and the wire: readings into whole revolutions of Neato packets,
//! decoded revolutions back into recording rows with their timestamps, and readings into the
//! terms of any other unit's protocol ([`to_unit_reading`]).

use hilsim_lidar_protocols::{Direction, UnitReading, UnitSpec};
use hilsim_recording::LidarSample;

use crate::lidar::{next_revolution_start_s, reading_time_s, LidarReading};
use crate::neato_packet::{encode_revolution, Reading, Revolution, READINGS_PER_REVOLUTION};

/// The wire form of one emulated reading. An invalid reading carries its error code and no
/// strength, as real units send it.
#[must_use]
pub fn to_wire(reading: &LidarReading) -> Reading {
    match reading.error_code {
        Some(code) => Reading::error(code),
        None => Reading {
            distance_mm: reading.distance_mm,
            invalid: false,
            strength_warning: reading.warning,
            strength: reading.strength,
        },
    }
}

/// An emulated reading in the terms of a unit's protocol: its angle from the unit's 0° in the
/// unit's direction, no distance when invalid, its strength in one byte.
#[must_use]
pub fn to_unit_reading(reading: &LidarReading, spec: &UnitSpec) -> UnitReading {
    let angle_deg = match spec.direction {
        Direction::CounterClockwise => reading.angle_deg,
        Direction::Clockwise => (360.0 - reading.angle_deg).rem_euclid(360.0),
    };
    UnitReading {
        t_s: reading.t_s,
        rev: reading.rev,
        index: u32::from(reading.index),
        // 360 - 1e-13 is 360 in the unit's terms.
        angle_deg: if angle_deg >= 360.0 { 0.0 } else { angle_deg },
        distance_mm: if reading.error_code.is_some() {
            0
        } else {
            u32::from(reading.distance_mm)
        },
        intensity: u8::try_from(reading.strength).unwrap_or(u8::MAX),
        rev_hz: reading.rev_hz,
        starts_revolution: reading.index == 0,
    }
}

/// One complete revolution ready for the wire.
#[derive(Debug, Clone, PartialEq)]
pub struct RevolutionFrame {
    /// Revolution counter.
    pub rev: u64,
    /// Motor speed the packets report.
    pub rpm: f64,
    /// When its first reading was taken, simulation seconds.
    pub start_s: f64,
    /// The 360 readings, index = angle in degrees.
    pub readings: [Reading; READINGS_PER_REVOLUTION],
}

impl RevolutionFrame {
    /// Appends the revolution's 90 packets (1,980 bytes) to `out`.
    pub fn encode(&self, out: &mut Vec<u8>) {
        encode_revolution(&self.readings, self.rpm, out);
    }

    /// When the reading at `angle` was taken, simulation seconds.
    #[must_use]
    pub fn reading_time_s(&self, angle: u16) -> f64 {
        reading_time_s(self.start_s, angle, self.rpm)
    }
}

/// Collects emulated readings into complete revolutions; a revolution the run ended inside is
/// never emitted (real units only send whole revolutions).
#[derive(Debug, Clone)]
pub struct RevolutionCollector {
    current: Option<(u64, f64)>,
    readings: [Reading; READINGS_PER_REVOLUTION],
    filled: usize,
}

impl Default for RevolutionCollector {
    fn default() -> Self {
        Self {
            current: None,
            readings: [Reading::default(); READINGS_PER_REVOLUTION],
            filled: 0,
        }
    }
}

impl RevolutionCollector {
    /// Adds the next reading; `rpm` is the motor speed of its revolution
    /// ([`crate::Lidar::rpm_of_revolution`]). Returns the revolution it completes.
    pub fn push(&mut self, reading: &LidarReading, rpm: f64) -> Option<RevolutionFrame> {
        if self.current.map(|(rev, _)| rev) != Some(reading.rev) {
            self.current = Some((reading.rev, reading.t_s));
            self.filled = 0;
        }
        self.readings[usize::from(reading.index)] = to_wire(reading);
        self.filled += 1;
        let (rev, start_s) = self.current?;
        if usize::from(reading.index) != READINGS_PER_REVOLUTION - 1
            || self.filled != READINGS_PER_REVOLUTION
        {
            return None;
        }
        Some(RevolutionFrame {
            rev,
            rpm,
            start_s,
            readings: self.readings,
        })
    }
}

/// Rebuilds recording rows from decoded revolutions, timing each reading from the motor speed
/// the packets report, exactly as the emulator timed it. The first revolution received starts
/// at t = 0; a revolution's time advances whether or not all its packets arrived.
#[derive(Debug, Clone, Default)]
pub struct WireTimeline {
    next_start_s: f64,
    next_rev: u64,
}

impl WireTimeline {
    /// A timeline starting at t = 0, revolution 0.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// The rows of one decoded revolution (its lost packets' readings are absent), appended to
    /// `out`. The true range is unknown on the wire.
    pub fn push(&mut self, revolution: &Revolution, out: &mut Vec<LidarSample>) {
        let Some(rpm) = revolution.packets.iter().flatten().map(|p| p.rpm()).next() else {
            return;
        };
        let (rev, start_s) = (self.next_rev, self.next_start_s);
        for (angle, reading) in revolution.readings() {
            out.push(LidarSample {
                t_s: hilsim_sim::exact_time_s(reading_time_s(start_s, angle, rpm)),
                rev,
                angle_deg: f64::from(angle),
                range_m: reading.range_m().unwrap_or(0.0),
                strength: reading.strength,
                invalid: reading.invalid,
                warning: reading.strength_warning,
                true_range_m: None,
            });
        }
        self.next_rev += 1;
        self.next_start_s = next_revolution_start_s(start_s, rpm);
    }
}
