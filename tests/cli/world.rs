//! `hilsim world`: a recorded run's twin (a map built from its scans or the user's, its path,
//! its scans) that `hilsim record` replays and `hilsim diagnose` holds the run against.

use std::path::Path;

use hilsim_recording::Recording;

use crate::common::{assert_bad_input, hilsim, stderr, stdout};

/// A room with a pillar, a short drive; an unbiased lidar with 5 mm of noise, exact encoders.
const ROOM: &str = r#"
name = "twin-room"
seed = 3
[world]
walls = [
  { from = [-1.0, -1.5], to = [4.0, -1.5] },
  { from = [4.0, -1.5], to = [4.0, 2.5] },
  { from = [4.0, 2.5], to = [-1.0, 2.5] },
  { from = [-1.0, 2.5], to = [-1.0, -1.5] },
]
cylinders = [{ center = [2.5, 1.2], radius = 0.15 }]
[robot]
start = { x = 0.0, y = 0.0 }
wheel_base_m = 0.23
[[drive]]
speed_mps = 0.3
distance_m = 0.9
[[drive]]
turn_deg = 60.0
[[drive]]
speed_mps = 0.3
distance_m = 0.6
[[drive]]
turn_deg = -90.0
[[drive]]
speed_mps = 0.3
distance_m = 0.6
[sensors.lidar]
noise = [0.005]
[sensors.odometer]
"#;

/// Records the room's run into `dir/rec`.
fn record(dir: &Path) {
    std::fs::write(dir.join("room.toml"), ROOM).unwrap();
    let out = hilsim(dir, &["record", "room.toml", "--out", "rec"]);
    assert!(out.status.success(), "{}", stderr(&out));
}

/// The share of readings paired that `world` printed.
fn paired_share(printed: &str) -> f64 {
    let line = printed.lines().find(|l| l.starts_with("twin: ")).unwrap();
    let open = line.find('(').unwrap();
    let close = line.find(" %)").unwrap();
    line[open + 1..close].parse().unwrap()
}

#[test]
fn a_run_gets_a_world_and_its_twin_replays_it_reading_for_reading() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path());
    let out = hilsim(tmp.path(), &["world", "rec", "--out", "twin/room.toml"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let printed = stdout(&out);
    assert!(
        printed.contains("the path is the recording's truth.csv"),
        "{printed}"
    );
    // Every reading of a wall the scans saw twice is in the map: a few at the pillar's edge
    // and at grazing incidence are not.
    assert!(paired_share(&printed) > 95.0, "{printed}");
    for file in [
        "room.toml",
        "room.map.yaml",
        "room.map.pgm",
        "room.path.csv",
        "room.scans.csv",
    ] {
        assert!(tmp.path().join("twin").join(file).is_file(), "{file}");
    }
    // Written again over its own files.
    let again = hilsim(tmp.path(), &["world", "rec", "--out", "twin/room.toml"]);
    assert!(again.status.success(), "{}", stderr(&again));
    let twin = hilsim(
        tmp.path(),
        &["record", "twin/room.toml", "--out", "twin-rec"],
    );
    assert!(twin.status.success(), "{}", stderr(&twin));
    let real = Recording::read_dir(&tmp.path().join("rec")).unwrap();
    let replayed = Recording::read_dir(&tmp.path().join("twin-rec")).unwrap();
    let (real, replayed) = (real.lidar.unwrap(), replayed.lidar.unwrap());
    assert_eq!(real.len(), replayed.len());
    for (a, b) in real.iter().zip(&replayed) {
        assert_eq!((a.rev, a.angle_deg), (b.rev, b.angle_deg));
        // Both stamped to the microsecond; the schedule's beam period is the scan's span over
        // its beams, so a beam's time may round to the next microsecond.
        assert!((a.t_s - b.t_s).abs() < 1.5e-6, "{a:?} {b:?}");
    }
}

#[test]
fn the_run_held_against_its_own_twin_names_no_sensor_physics() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path());
    let out = hilsim(tmp.path(), &["world", "rec", "--out", "twin.toml"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let diagnosis = hilsim(
        tmp.path(),
        &["diagnose", "--sim", "twin.toml", "--real", "rec"],
    );
    assert!(diagnosis.status.success(), "{}", stderr(&diagnosis));
    let said = stdout(&diagnosis);
    let verdict = said.lines().next().unwrap_or_default();
    // The map's 3 cm cells are all that differs from the world the run was made in.
    assert!(
        verdict == "verdict: none" || verdict == "verdict: world_mismatch",
        "{said}"
    );
    // Without a scenario the log is held against the same world, built in one step, and
    // nothing is written beside it.
    let before = std::fs::read_dir(tmp.path()).unwrap().count();
    let one_step = hilsim(tmp.path(), &["diagnose", "--real", "rec"]);
    assert!(one_step.status.success(), "{}", stderr(&one_step));
    assert_eq!(
        stdout(&one_step).lines().next().unwrap_or_default(),
        verdict,
        "{}",
        stdout(&one_step)
    );
    assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), before);
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["diagnose", "--real", "rec", "--calibration", "robot.json"],
    ));
    assert!(err.contains("--calibration needs --sim"), "{err}");
}

