//! Inputs that never end, or are garbage of any size: each is refused with exit
//! code 2 and one line naming the file (and the line, where there is one) after reading at most a
//! bounded amount — never the whole of it.

use std::fs;
use std::io::Write;
use std::os::unix::fs::symlink;
use std::path::Path;
use std::process::Output;
use std::time::{Duration, Instant};

use super::common::*;

/// Records `scenarios/straight-board.toml` into `dir/rec`.
fn record(dir: &Path) {
    let scenario = repo_file("scenarios/straight-board.toml");
    let out = hilsim(dir, &["record", scenario.to_str().unwrap(), "--out", "rec"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

/// Runs `hilsim ARGS`, asserting that it ends within a few seconds.
fn quickly(dir: &Path, args: &[&str]) -> Output {
    let start = Instant::now();
    let out = hilsim(dir, args);
    assert!(
        start.elapsed() < Duration::from_secs(20),
        "hilsim {args:?} took {:?}",
        start.elapsed()
    );
    out
}

#[test]
fn a_lidar_csv_linked_to_dev_zero_is_refused_at_once() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path());
    let cal = hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "groundtruth", "--json"],
    );
    assert_eq!(cal.status.code(), Some(0), "{}", stderr(&cal));
    fs::write(tmp.path().join("cal.json"), &cal.stdout).unwrap();
    fs::remove_file(tmp.path().join("rec/lidar.csv")).unwrap();
    symlink("/dev/zero", tmp.path().join("rec/lidar.csv")).unwrap();
    for args in [
        &["calibrate", "rec", "--method", "em"][..],
        &["calibrate", "rec", "--method", "groundtruth", "--json"],
        &["smooth", "rec", "--calibration", "cal.json"],
    ] {
        let err = assert_bad_input(&quickly(tmp.path(), args));
        assert!(
            err.contains("rec/lidar.csv: not a regular file but a character device"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn a_line_of_10_mb_without_a_newline_names_file_and_line() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path());
    let path = tmp.path().join("rec/lidar.csv");
    let text = fs::read_to_string(&path).unwrap();
    // The header and two rows, then 10 MB of digits that never end their line.
    let kept: String = text.lines().take(3).map(|l| format!("{l}\n")).collect();
    let mut file = fs::File::create(&path).unwrap();
    file.write_all(kept.as_bytes()).unwrap();
    file.write_all(&vec![b'7'; 10_000_000]).unwrap();
    drop(file);
    let err = assert_bad_input(&quickly(
        tmp.path(),
        &["calibrate", "rec", "--method", "em"],
    ));
    assert!(
        err.contains("rec/lidar.csv:4: line longer than 64 KiB; not a recording's table"),
        "{err}"
    );
}

#[test]
fn a_pipe_or_a_device_in_a_recording_is_refused_before_it_is_opened() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path());
    // Opening a pipe would wait for a writer that never comes: it must not be opened at all.
    fs::remove_file(tmp.path().join("rec/sonar.csv")).unwrap();
    let made = std::process::Command::new("mkfifo")
        .arg(tmp.path().join("rec/sonar.csv"))
        .status()
        .unwrap();
    assert!(made.success());
    let err = assert_bad_input(&quickly(
        tmp.path(),
        &["calibrate", "rec", "--method", "em"],
    ));
    assert!(
        err.contains("rec/sonar.csv: not a regular file but a pipe"),
        "{err}"
    );
    fs::remove_file(tmp.path().join("rec/meta.toml")).unwrap();
    symlink("/dev/zero", tmp.path().join("rec/meta.toml")).unwrap();
    let err = assert_bad_input(&quickly(
        tmp.path(),
        &["calibrate", "rec", "--method", "em"],
    ));
    assert!(
        err.contains("rec/meta.toml: not a regular file but a character device"),
        "{err}"
    );
}

#[test]
fn a_meta_toml_over_1_mib_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path());
    let path = tmp.path().join("rec/meta.toml");
    let mut text = fs::read_to_string(&path).unwrap();
    text.push_str(&format!("# {}\n", "x".repeat(1 << 20)));
    fs::write(&path, text).unwrap();
    let err = assert_bad_input(&quickly(
        tmp.path(),
        &["calibrate", "rec", "--method", "em"],
    ));
    assert!(
        err.contains("rec/meta.toml: larger than 1 MiB; not a meta.toml"),
        "{err}"
    );
}

#[test]
fn a_scenario_linked_to_dev_zero_is_refused_after_1_mib() {
    let tmp = tempfile::tempdir().unwrap();
    symlink("/dev/zero", tmp.path().join("zero.toml")).unwrap();
    for args in [
        &["record", "zero.toml", "--out", "rec"][..],
        &["run", "zero.toml"],
        &["diagnose", "--sim", "zero.toml", "--real", "rec"],
    ] {
        let err = assert_bad_input(&quickly(tmp.path(), args));
        assert!(
            err.contains("zero.toml: larger than 1 MiB; not a scenario file"),
            "{args:?}: {err}"
        );
    }
    assert!(!tmp.path().join("rec").exists());
    // `scenario test` takes a path that is not a regular file for a directory of scenarios.
    let err = assert_bad_input(&quickly(tmp.path(), &["scenario", "test", "zero.toml"]));
    assert!(err.contains("zero.toml: "), "{err}");
}

#[test]
fn a_scenario_over_1_mib_or_from_an_endless_pipe_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let mut text = fs::read_to_string(repo_file("scenarios/straight-board.toml")).unwrap();
    text.push_str(&format!("# {}\n", "x".repeat(1 << 20)));
    fs::write(tmp.path().join("huge.toml"), text).unwrap();
    let err = assert_bad_input(&quickly(
        tmp.path(),
        &["record", "huge.toml", "--out", "rec"],
    ));
    assert!(
        err.contains("huge.toml: larger than 1 MiB; not a scenario file"),
        "{err}"
    );
    // A pipe is read (a scenario may come from a process), but only up to the limit.
    let fifo = tmp.path().join("pipe.toml");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let writer = std::thread::spawn(move || {
        let mut pipe = fs::OpenOptions::new().write(true).open(fifo).unwrap();
        let comments = "# an endless scenario\n".repeat(1000);
        // Ends when the reader closes the pipe (the write fails).
        while pipe.write_all(comments.as_bytes()).is_ok() {}
    });
    let err = assert_bad_input(&quickly(
        tmp.path(),
        &["record", "pipe.toml", "--out", "rec"],
    ));
    assert!(
        err.contains("pipe.toml: larger than 1 MiB; not a scenario file"),
        "{err}"
    );
    writer.join().unwrap();
}
