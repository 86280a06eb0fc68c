//! The serial protocols of the cheap 2-D lidars robot builders use, as pure state machines:
//! nothing here opens a port, reads a clock or prints.
//!
//! Each protocol has two sides:
//! - the unit's ([`Unit`]): the emulated head's readings into the unit's packets, and for a
//!   command-driven unit the host's commands into its replies (start, stop, info, health);
//! - the host's ([`HostDecoder`]): the bytes a unit sends back into its readings, as a driver
//!   reads them (`hilsim decode --model`).
//!
//! Which unit a scenario carries is a [`LidarModel`]; what the unit is (its rate, its readings
//! per revolution, its direction, its limits) is its [`UnitSpec`].
//!
//! The Neato XV-11's codec is [`xv11`]; the others are [`rplidar`] (Slamtec RPLIDAR A1),
//! [`lds01`] (Hitachi-LG HLS-LFCD2, the TurtleBot3's LDS-01), [`lds02rr`] (Xiaomi LDS02RR),
//! [`ld06`] (LDROBOT LD06), [`ydlidar`] (YDLIDAR X4) and [`scip`] (Hokuyo URG-04LX, SCIP 2.0).
#![warn(missing_docs)]

mod framing;
pub mod ld06;
pub mod lds01;
pub mod lds02rr;
mod model;
pub mod rplidar;
pub mod scip;
mod unit;
pub mod xv11;
pub mod ydlidar;

pub use model::{Direction, LidarModel, Sampling, UnitSpec};
pub use unit::{DecodeStats, HostDecoder, Output, PacketSpan, Point, Unit, UnitReading};

/// The unit's side of `model`'s protocol (`None` for the XV-11, whose revolutions [`xv11`]
/// encodes whole).
#[must_use]
pub fn unit_for(model: LidarModel) -> Option<Box<dyn Unit>> {
    match model {
        LidarModel::Xv11 => None,
        LidarModel::Lds01 => Some(Box::new(lds01::Lds01Unit::new())),
        LidarModel::Lds02rr => Some(Box::new(lds02rr::Lds02rrUnit::new())),
        LidarModel::Ld06 => Some(Box::new(ld06::Ld06Unit::new())),
        LidarModel::RplidarA1 => Some(Box::new(rplidar::RplidarUnit::new())),
        LidarModel::YdlidarX4 => Some(Box::new(ydlidar::YdlidarUnit::new())),
        LidarModel::Urg04lx => Some(Box::new(scip::ScipUnit::new())),
    }
}

/// The host's side of `model`'s protocol (`None` for the XV-11: [`xv11::Decoder`]).
#[must_use]
pub fn decoder_for(model: LidarModel) -> Option<Box<dyn HostDecoder>> {
    match model {
        LidarModel::Xv11 => None,
        LidarModel::Lds01 => Some(Box::new(lds01::Lds01Decoder::new())),
        LidarModel::Lds02rr => Some(Box::new(lds02rr::Lds02rrDecoder::new())),
        LidarModel::Ld06 => Some(Box::new(ld06::Ld06Decoder::new())),
        LidarModel::RplidarA1 => Some(Box::new(rplidar::RplidarDecoder::new())),
        LidarModel::YdlidarX4 => Some(Box::new(ydlidar::YdlidarDecoder::new())),
        LidarModel::Urg04lx => Some(Box::new(scip::ScipDecoder::new())),
    }
}