#[test]
fn what_is_in_the_way_or_missing_is_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path());
    // A file of the user's where the path would go is never replaced.
    std::fs::write(tmp.path().join("twin.path.csv"), "my notes\n").unwrap();
    let err = assert_bad_input(&hilsim(tmp.path(), &["world", "rec", "--out", "twin.toml"]));
    assert!(err.contains("twin.path.csv"), "{err}");
    assert_eq!(
        std::fs::read_to_string(tmp.path().join("twin.path.csv")).unwrap(),
        "my notes\n"
    );
    // Nor the user's scenario.
    let err = assert_bad_input(&hilsim(tmp.path(), &["world", "rec", "--out", "room.toml"]));
    assert!(err.contains("room.toml"), "{err}");
    assert_eq!(
        std::fs::read_to_string(tmp.path().join("room.toml")).unwrap(),
        ROOM
    );
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["world", "nothing", "--out", "w.toml"],
    ));
    assert!(err.contains("nothing"), "{err}");
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["world", "rec", "--map", "missing.yaml", "--out", "w.toml"],
    ));
    assert!(err.contains("missing.yaml"), "{err}");
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["world", "rec", "--resolution-m", "0", "--out", "w.toml"],
    ));
    assert!(err.contains("--resolution-m"), "{err}");
}

/// The room's drive, longer, on wheels 6 % long and 4 % short: the commands replayed through
/// the nominal drive turn away from the real path faster than a revolution's match follows.
const LONGER_ON_WRONG_WHEELS: &str = "
[[drive]]
turn_deg = 120.0
[[drive]]
speed_mps = 0.3
distance_m = 1.2
[[drive]]
turn_deg = -150.0
[[drive]]
speed_mps = 0.3
distance_m = 1.0
[effects.odometer_wheel_radius]
left_scale = 1.06
right_scale = 0.96
";

/// A log without truth diagnosed against its own twin: the twin's path (the encoders already
/// matched to the scans) carries the trajectory's estimate where the commands' replay loses the
/// robot. Along the commands the diagnosis named a lidar mount at its search's bound. The
/// lidar is as declared: along the commands no physics is named (at most a mismatch within
/// the map's cells); where the log has no commands, the path is the scans' own matches and the
/// encoders judged against it show the wheels.
#[test]
fn a_twins_path_carries_the_estimate_where_the_commands_lose_the_robot() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(
        tmp.path().join("room.toml"),
        format!("{ROOM}{LONGER_ON_WRONG_WHEELS}"),
    )
    .unwrap();
    let out = hilsim(tmp.path(), &["record", "room.toml", "--out", "rec"]);
    assert!(out.status.success(), "{}", stderr(&out));
    std::fs::remove_file(tmp.path().join("rec/truth.csv")).unwrap();
    let out = hilsim(tmp.path(), &["world", "rec", "--out", "twin/room.toml"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let diagnose = |rec: &str| {
        let out = hilsim(
            tmp.path(),
            &[
                "diagnose",
                "--sim",
                "twin/room.toml",
                "--real",
                rec,
                "--json",
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let json: serde_json::Value = serde_json::from_str(stdout(&out).trim()).unwrap();
        json
    };
    // A log without truth and without commands (the header alone) from `from`, at `to`.
    let without_commands = |from: &str, to: &str| {
        std::fs::create_dir(tmp.path().join(to)).unwrap();
        for file in ["meta.toml", "lidar.csv", "odometry.csv"] {
            std::fs::copy(
                tmp.path().join(from).join(file),
                tmp.path().join(to).join(file),
            )
            .unwrap();
        }
        std::fs::write(
            tmp.path().join(to).join("commands.csv"),
            "t_s,left_mps,right_mps\n",
        )
        .unwrap();
    };
    let along_commands = diagnose("rec");
    // The commands are then judged against the twin's path, which follows the encoders.
    assert_eq!(
        along_commands["references"]["drive"],
        "commands against the lidar-estimated path (the scenario's path between scans)"
    );
    without_commands("rec", "no-commands");
    let without_commands_json = diagnose("no-commands");
    // Another run in the same room, held against this run's twin: its path is not this run's.
    record(tmp.path());
    without_commands("rec", "other-run");
    let other_run = diagnose("other-run");
    // Without commands the path is the scans' own matches, so that the encoders are judged
    // against the lidar rather than against themselves.
    let scans_only = "lidar-estimated path (each scan's own match, straight between scans)";
    for json in [&other_run, &without_commands_json] {
        assert_eq!(json["references"]["lidar"], scans_only, "{json}");
        assert_eq!(json["references"]["odometer"], scans_only, "{json}");
    }
    assert_eq!(
        along_commands["references"]["lidar"],
        "lidar-estimated path (the scenario's path between scans)"
    );
    let effect = along_commands["effect"].as_str().unwrap();
    assert!(
        ["none", "world_mismatch"].contains(&effect),
        "{effect}: {}",
        along_commands["explanation"]
    );
    // Judged against the scans, the encoders show the wheels' real radii (106 % and 96 %),
    // within a percent: the path's length is the lidar's, which is as declared.
    let wheels = without_commands_json["effects"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["effect"] == "odometer_wheel_radius")
        .unwrap_or_else(|| panic!("{without_commands_json}"));
    let (left, right) = (
        wheels["params"]["left_scale"].as_f64().unwrap(),
        wheels["params"]["right_scale"].as_f64().unwrap(),
    );
    assert!(
        (left - 1.06).abs() < 0.01 && (right - 0.96).abs() < 0.01,
        "{left} {right}"
    );
}
