//! YDLIDAR X4: the command/response protocol and the point cloud packets of the "YDLIDAR X4
//! Development Manual" (EAI), as `docs/formats/ydlidar-x4.md` describes it.
//!
//! The host sends `A5 cmd`; the unit answers with `A5 5A len:30|mode:2 type` and its data. While
//! scanning it sends packets `AA 55 CT LSN FSA LSA CS` + LSN samples; a sample's angle is
//! interpolated between FSA and LSA and corrected for its distance (the manual's `AngCorrect`).
//!
//! ```
//! use hilsim_lidar_protocols::ydlidar::{YdlidarDecoder, YdlidarUnit};
//! use hilsim_lidar_protocols::{HostDecoder, Output, Unit, UnitReading};
//!
//! let mut unit = YdlidarUnit::new();
//! let mut out = Output::new();
//! unit.host_wrote(&[0xA5, 0x60], 0.0, &mut out); // start scan
//! assert_eq!(out.bytes, [0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81]);
//! for i in 0..3 {
//!     let reading = UnitReading {
//!         t_s: f64::from(i) * 2e-4, rev: 0, index: i, angle_deg: 10.0 + 0.5 * f64::from(i),
//!         distance_mm: 1000, intensity: 0, rev_hz: 7.0, starts_revolution: i == 0,
//!     };
//!     unit.push(&reading, &mut out);
//! }
//! unit.host_wrote(&[0xA5, 0x65], 0.1, &mut out); // stop: the held readings go first
//! let mut points = Vec::new();
//! YdlidarDecoder::new().feed(&out.bytes, &mut points);
//! assert_eq!(points.len(), 3);
//! assert!((points[2].angle_deg - 11.0).abs() < 0.1);
//! assert_eq!(points[0].rev_hz, Some(7.0));
//! ```

mod decoder;
mod packet;
mod unit;

#[cfg(test)]
mod tests;

pub use decoder::YdlidarDecoder;
pub use packet::{angle_correction_q6, Packet, HEADER_LEN, MAX_SAMPLES, PH};
pub use unit::YdlidarUnit;

/// Command codes (X4 Development Manual, "System commands"; `lds2d/drivers/ydlidar.py` sends
/// 0x00 before 0x60, the SDK's force stop, taken here as a stop).
pub mod cmd {
    /// Start scanning.
    pub const SCAN: u8 = 0x60;
    /// Stop scanning; no reply.
    pub const STOP: u8 = 0x65;
    /// Force stop (the YDLIDAR SDK's); no reply.
    pub const FORCE_STOP: u8 = 0x00;
    /// Device information.
    pub const GET_INFO: u8 = 0x90;
    /// Health status.
    pub const GET_HEALTH: u8 = 0x91;
    /// Soft restart; no reply.
    pub const RESTART: u8 = 0x80;
}

/// The first byte of a command and of a reply header.
pub const SYNC_BYTE: u8 = 0xA5;
/// The second byte of a reply header.
pub const SYNC_BYTE2: u8 = 0x5A;

/// What the emulated unit reports to the device information command: model 6 (the X4's code
/// in the YDLIDAR SDK), firmware 1.5, hardware 1, a 16-byte serial number.
pub mod info {
    /// Model code.
    pub const MODEL: u8 = 6;
    /// Firmware major version: the field's high byte, as the YDLIDAR SDK and `PyLidar3` read it
    /// (the X2 manual's prose says the opposite; its drivers win).
    pub const FIRMWARE_MAJOR: u8 = 1;
    /// Firmware minor version: the low byte.
    pub const FIRMWARE_MINOR: u8 = 5;
    /// Hardware version.
    pub const HARDWARE: u8 = 1;
    /// Serial number, 16 bytes.
    pub const SERIAL: [u8; 16] = [2, 0, 2, 6, 0, 1, 0, 1, 0, 0, 0, 0, 0, 0, 4, 2];
    /// The 20 bytes of the reply: model, firmware (2 bytes), hardware, serial number.
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
