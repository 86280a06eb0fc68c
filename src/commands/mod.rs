//! One module per subcommand; each validates its arguments before opening anything.

pub mod calibrate;
pub mod dataset;
pub mod decode;
pub mod diagnose;
pub mod export;
pub mod hil;
pub mod import;
pub mod record;
pub mod report;
pub mod run;
pub mod scenario_test;
pub mod serve;

pub mod world;

/// 0 when `passed`, else 1: a check or assertion failed (the result is still printed).
pub fn exit_code(passed: bool) -> std::process::ExitCode {
    if passed {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::from(1)
    }
}
