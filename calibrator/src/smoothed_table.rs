//! The smoothed distances as a table: `hilsim smooth`'s CSV.

use std::fmt::Write as _;

use hilsim_recording::FileKind;

use crate::smoothing::Estimate;

/// The table's header line.
const SMOOTHED_CSV_HEADER: &str = "t_s,distance_m,sd_m\n";

/// The table of [`smoothed_csv`], as a previous one is recognised.
pub const SMOOTHED_CSV: FileKind = FileKind {
    name: "a table of smoothed distances",
    starts_with: SMOOTHED_CSV_HEADER.as_bytes(),
};

/// `t_s,distance_m,sd_m`: a row per estimate, its standard deviation the root of its variance
/// (0 for a variance rounded below 0).
#[must_use]
pub fn smoothed_csv(estimates: &[Estimate]) -> String {
    let mut csv = String::from(SMOOTHED_CSV_HEADER);
    for e in estimates {
        let sd = e.variance_m2.max(0.0).sqrt();
        let _ = writeln!(csv, "{},{},{sd}", e.t_s, e.distance_m);
    }
    csv
}
