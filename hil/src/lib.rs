//! Hardware in the loop without the hardware: serial links behind one trait ([`SerialLink`]),
//! pseudo-terminal pairs, a paced lidar streamer that never lets a reader stall the simulation,
//! `hilsim serve`, the loopback that sends the lidar through a pty and the decoder for
//! `hilsim run --via serial`, and firmware in the loop (`hilsim hil`: [`hil_run`], with the
//! robot [`command_port`], the [`motion`] controller and the [`firmware`] process).
#![warn(missing_docs)]

pub mod command_port;
pub mod decode;
mod decode_capture;
mod device;
pub mod escaped;
pub mod faults;
pub mod firmware;
pub mod hil_run;
mod link;
pub mod loopback;
pub mod motion;
pub mod process;
mod pty;
pub mod serve;
mod serve_model;
mod serve_setup;
mod streamer;
mod unit_streamer;

pub use decode_capture::{decode_capture, CaptureError, Decoded};
pub use device::{DeviceLink, XV11_BAUD};
pub use link::{MemoryLink, SerialLink};
pub use pty::PtyLink;
pub use serve_model::{serve_model, ServeOptions};
pub use serve_setup::ServeSetupError;
pub use streamer::{
    Pacing, StreamStats, Streamer, BACKLOG_LIMIT, FAST_STALL_GRACE, LOSSLESS_TIMEOUT, STALL_DETECT,
};
pub use unit_streamer::UnitStreamer;
