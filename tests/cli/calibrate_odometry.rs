//! `hilsim calibrate --method odometry`: on a recording of an ordinary drive whose wheels and
//! lidar mount are off, on a tuples file, and the inputs it refuses.

use super::common::*;

/// The odometry-drive scenario with its wheels and lidar mount off, recorded into `dir/rec`.
fn record_off(dir: &std::path::Path) {
    let text = std::fs::read_to_string(repo_file("scenarios/odometry-drive.toml")).unwrap();
    let scenario = format!(
        "{text}\n[effects.odometer_wheel_radius]\nleft_scale = 1.02\nright_scale = 0.985\n\
         [effects.drive_wheel_base]\nscale = 1.04\n\
         [effects.lidar_mount_offset]\nyaw_deg = 2.0\nx_m = 0.02\ny_m = -0.015\n"
    );
    std::fs::write(dir.join("off.toml"), scenario).unwrap();
    let o = hilsim(dir, &["record", "off.toml", "--out", "rec"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn a_drive_with_wheels_and_mount_off_is_calibrated_within_its_stated_uncertainty() {
    let tmp = tempfile::tempdir().unwrap();
    record_off(tmp.path());
    let o = hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "odometry", "--json"],
    );
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["method"], "odometry");
    let od = &v["odometry"];
    // The scenario's nominal radius 0.033 m and wheel base 0.23 m, its mount (0.05, 0, 0°).
    let truth = [
        ("left_wheel_radius_m", 0.033 * 1.02),
        ("right_wheel_radius_m", 0.033 * 0.985),
        ("wheel_base_m", 0.23 * 1.04),
        ("lidar_x_m", 0.07),
        ("lidar_y_m", -0.015),
        ("lidar_yaw_rad", 2f64.to_radians()),
    ];
    let cov = od["covariance"].as_array().unwrap();
    assert_eq!(cov.len(), 6);
    for (i, (key, want)) in truth.iter().enumerate() {
        let got = od[key].as_f64().unwrap();
        let sd = cov[i][i].as_f64().unwrap().sqrt();
        // A fixed seed: within 3 sd (a 0.3 % chance each of failing by luck, were it drawn).
        assert!(
            (got - want).abs() <= 3.0 * sd,
            "{key}: {got} against {want} ± {sd}"
        );
    }
    let scale = od["wheel_scale"].as_array().unwrap();
    assert!((scale[0].as_f64().unwrap() - 1.02).abs() < 0.01);
    let checks = v["checks"].as_array().unwrap();
    assert!(checks.iter().all(|c| c["pass"] == true), "{checks:#?}");
    assert!(checks
        .iter()
        .any(|c| c["name"] == "odometry.failed_match_share"));
    // The text says the same.
    let o = hilsim(tmp.path(), &["calibrate", "rec", "--method", "odometry"]);
    let text = stdout(&o);
    assert!(
        text.contains("wheel base") && text.contains("lidar mount"),
        "{text}"
    );
}

/// Tuples of a known robot (radii 20 and 21 mm, base 90 mm, lidar at the axle's centre),
/// turning both ways and driving straight, with the scan matcher's error a deterministic
/// wobble of a fraction of a millimetre.
fn tuples() -> String {
    let (rl, rr, b) = (0.020, 0.021, 0.090);
    (0..600)
        .map(|k| {
            let (l, r) = match k % 4 {
                0 | 2 => (0.5, 0.5),
                1 => (-1.5, 1.5),
                _ => (1.5, -1.5),
            };
            let t: f64 = 0.8;
            let (dl, dr) = (rl * l * t, rr * r * t);
            let turn = (dr - dl) / b;
            let forward = (dl + dr) / 2.0;
            let (x, y) = if turn.abs() < 1e-9 {
                (forward, 0.0)
            } else {
                (
                    forward * turn.sin() / turn,
                    forward * (1.0 - turn.cos()) / turn,
                )
            };
            let w = (k as f64 * 1.7).sin();
            format!(
                "{{ \"T\": {t}, \"phi_l\": {l}, \"phi_r\": {r}, \"sm\": [ {}, {}, {} ] }}\n",
                x + 3e-4 * w,
                y - 2e-4 * (k as f64 * 0.9).cos(),
                turn + 1e-3 * (k as f64 * 2.3).sin()
            )
        })
        .collect()
}

#[test]
fn tuples_are_calibrated_and_two_objects_on_a_line_are_read() {
    let tmp = tempfile::tempdir().unwrap();
    // Two objects on one line, as a few of the paper's lines hold.
    let text = tuples().replacen("}\n{", "} {", 3);
    std::fs::write(tmp.path().join("drive.tuple"), text).unwrap();
    let o = hilsim(
        tmp.path(),
        &[
            "calibrate",
            "--method",
            "odometry",
            "--tuples",
            "drive.tuple",
            "--json",
        ],
    );
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let od = &v["odometry"];
    for (key, want) in [
        ("left_wheel_radius_m", 0.020),
        ("right_wheel_radius_m", 0.021),
        ("wheel_base_m", 0.090),
    ] {
        let got = od[key].as_f64().unwrap();
        assert!(
            (got / want - 1.0).abs() < 0.002,
            "{key}: {got} against {want}"
        );
    }
    assert!(od["lidar_x_m"].as_f64().unwrap().abs() < 0.002);
    assert!(od.get("wheel_scale").is_none());
}

#[test]
fn what_the_odometry_method_cannot_use_is_refused_with_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(
        tmp.path().join("broken.tuple"),
        tuples() + "{\"T\": 1.0, \"phi_l\": }\n",
    )
    .unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &[
            "calibrate",
            "--method",
            "odometry",
            "--tuples",
            "broken.tuple",
        ],
    ));
    assert!(err.contains("broken.tuple:601"), "{err}");
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["calibrate", "--method", "em", "--tuples", "broken.tuple"],
    ));
    assert!(err.contains("--tuples"), "{err}");
    let err = assert_bad_input(&hilsim(tmp.path(), &["calibrate", "--method", "odometry"]));
    assert!(err.contains("RECORDING") || err.contains("tuples"), "{err}");
    // A recording without a nominal wheel radius: the flag it needs is named.
    record_off(tmp.path());
    let o = hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "odometry", "--json"],
    );
    std::fs::write(tmp.path().join("wheels.json"), o.stdout).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &[
            "calibrate",
            "rec",
            "--method",
            "odometry",
            "--lidar-model",
            "wheels.json",
        ],
    ));
    assert!(
        err.contains("wheels.json") && err.contains("no lidar model"),
        "{err}"
    );
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &[
            "calibrate",
            "rec",
            "--method",
            "odometry",
            "--lidar-latency-s",
            "5",
        ],
    ));
    assert!(err.contains("--lidar-latency-s"), "{err}");
    let meta = tmp.path().join("rec/meta.toml");
    let text = std::fs::read_to_string(&meta).unwrap();
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("wheel_radius_m"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&meta, without).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "odometry"],
    ));
    assert!(err.contains("--wheel-radius-m"), "{err}");
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &[
            "calibrate",
            "rec",
            "--method",
            "odometry",
            "--wheel-radius-m",
            "-1",
        ],
    ));
    assert!(err.contains("--wheel-radius-m"), "{err}");
}
