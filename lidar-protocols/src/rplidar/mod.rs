//! Slamtec RPLIDAR A1: the request/response protocol of the "RPLIDAR Interface Protocol and
//! Application Notes" (Slamtec, v2.1), as `docs/formats/rplidar-a1.md` describes it.
//!
//! The host sends requests `A5 cmd` (a command with bit 7 set adds `size payload checksum`);
//! the unit answers with a 7-byte response descriptor `A5 5A len:30|mode:2 type` and its data:
//! one reply for GET_INFO, GET_HEALTH and GET_SAMPLERATE, and while scanning a stream of 5-byte
//! measurement nodes (SCAN, FORCE_SCAN) or 84-byte express capsules (EXPRESS_SCAN).
//!
//! ```
//! use hilsim_lidar_protocols::rplidar::{RplidarDecoder, RplidarUnit};
//! use hilsim_lidar_protocols::{HostDecoder, Output, Unit, UnitReading};
//!
//! let mut unit = RplidarUnit::new();
//! let mut out = Output::new();
//! unit.host_wrote(&[0xA5, 0x20], 0.0, &mut out); // SCAN
//! assert_eq!(out.bytes, [0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81]);
//! let reading = UnitReading {
//!     t_s: 0.001, rev: 0, index: 0, angle_deg: 12.5, distance_mm: 1500, intensity: 188,
//!     rev_hz: 5.5, starts_revolution: true,
//! };
//! unit.push(&reading, &mut out);
//! let mut points = Vec::new();
//! RplidarDecoder::new().feed(&out.bytes, &mut points);
//! assert_eq!((points[0].angle_deg, points[0].distance_mm), (12.5, 1500));
//! assert!(points[0].starts_revolution);
//! ```

mod command;
mod decoder;
mod express;
mod node;
mod unit;

#[cfg(test)]
mod tests;

pub use command::{request, Request, MAX_PAYLOAD_LEN};
pub use decoder::RplidarDecoder;
pub use express::{Cabin, Capsule, CAPSULE_LEN};
pub use node::{Node, NODE_LEN};
pub use unit::RplidarUnit;

/// The first byte of every request and of every response descriptor.
pub const SYNC_BYTE: u8 = 0xA5;
/// The second byte of a response descriptor.
pub const SYNC_BYTE2: u8 = 0x5A;
/// Bytes in a response descriptor.
pub const DESCRIPTOR_LEN: usize = 7;

/// Request codes (protocol v2.1, "Request packets' format"; the drivers `rplidar-roboticia`
/// and `pyrplidar` use the same values).
pub mod cmd {
    /// Leave the scanning state; no reply.
    pub const STOP: u8 = 0x25;
    /// Reboot the core; no descriptor.
    pub const RESET: u8 = 0x40;
    /// Start scanning: 5-byte nodes.
    pub const SCAN: u8 = 0x20;
    /// Start scanning whatever the motor speed: 5-byte nodes.
    pub const FORCE_SCAN: u8 = 0x21;
    /// Start the legacy express scan: 84-byte capsules (payload: working mode + 4 reserved).
    pub const EXPRESS_SCAN: u8 = 0x82;
    /// Model, firmware, hardware, serial number.
    pub const GET_INFO: u8 = 0x50;
    /// Status and error code.
    pub const GET_HEALTH: u8 = 0x52;
    /// Sample durations of the standard and express scans.
    pub const GET_SAMPLERATE: u8 = 0x59;
    /// Motor PWM (A2's; the A1 turns its motor by the DTR line and takes it without effect).
    pub const SET_MOTOR_PWM: u8 = 0xF0;
}

/// Response data types (the descriptor's last byte).
pub mod answer {
    /// Measurement nodes.
    pub const MEASUREMENT: u8 = 0x81;
    /// Legacy express capsules.
    pub const CAPSULED: u8 = 0x82;
    /// GET_INFO.
    pub const DEVICE_INFO: u8 = 0x04;
    /// GET_HEALTH.
    pub const DEVICE_HEALTH: u8 = 0x06;
    /// GET_SAMPLERATE.
    pub const SAMPLE_RATE: u8 = 0x15;
}

/// A response descriptor: `A5 5A`, then `len | mode << 30` (u32 LE), then the data type.
/// Mode 0 is a single response, 1 a stream of `len`-byte responses.
#[must_use]
pub fn descriptor(len: u32, multiple: bool, data_type: u8) -> [u8; DESCRIPTOR_LEN] {
    let word = (len & 0x3FFF_FFFF) | (u32::from(multiple) << 30);
    let [a, b, c, d] = word.to_le_bytes();
    [SYNC_BYTE, SYNC_BYTE2, a, b, c, d, data_type]
}

/// What the emulated unit reports to GET_INFO: an A1M8 (model 0x18, firmware 1.29, hardware 7,
/// the values A1M8 units report to Slamtec's `ultra_simple` and `rplidar-roboticia`).
pub mod info {
    /// Model byte.
    pub const MODEL: u8 = 0x18;
    /// Firmware major version.
    pub const FIRMWARE_MAJOR: u8 = 1;
    /// Firmware minor version.
    pub const FIRMWARE_MINOR: u8 = 29;
    /// Hardware version.
    pub const HARDWARE: u8 = 7;
    /// Serial number, 16 bytes (drivers print it as 32 hex digits).
    pub const SERIAL: [u8; 16] = *b"HILSIM-RPLIDARA1";
    /// The 20 bytes of the GET_INFO reply: model, firmware minor, firmware major, hardware,
    /// serial.
    #[must_use]
    pub fn bytes() -> [u8; 20] {
        let mut b = [0; 20];
        b[0] = MODEL;
        b[1] = FIRMWARE_MINOR;
        b[2] = FIRMWARE_MAJOR;
        b[3] = HARDWARE;
        b[4..].copy_from_slice(&SERIAL);
        b
    }
}

/// The A1's sample durations, µs (datasheet: 2,000 samples/s standard, 4,000 express).
pub const T_STANDARD_US: u16 = 500;
/// See [`T_STANDARD_US`].
pub const T_EXPRESS_US: u16 = 250;
