//! The bad-input corpus (`tests/data/bad-scenarios/`): every malformed scenario fails before any
//! work with exit code 2 and one line naming the file, the line and what was expected.

use std::path::Path;

use super::common::*;

/// (file, line, a fragment of what was expected).
const CORPUS: &[(&str, usize, &str)] = &[
    ("missing-robot.toml", 1, "missing field `robot`"),
    (
        "wrong-type.toml",
        6,
        "invalid type: string \"wide\", expected f64",
    ),
    ("unknown-key.toml", 6, "unknown field `wheel_bse_m`"),
    (
        "negative-radius.toml",
        9,
        "world.cylinders[0].radius: expected a positive number",
    ),
    (
        "nan-coefficient.toml",
        9,
        "sensors.lidar.bias: expected finite coefficients",
    ),
    (
        "empty-drive-without-duration.toml",
        1,
        "the drive program is empty and `duration_s` is not set",
    ),
    ("robot-inside-wall.toml", 5, "starts inside wall 0"),
    (
        "robot-inside-cylinder.toml",
        5,
        "starts inside or touching cylinder 0",
    ),
    (
        "overlapping-cylinders.toml",
        11,
        "cylinder 1 overlaps cylinder 0",
    ),
    ("empty.toml", 1, "missing field `name`"),
    (
        "binary-garbage.toml",
        1,
        "not a text file: expected UTF-8 TOML",
    ),
    (
        "drive-step-two-kinds.toml",
        8,
        "drive[0]: found stop_s and turn_deg",
    ),
    (
        "speed-without-distance.toml",
        9,
        "`speed_mps` needs `distance_m`",
    ),
    (
        "negative-noise.toml",
        9,
        "sensors.lidar.noise: expected finite coefficients ≥ 0",
    ),
    ("toml-syntax.toml", 8, "unclosed table"),
    ("unknown-metric.toml", 9, "unknown metric `lidar.magic`"),
    (
        "sonar-half-angle.toml",
        9,
        "expected 0 ≤ half_angle_deg < 90",
    ),
    (
        "name-not-a-string.toml",
        1,
        "invalid type: integer `42`, expected a string",
    ),
    // Values with no physical sense are refused with the documented limit.
    (
        "issue-18-duration-a-billion-seconds.toml",
        2,
        "duration_s: expected at most 86400 s (a day)",
    ),
    (
        "issue-18-drive-a-million-km.toml",
        7,
        "drive: the drive program lasts 10000000000 s; expected at most 86400 s",
    ),
    (
        "issue-18-sonar-rate-a-gigahertz.toml",
        9,
        "sensors.sonar.rate_hz: expected at most 1000 Hz",
    ),
    (
        "issue-18-yaw-1e300.toml",
        5,
        "robot.start.yaw_deg: expected an angle within ±360 degrees",
    ),
    (
        "issue-18-wall-beyond-rapier-precision.toml",
        9,
        "world.walls[0].from: expected coordinates within ±1000 m",
    ),
];

#[test]
fn every_malformed_scenario_names_file_line_and_expectation() {
    let tmp = tempfile::tempdir().unwrap();
    for (file, line, fragment) in CORPUS {
        let path = repo_file(&format!("tests/data/bad-scenarios/{file}"));
        let path = path.to_str().unwrap();
        for args in [
            vec!["run", path],
            vec!["record", path, "--out", "rec"],
            vec!["scenario", "test", path],
        ] {
            let out = hilsim(tmp.path(), &args);
            let err = assert_bad_input(&out);
            let located = format!("{path}:{line}: ");
            assert!(
                err.contains(&located),
                "{args:?}: expected `{located}` in: {err}"
            );
            assert!(
                err.contains(fragment),
                "{args:?}: expected `{fragment}` in: {err}"
            );
        }
        assert!(
            !tmp.path().join("rec").exists(),
            "{file}: no output for bad input"
        );
    }
}

