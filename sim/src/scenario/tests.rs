use std::path::Path;

use super::*;

const MINIMAL: &str = r#"name = "t"
duration_s = 1.0
[robot]
start = { x = 0.0, y = 0.0 }
wheel_base_m = 0.23
"#;

fn err(text: &str) -> String {
    Scenario::from_toml(text, Path::new("s.toml"))
        .unwrap_err()
        .to_string()
}

#[test]
fn minimal_scenario_loads_with_defaults() {
    let s = Scenario::from_toml(MINIMAL, Path::new("s.toml")).unwrap();
    assert_eq!(s.seed, 0);
    assert_eq!(s.run_steps(), 100);
    assert!(s.sensors.lidar.is_none());
}

#[test]
fn unknown_key_names_its_line() {
    let text = format!("{MINIMAL}[sensors.lidar]\nbias = [0.0, 1.0]\nnoize = [0.0]\n");
    let msg = err(&text);
    assert!(msg.starts_with("s.toml:8: "), "{msg}");
    assert!(msg.contains("noize"), "{msg}");
}

#[test]
fn wrong_type_names_its_line() {
    let msg = err(&MINIMAL.replace("wheel_base_m = 0.23", "wheel_base_m = \"wide\""));
    assert!(msg.starts_with("s.toml:5: "), "{msg}");
}

#[test]
fn semantic_errors_name_the_line_of_the_key() {
    let text = format!(
        "{MINIMAL}[world]\ncylinders = [\n  {{ center = [1.0, 1.0], radius = 0.1 }},\n  {{ center = [3.0, 1.0], radius = -0.1 }},\n]\n"
    );
    let msg = err(&text);
    assert!(
        msg.starts_with("s.toml:9: world.cylinders[1].radius: expected a positive"),
        "{msg}"
    );
}

#[test]
fn drive_step_with_two_kinds_is_rejected_at_its_table() {
    let text =
        format!("{MINIMAL}[[drive]]\nstop_s = 1.0\n[[drive]]\nstop_s = 1.0\nturn_deg = 90.0\n");
    let msg = err(&text);
    assert!(
        msg.starts_with("s.toml:8: drive[1]: found stop_s and turn_deg"),
        "{msg}"
    );
}

#[test]
fn robot_inside_a_wall_is_rejected() {
    let text = format!("{MINIMAL}[world]\nwalls = [{{ from = [0.1, -1.0], to = [0.1, 1.0] }}]\n");
    let msg = err(&text);
    assert!(
        msg.contains("robot.start: the robot (radius 0.165 m) starts inside wall 0"),
        "{msg}"
    );
    assert!(msg.starts_with("s.toml:4: "), "{msg}");
}

#[test]
fn empty_program_needs_a_duration() {
    let msg = err(&MINIMAL.replace("duration_s = 1.0\n", ""));
    assert!(msg.contains("the drive program is empty"), "{msg}");
}

#[test]
fn unknown_metric_is_rejected() {
    let text = format!("{MINIMAL}[[expect]]\nmetric = \"lidar.magic\"\nat_least = 1.0\n");
    let msg = err(&text);
    assert!(
        msg.starts_with("s.toml:7: expect[0].metric: unknown metric `lidar.magic`"),
        "{msg}"
    );
}
