//! Counts, flags, pipes, links and recordings that once hung, panicked or answered wrongly
//!: each now ends in the documented exit code with one clear line, or none.

use std::fs;
use std::process::{Command, Stdio};

use super::common::*;

/// A scenario that runs in a moment: a room, a robot standing still, no sensors.
const TINY: &str = "name = \"tiny\"\nduration_s = 0.5\n[robot]\nstart = { x = 0.0, y = 0.0 }\n\
                    wheel_base_m = 0.23\n";

#[test]
fn self_test_counts_are_checked_before_anything_is_allocated() {
    let tmp = tempfile::tempdir().unwrap();
    for n in ["18446744073709551615", "1000000000000", "100001"] {
        let err = assert_bad_input(&hilsim(tmp.path(), &["diagnose", "--self-test", n]));
        assert!(
            err.contains("--self-test: expected at most 100000 trials"),
            "{err}"
        );
    }
}

#[test]
fn a_negative_start_distance_is_a_value_not_a_flag() {
    let tmp = tempfile::tempdir().unwrap();
    for command in ["calibrate", "smooth"] {
        let mut args = vec![command, "rec"];
        if command == "calibrate" {
            args.extend(["--method", "em"]);
        } else {
            args.extend(["--calibration", "cal.json"]);
        }
        args.extend(["--start-distance", "-1"]);
        let err = assert_bad_input(&hilsim(tmp.path(), &args));
        assert!(
            err.contains("--start-distance: expected a distance from 0.01 to 1000 m, found -1.0"),
            "{command}: {err}"
        );
    }
}

#[test]
fn a_reader_that_goes_away_ends_the_run_quietly() {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(tmp.path().join("tiny.toml"), TINY).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_hilsim"))
        .args(["run", "tiny.toml"])
        .current_dir(tmp.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close the read end before the run has anything to print.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(out.stderr.is_empty(), "{}", stderr(&out));
}

#[test]
fn scenario_test_enters_each_directory_once() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    fs::create_dir(&dir).unwrap();
    fs::write(dir.join("tiny.toml"), TINY).unwrap();
    // Two links back to the directory itself: an exponential walk without a visited set.
    std::os::unix::fs::symlink(".", dir.join("again")).unwrap();
    std::os::unix::fs::symlink("..", dir.join("up")).unwrap();
    let out = hilsim(tmp.path(), &["scenario", "test", "s"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(
        stdout(&out).ends_with("1 passed, 0 failed\n"),
        "{}",
        stdout(&out)
    );
}

#[test]
fn diagnose_with_no_sensor_in_common_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = fs::read_to_string(repo_file("scenarios/straight-board.toml")).unwrap();
    fs::write(tmp.path().join("with.toml"), &scenario).unwrap();
    let o = hilsim(tmp.path(), &["record", "with.toml", "--out", "rec"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // The same world and drive with no sensor declared.
    let start = scenario.find("[sensors.lidar]").unwrap();
    let end = scenario.find("[calibration]").unwrap();
    let without = format!("{}{}", &scenario[..start], &scenario[end..])
        .replace("methods = [\"em\", \"groundtruth\"]", "methods = []");
    let without = &without[..without.find("[[expect]]").unwrap()];
    fs::write(tmp.path().join("without.toml"), without).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["diagnose", "--sim", "without.toml", "--real", "rec"],
    ));
    assert!(err.contains("no sensor in common"), "{err}");
}

#[test]
fn an_endless_calibration_or_scenario_path_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["smooth", "rec", "--calibration", "/dev/zero"],
    ));
    assert!(
        err.contains("/dev/zero: larger than 1 MiB; not a calibration"),
        "{err}"
    );
    std::os::unix::fs::symlink("/dev/zero", tmp.path().join("zero.toml")).unwrap();
    let err = assert_bad_input(&hilsim(tmp.path(), &["scenario", "test", "zero.toml"]));
    assert!(
        err.contains("zero.toml: ") && !err.contains("cannot list"),
        "{err}"
    );
}

#[test]
fn dataset_counts_and_scenarios_are_bounded_before_work() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = repo_file("scenarios/straight-board.toml");
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &[
            "dataset",
            scenario.to_str().unwrap(),
            "--runs",
            "1000000000000",
            "--out",
            "d",
        ],
    ));
    assert!(
        err.contains("--runs: expected at most 1000000 runs"),
        "{err}"
    );
    std::os::unix::fs::symlink("/dev/zero", tmp.path().join("zero.toml")).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["dataset", "zero.toml", "--runs", "1", "--out", "d"],
    ));
    assert!(err.contains("zero.toml: larger than 1 MiB"), "{err}");
    assert!(!tmp.path().join("d").exists());
}

#[test]
fn a_looping_link_in_a_recording_is_named_not_taken_for_a_missing_table() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = repo_file("scenarios/straight-board.toml");
    let o = hilsim(
        tmp.path(),
        &["record", scenario.to_str().unwrap(), "--out", "rec"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let sonar = tmp.path().join("rec/sonar.csv");
    fs::remove_file(&sonar).unwrap();
    std::os::unix::fs::symlink("sonar.csv", &sonar).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "groundtruth"],
    ));
    assert!(err.contains("sonar.csv"), "{err}");
}