#[test]
fn the_corpus_is_complete() {
    let dir = repo_file("tests/data/bad-scenarios");
    let files = std::fs::read_dir(dir).unwrap().count();
    assert_eq!(files, CORPUS.len(), "every corpus file has an expectation");
}

#[test]
fn a_missing_scenario_file_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let out = hilsim(tmp.path(), &["run", "no-such.toml"]);
    let err = assert_bad_input(&out);
    assert!(err.contains("no-such.toml: cannot read"), "{err}");
}

#[test]
fn usage_errors_are_one_line_naming_the_help_to_read() {
    let tmp = tempfile::tempdir().unwrap();
    for (args, says, help) in [
        (
            &["run", "--seed", "minus-one"][..],
            "--seed",
            "hilsim run --help",
        ),
        (
            &["record", "x.toml"][..],
            "missing --out",
            "hilsim record --help",
        ),
        (
            &["frobnicate"][..],
            "unknown command `frobnicate`",
            "hilsim --help",
        ),
        (&[][..], "missing a command", "hilsim --help"),
        (
            &["import"][..],
            "missing --out <OUT>, <BAG>",
            "hilsim import --help",
        ),
        (
            &["run", "x.toml", "--via", "carrier-pigeon"][..],
            "invalid value `carrier-pigeon` (expected one of: memory, serial)",
            "hilsim run --help",
        ),
        (
            &["diagnose", "--self-test", "--trial", "1"][..],
            "--self-test <N>: a value is required",
            "hilsim diagnose --help",
        ),
        (
            &["dataset", "merge"][..],
            "missing --out",
            "hilsim dataset merge --help",
        ),
    ] {
        let err = assert_bad_input(&hilsim(tmp.path(), args));
        assert!(err.starts_with("hilsim: "), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(
            err.trim_end().ends_with(&format!("; see {help}")),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn a_typed_value_in_a_usage_error_is_shown_terminal_safe() {
    let tmp = tempfile::tempdir().unwrap();
    let err = assert_bad_input(&hilsim(tmp.path(), &["run", "--via", "a\x1b[31mb\nc"]));
    assert!(err.contains("a\\e[31mb\\nc"), "{err}");
}

#[test]
fn help_and_version_go_to_stdout_and_succeed() {
    let tmp = tempfile::tempdir().unwrap();
    for args in [&["--help"][..], &["--version"], &["calibrate", "--help"]] {
        let out = hilsim(tmp.path(), args);
        assert_eq!(out.status.code(), Some(0), "{args:?}");
        assert!(stderr(&out).is_empty(), "{args:?}: {}", stderr(&out));
        assert!(stdout(&out).contains("hilsim"), "{args:?}");
    }
}

#[test]
fn negative_numbers_reach_their_own_check() {
    let tmp = tempfile::tempdir().unwrap();
    let err = assert_bad_input(&hilsim(tmp.path(), &["diagnose", "--self-test", "-5"]));
    assert!(
        err.contains("--self-test: expected at least one trial, found -5"),
        "{err}"
    );
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["diagnose", "--self-test", "1", "--strength", "-1"],
    ));
    assert!(
        err.contains("--strength: expected a factor in (0, 5], found -1"),
        "{err}"
    );
}

#[test]
fn a_self_test_report_without_a_trial_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["diagnose", "--self-test", "1", "--report", "rep"],
    ));
    assert!(
        err.contains("--report with --self-test needs --trial"),
        "{err}"
    );
    assert!(!tmp.path().join("rep").exists());
}

#[test]
fn a_full_device_is_named_in_the_systems_words() {
    if !Path::new("/dev/full").exists() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let scenario = repo_file("scenarios/straight-board.toml");
    let out = hilsim(
        tmp.path(),
        &["record", scenario.to_str().unwrap(), "--out", "rec"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["export", "rec", "--mcap", "/dev/full"],
    ));
    assert!(
        err.contains("/dev/full: No space left on device (os error 28)"),
        "{err}"
    );
}
