//! A recorded run's twin: the world the run took place in (the user's map, or a map built from
//! the run's own scans at its path), a scenario that replays the run in it (the robot follows
//! the log's path, the lidar takes the log's scans at their times and beam angles), and the
//! twin's readings set against the log's, reading for reading.
//!
//! `hilsim world REC --out SCENARIO.toml` is [`build_world`], [`TwinWorld::write`] and
//! [`compare`]; `hilsim record SCENARIO.toml` then makes the twin's recording.

mod declare;
mod error;
mod fit;
mod local_map;
mod path;
mod raster;
mod scans;
mod world;

pub use error::TwinError;
pub use fit::{compare, TwinFit, COMPARED_WITHIN_M};
pub use path::{find_path, scan_points, FoundPath, PoseSource};
pub use raster::map_of_world;
pub use scans::{for_each_scan, scan_of, LogScan, ScanCounts};
pub use world::{
    build_world, Declared, TwinFiles, TwinMap, TwinWorld, WorldOptions, SCENARIO_FIRST_LINE,
    SCENARIO_KIND,
};
