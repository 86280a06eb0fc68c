//! Real robots' logs, in the formats their authors published them, read into hilsim
//! [`Recording`](hilsim_recording::Recording)s:
//!
//! - [`coreslam`]: the CoreSLAM data set's `.dat` (one scan a line with the wheel encoders'
//!   counts);
//! - [`carmen`]: CARMEN logs (`.log`, `.clf`): `FLASER`, `ROBOTLASER1`, `ODOM`, `TRUEPOS`.
//!
//! The readers take the log's text (see [`read_text`] for a file, gzipped or not) and never
//! print; a CARMEN log's bad lines are skipped and described in notes, not refused.
#![warn(missing_docs)]

pub mod carmen;
pub mod coreslam;
mod error;
mod log_file;
mod text;

pub use carmen::{read_carmen, CarmenOptions, Clock, Poses};
pub use coreslam::{read_coreslam, CoreSlamOptions};
pub use error::LogError;
pub use log_file::{import_log, read_log, LogImport, LogKind};
pub use text::{read_text, MAX_TEXT_BYTES};
