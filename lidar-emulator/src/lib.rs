//! Sensor emulators for hilsim, driven by the simulated world: the papers' range model, the Neato
//! XV-11 triangulation lidar, the sonar and the wheel-slip odometer, their in-process delivery
//! ([`Emulation`]), and the Neato XV-11 serial packet codec.
#![warn(missing_docs)]

pub mod effects;
mod emulation;
pub mod lidar;
pub mod normal;
mod odometer;
pub mod prediction;
mod range_model;
mod sonar;
mod unit_scans;
pub mod wire;

/// The Neato XV-11 serial packet codec (its home is `hilsim_lidar_protocols::xv11`).
pub use hilsim_lidar_protocols::xv11 as neato_packet;

pub use emulation::{Emulation, Run, StepSamples};
pub use lidar::{Lidar, LidarReading};
pub use odometer::Odometer;
pub use range_model::{ModelError, RangeModel, RangeModelBuilder};
pub use sonar::Sonar;
