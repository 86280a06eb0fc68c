//! The run report (`hilsim report`, `hilsim run --report`): one self-contained HTML page with
//! the world to scale, the true and the dead-reckoned paths, lidar scans in the world frame
//! (raw and calibrated), each range sensor's error against the true distance with its declared
//! and fitted bias curves, the sensors over time and the calibration with its standard errors.
//!
//! `svg` is the project's one plotting module (the diagnosis draws with it too). The crate
//! prints nothing and reads no files: it turns values into a string.

#![warn(missing_docs)]

pub mod colours;
mod errors;
pub mod map;
mod page;
mod report_dir;
pub mod svg;
mod table;
mod timelines;
pub mod view;

pub use map::Overlay;
pub use page::{is_report, map_svg, render, render_with, GENERATOR};
pub use report_dir::{check_report_dir, write_report_files, ReportDirError};
pub use view::Inputs;

/// The most rows of one table a report draws from ([`hilsim_recording::MAX_ROWS_HELD`]).
pub const MAX_ROWS: u64 = hilsim_recording::MAX_ROWS_HELD;

/// The page of `hilsim report`: the recording named `name` (the part `thinning` kept), the
/// scenario it is a run of and the calibrations to show.
#[must_use]
pub fn recording_page(
    name: &str,
    recording: &hilsim_recording::Recording,
    thinning: &hilsim_recording::Thinning,
    scenario: Option<&hilsim_sim::Scenario>,
    calibrations: &[hilsim_calibrator::Calibration],
) -> String {
    render(Inputs {
        title: &format!("hilsim report: {name}"),
        recording,
        recording_name: &drawn_name(name, thinning),
        scenario,
        calibrations,
        truth_estimated: false,
    })
}

/// The recording's name as a page gives it: with which part was drawn, when not all of it.
#[must_use]
pub fn drawn_name(name: &str, thinning: &hilsim_recording::Thinning) -> String {
    if thinning.is_whole() {
        name.to_string()
    } else {
        format!(
            "{name}, drawn from {} (longer than a report draws whole)",
            thinning.describe()
        )
    }
}
