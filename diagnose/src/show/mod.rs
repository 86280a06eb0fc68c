//! Show: the diagnosis as the JSON object of `interfaces.md`, as text for people, and as
//! evidence for the eye: residuals against the located variable before and after the fix
//! (SVG, drawn with `hilsim_report::svg`) and an HTML page that holds them with the verdict.
//! Everything here returns strings; writing files is the caller's business.

mod format;
mod html;
mod json;
mod page;
mod svg;
mod text;

pub use self::html::html;
pub use self::json::to_json;
pub use self::page::{report_files, report_files_of, MAP_FILE};
pub use self::svg::svg;
pub use self::text::summary;
pub use crate::plot::PlotData;
