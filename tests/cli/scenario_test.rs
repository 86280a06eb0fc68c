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

    // The same as one JSON object, and as JUnit XML for CI systems.
    let out = hilsim(
        tmp.path(),
        &["scenario", "test", ".", "--json", "--junit", "junit.xml"],
    );
    assert_eq!(out.status.code(), Some(1));
    let j: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert_eq!(
        (j["passed"].as_u64(), j["failed"].as_u64()),
        (Some(1), Some(1))
    );
    let scenarios = j["scenarios"].as_array().unwrap();
    let bad = scenarios
        .iter()
        .find(|s| s["scenario"] == "too-far")
        .unwrap();
    assert_eq!(bad["passed"], false);
    assert!(bad["expectations"]
        .as_array()
        .unwrap()
        .iter()
        .any(|e| e["passed"] == false && e["value"].is_number()));
    let xml = std::fs::read_to_string(tmp.path().join("junit.xml")).unwrap();
    assert!(
        xml.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>"),
        "{xml}"
    );
    assert_eq!(xml.matches("<testsuite ").count(), 2, "{xml}");
    assert_eq!(xml.matches("<failure ").count(), 1, "{xml}");
    assert!(xml.contains("<testsuite name=\"too-far\""), "{xml}");
    assert!(
        xml.contains("failure message=\"FAIL sim.distance_m"),
        "{xml}"
    );
}

/// `run --json` prints results.json's object instead of the summary.
#[test]
fn run_json_prints_the_results_object() {
    let tmp = tempfile::tempdir().unwrap();
    let out = hilsim(
        tmp.path(),
        &[
            "run",
            repo_file("scenarios/straight-board-0.3.toml")
                .to_str()
                .unwrap(),
            "--json",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let j: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert_eq!(j["scenario"], "straight-board-0.3");
    assert_eq!(j["passed"], true);
    assert!(j["metrics"]["em.lidar_model.mse_ratio"].is_number(), "{j}");
    assert!(j["calibrations"][0]["checks"].is_array(), "{j}");
}

#[test]
fn an_empty_directory_is_bad_input() {
    let tmp = tempfile::tempdir().unwrap();
    let out = hilsim(tmp.path(), &["scenario", "test", "."]);
    let err = assert_bad_input(&out);
    assert!(err.contains("no scenario files"), "{err}");
}

#[test]
fn a_scenario_name_with_control_characters_is_printed_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(repo_file("scenarios/straight-board.toml")).unwrap();
    let hostile = text.replacen(
        "name = \"straight-board\"",
        r#"name = "bell\u0007\nnext\u001b[31mred""#,
        1,
    );
    assert_ne!(hostile, text, "the scenario's name line");
    std::fs::write(tmp.path().join("ctrl.toml"), hostile).unwrap();
    let shown = r"bell\u{7}\nnext\e[31mred";
    let run = hilsim(tmp.path(), &["run", "ctrl.toml"]);
    let test = hilsim(tmp.path(), &["scenario", "test", "ctrl.toml"]);
    for (out, first) in [
        (&run, format!("scenario {shown} (seed ")),
        (&test, format!("PASS {shown} (ctrl.toml, ")),
    ] {
        let text = stdout(out);
        assert_eq!(out.status.code(), Some(0), "{text}{}", stderr(out));
        assert!(text.starts_with(&first), "{text}");
        assert!(!text.contains(['\u{7}', '\u{1b}']), "{text}");
    }
}

#[test]
fn junit_replaces_a_previous_report_but_never_a_scenario_or_a_users_file() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    std::fs::copy(
        repo_file("scenarios/straight-board.toml"),
        cwd.join("s.toml"),
    )
    .unwrap();
    for _ in 0..2 {
        let o = hilsim(cwd, &["scenario", "test", "s.toml", "--junit", "j.xml"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    std::fs::write(cwd.join("notes.txt"), "mine").unwrap();
    for target in ["s.toml", "notes.txt"] {
        let args = ["scenario", "test", "s.toml", "--junit", target];
        let err = assert_bad_input(&hilsim(cwd, &args));
        assert!(err.contains("refusing"), "{err}");
    }
    assert_eq!(
        std::fs::read_to_string(cwd.join("notes.txt")).unwrap(),
        "mine"
    );
    assert!(std::fs::read_to_string(cwd.join("s.toml"))
        .unwrap()
        .contains("[robot]"));
}
