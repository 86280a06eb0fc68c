//! Firmware in the loop (`hilsim hil`): the simulation in real time, its lidar streamed on one
//! pty, the robot command port on another, and the firmware under test as a child process
//! driving the wheels.
//!
//! One thread does it all, in a poll loop: each physics step is computed when its start time
//! comes on the wall clock (the model never reads the clock; this loop maps simulation time to
//! wall time), each lidar packet is written when its last reading has been taken
//! ([`Streamer::send_packet`] for the XV-11, [`crate::UnitStreamer::send_due`] for the other
//! units), and between those instants the loop sleeps in `ppoll` on the command port (and on
//! the lidar port of a unit that takes commands), so a request is answered as soon as it
//! arrives, from the sensor samples taken up to that instant. A `SetMotor` takes effect at the
//! next physics step.
//!
//! The run ends when its time is up, when the firmware exits, or at the first fault:
//! - the firmware **crashed**: it exited with a non-zero status or was killed by a signal;
//! - it **hung**: no request for the watchdog period ([`DEFAULT_WATCHDOG`], from the start and
//!   after every request);
//! - it **flooded** the command port: more than [`FloodLimits`] allow within a second;
//! - it **never read the lidar**: one watchdog period into the run it had taken less than one
//!   revolution of the stream (the streamer discards what a reader leaves behind, so this shows
//!   in its counts), or never started a unit that waits for its start command.
//!
//! Then the ports close (a firmware blocked on them sees them go), the firmware gets
//! [`HilConfig::firmware_grace`] to exit by itself, then `SIGTERM`, then `SIGKILL`
//! ([`Firmware::shut_down`]).

mod config;
mod flood;
mod lidar_wire;
mod packets;
mod report;
mod sensors;
mod session;
mod setup;
mod summary;

pub use config::{FloodLimits, HilConfig, DEFAULT_FIRMWARE_GRACE, DEFAULT_WATCHDOG};
pub use report::{Ending, Fault, HilReport};
pub use session::{run, run_with_progress, HilProgress};
pub use setup::{stop_on_signals, HilPorts, HilWorld};
