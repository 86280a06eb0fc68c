//! `hilsim run`: the main job, on its built-in scenario and on files.

use super::common::*;

#[test]
fn run_without_arguments_runs_the_built_in_straight_board() {
    let tmp = tempfile::tempdir().unwrap();
    let out = hilsim(tmp.path(), &["run"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.starts_with("scenario straight-board (seed 7): 37.00 s simulated"),
        "{text}"
    );
    for sensor in ["lidar", "sonar", "odometer"] {
        assert!(
            text.contains(&format!("  {sensor} ")),
            "{sensor} missing from: {text}"
        );
    }
    assert!(!text.contains("FAIL"), "{text}");
}

#[test]
fn run_out_writes_the_recording_and_the_results() {
    let tmp = tempfile::tempdir().unwrap();
    let out = hilsim(tmp.path(), &["run", "--out", "result", "--seed", "3"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let dir = tmp.path().join("result");
    for f in [
        "meta.toml",
        "commands.csv",
        "lidar.csv",
        "sonar.csv",
        "odometry.csv",
        "truth.csv",
    ] {
        assert!(dir.join(f).is_file(), "{f}");
    }
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    assert_eq!(results["seed"], 3);
    assert_eq!(results["passed"], true);
    assert!(results["metrics"]["lidar.readings"].as_f64().unwrap() > 60_000.0);
}

#[test]
fn a_failed_assertion_exits_1_and_says_which() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(repo_file("scenarios/room-tour.toml")).unwrap();
    let text = text.replace("at_least = 11.99", "at_least = 20.0");
    std::fs::write(tmp.path().join("s.toml"), text).unwrap();
    let out = hilsim(tmp.path(), &["run", "s.toml"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("FAIL sim.distance_m = 12.0"),
        "{}",
        stdout(&out)
    );
}

#[test]
fn via_serial_gives_the_in_process_results() {
    let tmp = tempfile::tempdir().unwrap();
    for scenario in ["", "landmarks-5.toml"] {
        let path = repo_file(&format!("scenarios/{scenario}"));
        let mut args = vec!["run"];
        if !scenario.is_empty() {
            args.push(path.to_str().unwrap());
        }
        let memory = hilsim(tmp.path(), &args);
        args.extend(["--via", "serial"]);
        let serial = hilsim(tmp.path(), &args);
        assert_eq!(serial.status.code(), Some(0), "{}", stderr(&serial));
        // The whole summary, calibrations included, is the same.
        assert_eq!(stdout(&serial), stdout(&memory));
        assert!(stdout(&serial).contains("lidar.mse_ratio"));
    }
}
