//! The unit's side: requests in, descriptors, replies and the scan stream out.

use super::command::{Request, RequestParser};
use super::express::{CapsuleEncoder, CAPSULE_LEN};
use super::node::{Node, NODE_LEN};
use super::{answer, cmd, descriptor, info, T_EXPRESS_US, T_STANDARD_US};
use crate::{Output, Unit, UnitReading};

/// What the unit is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scan {
    Idle,
    Standard,
    Express,
}

/// A Slamtec RPLIDAR A1 on its serial line: answers STOP, RESET, SCAN, FORCE_SCAN,
/// EXPRESS_SCAN (legacy capsules), GET_INFO, GET_HEALTH, GET_SAMPLERATE and SET_MOTOR_PWM as
/// the A1 does, and while scanning sends each reading as a node (or 32 readings as a capsule).
///
/// Not emulated: RESET's boot text (the unit goes idle and sends nothing), GET_LIDAR_CONF and
/// the newer scan modes (an A1 of firmware 1.29 has none of them in its legacy express mode;
/// requests it does not know are dropped, as the A1 drops them).
#[derive(Debug, Clone)]
pub struct RplidarUnit {
    parser: RequestParser,
    scan: Scan,
    express: CapsuleEncoder,
}

impl Default for RplidarUnit {
    fn default() -> Self {
        Self::new()
    }
}

impl RplidarUnit {
    /// An idle unit, just powered.
    #[must_use]
    pub fn new() -> Self {
        Self {
            parser: RequestParser::new(),
            scan: Scan::Idle,
            express: CapsuleEncoder::new(),
        }
    }

    fn answer(&mut self, request: &Request, now_s: f64, out: &mut Output) {
        match request.cmd {
            cmd::STOP | cmd::RESET => self.scan = Scan::Idle,
            cmd::SCAN | cmd::FORCE_SCAN => {
                self.scan = Scan::Standard;
                out.packet(now_s, 2, false, |b| {
                    b.extend_from_slice(&descriptor(NODE_LEN as u32, true, answer::MEASUREMENT));
                });
            }
            // Working mode 0 is the legacy express scan, the only one an A1 of firmware 1.29
            // has; the request carries the mode and four reserved bytes.
            cmd::EXPRESS_SCAN if request.payload.first().copied().unwrap_or(0) == 0 => {
                self.scan = Scan::Express;
                self.express = CapsuleEncoder::new();
                out.packet(now_s, 2, false, |b| {
                    b.extend_from_slice(&descriptor(CAPSULE_LEN as u32, true, answer::CAPSULED));
                });
            }
            cmd::GET_INFO => out.packet(now_s, 2, false, |b| {
                b.extend_from_slice(&descriptor(20, false, answer::DEVICE_INFO));
                b.extend_from_slice(&info::bytes());
            }),
            // Status 0 (good), error code 0.
            cmd::GET_HEALTH => out.packet(now_s, 2, false, |b| {
                b.extend_from_slice(&descriptor(3, false, answer::DEVICE_HEALTH));
                b.extend_from_slice(&[0, 0, 0]);
            }),
            cmd::GET_SAMPLERATE => out.packet(now_s, 2, false, |b| {
                b.extend_from_slice(&descriptor(4, false, answer::SAMPLE_RATE));
                b.extend_from_slice(&T_STANDARD_US.to_le_bytes());
                b.extend_from_slice(&T_EXPRESS_US.to_le_bytes());
            }),
            // SET_MOTOR_PWM and anything else: taken, no reply.
            _ => {}
        }
    }
}

impl Unit for RplidarUnit {
    fn host_wrote(&mut self, bytes: &[u8], now_s: f64, out: &mut Output) {
        for &byte in bytes {
            if let Some(request) = self.parser.push(byte) {
                self.answer(&request, now_s, out);
            }
        }
    }

    fn scanning(&self) -> bool {
        self.scan != Scan::Idle
    }

    fn push(&mut self, reading: &UnitReading, out: &mut Output) {
        let angle = if reading.angle_deg.is_finite() {
            reading.angle_deg.rem_euclid(360.0)
        } else {
            0.0
        };
        match self.scan {
            Scan::Idle => {}
            Scan::Standard => {
                let node = Node {
                    start: reading.starts_revolution,
                    quality: reading.intensity >> 2,
                    // Below 23,040 after rem_euclid and rounding (the modulo folds 360.0 to 0).
                    angle_q6: ((angle * 64.0).round() as u32 % (360 * 64)) as u16,
                    distance_q2: (u64::from(reading.distance_mm) * 4).min(0xFFFC) as u16,
                };
                out.packet(reading.t_s, 0, reading.starts_revolution, |b| {
                    b.extend_from_slice(&node.encode());
                });
            }
            Scan::Express => {
                if let Some((bytes, due, starts)) = self.express.push(
                    angle,
                    reading.distance_mm,
                    reading.t_s,
                    reading.starts_revolution,
                ) {
                    out.packet(due, 2, starts, |b| b.extend_from_slice(&bytes));
                }
            }
        }
    }
}
