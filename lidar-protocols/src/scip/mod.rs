//! The Hokuyo URG-04LX's serial protocol, SCIP 2.0, as described in
//! `docs/formats/scip-urg-04lx.md`: the unit's side ([`ScipUnit`]) and the host's
//! ([`ScipDecoder`]).
//!
//! A pure state machine: nothing here opens a port, reads a clock or prints.
//!
//! ```
//! use hilsim_lidar_protocols::scip::{ScipDecoder, ScipUnit};
//! use hilsim_lidar_protocols::{HostDecoder, Output, Unit, UnitReading};
//!
//! let mut unit = ScipUnit::new();
//! let mut out = Output::new();
//! unit.host_wrote(b"GD0384038401\n", 0.0, &mut out);
//! assert_eq!(out.bytes, b"GD0384038401\n10Q\n\n"); // status 10: the laser is off
//! out.clear();
//! unit.host_wrote(b"BM\nGD0384038401\n", 0.0, &mut out);
//! assert_eq!(out.bytes, b"BM\n00P\n\n");
//! for index in 0..=681 {
//!     let reading = UnitReading {
//!         t_s: 0.01 + f64::from(index) * 0.1 / 1024.0,
//!         rev: 0,
//!         index,
//!         angle_deg: 0.0, // the codec takes the step from the index
//!         distance_mm: 1234,
//!         intensity: 0,
//!         rev_hz: 10.0,
//!         starts_revolution: index == 0,
//!     };
//!     unit.push(&reading, &mut out);
//! }
//! let mut decoder = ScipDecoder::new();
//! let mut points = Vec::new();
//! decoder.feed(&out.bytes, &mut points);
//! assert_eq!(points.len(), 1);
//! assert_eq!((points[0].angle_deg, points[0].distance_mm), (0.0, 1234));
//! ```

mod commands;
mod decoder;
mod encoding;
mod unit;

pub use commands::{parse, Command, ScanRequest, Status};
pub use decoder::ScipDecoder;
pub use encoding::{
    checksum, clock_ms, decode, encode, step_angle_deg, FIRST_STEP, FRONT_STEP, LAST_STEP,
    MAX_DISTANCE_MM, MAX_STEP, MIN_DISTANCE_MM, NON_MEASURABLE_CODE, NO_OBJECT_CODE, STEPS_PER_REV,
};
pub use unit::ScipUnit;

#[cfg(test)]
mod tests;
