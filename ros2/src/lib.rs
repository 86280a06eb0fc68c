//! ROS bags in and out: a ROS 2 bag (MCAP or SQLite3 storage, CDR messages) or a ROS 1 bag
//! (rosbag format 2.0, ROS 1 messages: [`ros1`]) read into a hilsim recording ([`import()`]),
//! the lidar's mount taken from the bag's TF; and a recording written as an MCAP file of
//! standard ROS 2 messages that `ros2 bag play`, RViz and Foxglove read ([`export()`]).
//!
//! Bags stream: an import holds one record (a message, or a chunk being decompressed) at a
//! time, whatever the bag's size. The crate knows the recording format only through
//! `hilsim-recording`; a scenario's world reaches the exporter as plain shapes ([`World`]).
//!
//! ```
//! use hilsim_recording::{CommandSample, Meta, Recording};
//! let dir = tempfile::tempdir().unwrap();
//! let mut rec = Recording::new(Meta::default());
//! rec.commands.push(CommandSample { t_s: 0.5, left_mps: 0.1, right_mps: 0.2 });
//! let bag = dir.path().join("run.mcap");
//! hilsim_ros2::export(&rec, None, &bag).unwrap();
//! let out = dir.path().join("back");
//! hilsim_ros2::import(&bag, &out, &hilsim_ros2::ImportOptions::default()).unwrap();
//! let back = Recording::read_dir(&out).unwrap();
//! assert_eq!(back.commands[0].t_s, 0.5);
//! assert!((back.commands[0].right_mps - 0.2).abs() < 1e-12);
//! ```
#![warn(missing_docs)]

pub mod bag;
mod cdr;
pub mod definitions;
mod error;
mod export;
mod import;
mod import_summary;
pub mod msgs;
pub mod ros1;
mod tf;
pub mod topics;

pub use error::Error;

/// An MCAP file, as a single-file output recognises a previous one: by the format's magic.
pub const MCAP_FILE: hilsim_recording::FileKind = hilsim_recording::FileKind {
    name: "an MCAP file",
    starts_with: b"\x89MCAP0\r\n",
};
pub use export::{
    export, export_dir, export_with, ExportOptions, ExportReport, World, MAX_SCAN_READINGS,
    START_NS,
};
pub use hilsim_recording::decimal_of_f32;
pub use import::{
    angle_deg, import, read_file, Converter, Encoding, Fault, FlagError, ImportFlags,
    ImportOptions, ImportReport,
};
pub use tf::Source as TfSource;
pub use topics::{Kind, Role};
