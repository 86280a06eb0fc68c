//! `hilsim scenario test`: the checked-in scenarios pass, and a failing one is reported.

use super::common::*;

#[test]
fn the_checked_in_scenarios_pass() {
    let out = hilsim(&root(), &["scenario", "test", "scenarios"]);
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(0), "{text}{}", stderr(&out));
    assert!(
        text.lines().last().unwrap().ends_with(" passed, 0 failed"),
        "{text}"
    );
    for name in [
        "straight-board",
        "straight-board-0.2",
        "straight-board-0.3",
        "landmarks-5",
        "room-tour",
    ] {
        assert!(text.contains(&format!("PASS {name} (")), "{name}: {text}");
    }
}

#[test]
fn a_failing_scenario_fails_the_whole_test_with_exit_1() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(repo_file("scenarios/room-tour.toml")).unwrap();
    std::fs::write(tmp.path().join("good.toml"), &text).unwrap();
    let bad = text
        .replace("name = \"room-tour\"", "name = \"too-far\"")
        .replace("at_most = 12.01", "at_most = 5.0");
    std::fs::write(tmp.path().join("bad.toml"), bad).unwrap();
    let out = hilsim(tmp.path(), &["scenario", "test", "."]);
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("FAIL too-far"), "{text}");
    assert!(text.contains("PASS room-tour"), "{text}");
    assert!(text.ends_with("1 passed, 1 failed\n"), "{text}");
}

#[test]
fn an_empty_directory_is_bad_input() {
    let tmp = tempfile::tempdir().unwrap();
    let out = hilsim(tmp.path(), &["scenario", "test", "."]);
    let err = assert_bad_input(&out);
    assert!(err.contains("no scenario files"), "{err}");
}
