//! Running the binary as a user would.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The workspace root (where `scenarios/` lives).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A checked-in file, by path relative to the workspace root.
pub fn repo_file(rel: &str) -> PathBuf {
    root().join(rel)
}

/// Runs `hilsim ARGS` in `cwd` with an empty environment (but PATH).
pub fn hilsim(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hilsim"))
        .args(args)
        .current_dir(cwd)
        .env_clear()
        .env("PATH", std::env::var_os("PATH").unwrap_or_default())
        .output()
        .expect("the hilsim binary runs")
}

pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Asserts a bad-input failure: exit code 2 and exactly one line on stderr, no panic.
pub fn assert_bad_input(out: &Output) -> String {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert_eq!(err.lines().count(), 1, "one line expected, got: {err}");
    assert!(!err.contains("panicked") && !err.contains("backtrace") && !err.contains("NaN"));
    err
}
