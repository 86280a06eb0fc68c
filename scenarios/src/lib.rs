//! The checked-in scenarios (the `*.toml` files beside this crate, two of them built in) and the
//! pipeline that runs one end to end, as `hilsim run` and `hilsim scenario test` do: emulate the
//! sensors in the scenario's world, calibrate with the methods it names, compute the metrics
//! (`hilsim_sim::scenario::metrics` is their catalogue) and check its `[[expect]]` assertions.
#![warn(missing_docs)]

pub mod builtin;
pub mod calibrated;
mod discover;
mod firmware_plan;
mod firmware_run;
pub mod metrics;
mod pipeline;
mod recorded_run;
mod ros2_export;
mod summary;
mod test_results;

pub use discover::{load_scenarios, scenario_files, DiscoverError, LoadError};
pub use firmware_plan::{FirmwarePlan, FirmwarePlanError, FirmwareRequest};
pub use firmware_run::FirmwareRun;
pub use metrics::{Metrics, Outcome};
pub use pipeline::{execute, execute_all, execute_into, Report, RunError, Via};
pub use recorded_run::{RecordedRun, StreamTarget};
pub use ros2_export::{drawn_world, ExportError, ExportRequest, McapExport};
pub use test_results::{TestResults, JUNIT_XML};
