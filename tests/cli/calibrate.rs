//! `hilsim calibrate` and `hilsim smooth` on recordings: the JSON of interfaces.md, and bad
//! recordings refused with one line and exit code 2.

use super::common::*;

fn record(dir: &std::path::Path, scenario: &str, out: &str) {
    let path = repo_file(&format!("scenarios/{scenario}"));
    let o = hilsim(dir, &["record", path.to_str().unwrap(), "--out", out]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

fn json(out: &std::process::Output) -> serde_json::Value {
    assert_eq!(out.status.code(), Some(0), "{}", stderr(out));
    serde_json::from_str(&stdout(out)).unwrap()
}

#[test]
fn em_and_groundtruth_print_the_interface_json() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path(), "straight-board.toml", "rec");
    for method in ["em", "groundtruth"] {
        let v = json(&hilsim(
            tmp.path(),
            &["calibrate", "rec", "--method", method, "--json"],
        ));
        assert_eq!(v["method"], method);
        assert_eq!(v["sensors"]["lidar"]["alpha"].as_array().unwrap().len(), 3);
        assert_eq!(v["sensors"]["sonar"]["alpha"].as_array().unwrap().len(), 2);
        assert_eq!(
            v["sensors"]["odometer"]["beta"].as_array().unwrap().len(),
            1
        );
        assert!(v["iterations"].as_u64().unwrap() >= 1);
        assert_eq!(v["converged"], true);
        let m = &v["metrics"];
        // The raw lidar's quadratic bias is far from the truth; any calibration beats it.
        assert!(m["mse_calibrated"].as_f64().unwrap() < m["mse_raw"].as_f64().unwrap() / 3.0);
    }
}

#[test]
fn landmarks_add_order_and_landmarks_and_metrics_need_truth() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path(), "landmarks-5.toml", "rec");
    let v = json(&hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "landmarks", "--json"],
    ));
    assert_eq!(v["order"], 2);
    assert_eq!(v["landmarks"].as_array().unwrap().len(), 5);
    assert!(v["metrics"].is_object());
    // Without truth (and true ranges) there is nothing to score against: no metrics.
    std::fs::remove_file(tmp.path().join("rec/truth.csv")).unwrap();
    let lidar = std::fs::read_to_string(tmp.path().join("rec/lidar.csv")).unwrap();
    let stripped: String = lidar
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string() + "\n")
        .collect();
    std::fs::write(tmp.path().join("rec/lidar.csv"), stripped).unwrap();
    let v = json(&hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "landmarks", "--json"],
    ));
    assert!(v.get("metrics").is_none(), "{v}");
    assert_eq!(v["landmarks"].as_array().unwrap().len(), 5);
}

#[test]
fn smooth_applies_a_trained_calibration_to_another_run() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path(), "straight-board.toml", "train");
    record(tmp.path(), "straight-board-0.3.toml", "test");
    let cal = hilsim(
        tmp.path(),
        &["calibrate", "train", "--method", "em", "--json"],
    );
    std::fs::write(tmp.path().join("cal.json"), &cal.stdout).unwrap();
    let o = hilsim(
        tmp.path(),
        &[
            "smooth",
            "test",
            "--calibration",
            "cal.json",
            "--csv",
            "d.csv",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let csv = std::fs::read_to_string(tmp.path().join("d.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("t_s,distance_m,sd_m"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    // 13.7 s at 5 revolutions per second; the run ends ~4 m from the board.
    assert!(rows.len() >= 60, "{}", rows.len());
    let last = rows.last().unwrap();
    assert!((3.5..4.5).contains(&last[1]), "{last:?}");
    assert!(last[2] > 0.0 && last[2] < 0.1, "{last:?}");
}

#[test]
fn bad_recordings_exit_2_with_one_line_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path(), "straight-board.toml", "rec");
    let run = |args: &[&str]| assert_bad_input(&hilsim(tmp.path(), args));
    // A missing recording.
    let err = run(&["calibrate", "nowhere", "--method", "em"]);
    assert!(err.contains("nowhere"), "{err}");
    // Time going backwards in the lidar table.
    let lidar = tmp.path().join("rec/lidar.csv");
    let text = std::fs::read_to_string(&lidar).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines.swap(5, 6);
    std::fs::write(&lidar, lines.join("\n") + "\n").unwrap();
    let err = run(&["calibrate", "rec", "--method", "em"]);
    assert!(err.contains("lidar.csv:7: time goes backwards"), "{err}");
    // NaN.
    std::fs::write(&lidar, text.replacen(",0.509,", ",nan,", 1)).unwrap();
    let err = run(&["calibrate", "rec", "--method", "groundtruth"]);
    assert!(err.contains("lidar.csv:2:"), "{err}");
    std::fs::write(&lidar, &text).unwrap();
    // A beam that does not see the target (backwards: the far wall, mostly beyond range) must
    // be refused, not fitted into a confident wrong model.
    let err = run(&[
        "calibrate",
        "rec",
        "--method",
        "em",
        "--beam",
        "180",
        "--start-distance",
        "8.5",
    ]);
    assert!(err.contains("returned a valid reading in only"), "{err}");
    // meta.toml's start distance is the frontal target's: another beam needs its own.
    let err = run(&["calibrate", "rec", "--method", "em", "--beam", "-5"]);
    assert!(err.starts_with("hilsim: rec: em: "), "{err}");
    // A calibration file that is not one.
    std::fs::write(tmp.path().join("cal.json"), "{\"method\": \"magic\"}").unwrap();
    let err = run(&["smooth", "rec", "--calibration", "cal.json"]);
    assert!(err.contains("cal.json"), "{err}");
}

/// Stops of 1 s (five revolutions) in a recording without odometry: rest is found
/// from the scans and every stop is used; the JSON notes say so. Asking for more revolutions
/// than a stop holds leaves too few stops: exit 2, saying how many were needed.
#[test]
fn one_second_stops_without_odometry_calibrate() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = std::fs::read_to_string(repo_file("scenarios/landmarks-5.toml"))
        .unwrap()
        .replace("stop_s = 2.0", "stop_s = 1.0");
    std::fs::write(tmp.path().join("short-stops.toml"), scenario).unwrap();
    let o = hilsim(tmp.path(), &["record", "short-stops.toml", "--out", "rec"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    std::fs::remove_file(tmp.path().join("rec/odometry.csv")).unwrap();
    let v = json(&hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "landmarks", "--json"],
    ));
    let notes: Vec<&str> = v["notes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    let used = notes
        .iter()
        .find(|n| n.contains("stop(s) used"))
        .unwrap_or_else(|| panic!("{notes:?}"));
    assert!(used.starts_with("11 stop(s) used"), "{used}");
    assert!(used.contains("the scans"), "{used}");
    assert_eq!(v["landmarks"].as_array().unwrap().len(), 5);
    // The calibrated model is far better than the raw readings (the declared bias is 5-20 cm).
    let m = &v["metrics"];
    let ratio = m["mse_raw"].as_f64().unwrap() / m["mse_calibrated"].as_f64().unwrap();
    assert!(ratio > 10.0, "{m}");

    let o = hilsim(
        tmp.path(),
        &[
            "calibrate",
            "rec",
            "--method",
            "landmarks",
            "--min-revolutions",
            "6",
        ],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stdout(&o));
    assert!(
        stderr(&o).contains("holding at least 6 lidar revolutions"),
        "{}",
        stderr(&o)
    );
    for bad in [["--settle-s", "-1"], ["--min-revolutions", "0.5"]] {
        let mut args = vec!["calibrate", "rec", "--method", "landmarks"];
        args.extend(bad);
        let o = hilsim(tmp.path(), &args);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        assert!(stderr(&o).contains(bad[0]), "{}", stderr(&o));
    }
    // A settling time given is used as it is.
    let v = json(&hilsim(
        tmp.path(),
        &[
            "calibrate",
            "rec",
            "--method",
            "landmarks",
            "--settle-s",
            "0.4",
            "--json",
        ],
    ));
    let notes = v["notes"].to_string();
    assert!(notes.contains("the settling time given"), "{notes}");
}

/// EM's assumptions checked. On landmarks-5 (its lidar beam sweeps across cylinders
/// and walls) and with a start distance 2.5 m off it used to print a confident garbage model
/// with exit 0: now the result is still printed, with the failed checks, and the exit code is 1.
/// The run it is made for passes every check.
#[test]
fn em_checks_its_assumptions_and_a_failure_exits_1() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path(), "straight-board.toml", "board");
    record(tmp.path(), "landmarks-5.toml", "landmarks");
    let failed = |v: &serde_json::Value| -> Vec<String> {
        v["checks"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| c["pass"] == false)
            .map(|c| c["name"].as_str().unwrap().to_string())
            .collect()
    };
    let v = json(&hilsim(
        tmp.path(),
        &["calibrate", "board", "--method", "em", "--json"],
    ));
    assert!(failed(&v).is_empty(), "{v}");
    let names: Vec<&str> = v["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    for name in [
        "lidar.offset_plausible",
        "lidar.scale_plausible",
        "lidar.target_follows_commands",
        "lidar.innovation_size",
        "lidar.innovations_white",
        "path.heading_change_deg",
        "path.lateral_drift_m",
    ] {
        assert!(names.contains(&name), "{name} missing from {names:?}");
    }
    for c in v["checks"].as_array().unwrap() {
        for key in ["value", "threshold"] {
            assert!(c[key].is_number(), "{c}");
        }
        assert!(c["detail"].is_string(), "{c}");
    }

    let checked = |args: &[&str]| {
        let o = hilsim(tmp.path(), args);
        assert_eq!(o.status.code(), Some(1), "{}{}", stdout(&o), stderr(&o));
        let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
        assert!(v["sensors"]["lidar"]["alpha"].is_array(), "{v}");
        assert!(stderr(&o).contains("not to be trusted"), "{}", stderr(&o));
        failed(&v)
    };
    let f = checked(&["calibrate", "landmarks", "--method", "em", "--json"]);
    assert!(
        f.contains(&"lidar.target_follows_commands".to_string()),
        "{f:?}"
    );
    let f = checked(&[
        "calibrate",
        "board",
        "--method",
        "em",
        "--start-distance",
        "3.0",
        "--json",
    ]);
    assert!(f.contains(&"lidar.offset_plausible".to_string()), "{f:?}");

    // smooth: the distances are written, the misfit reported, exit 1.
    let cal = hilsim(
        tmp.path(),
        &["calibrate", "board", "--method", "em", "--json"],
    );
    std::fs::write(tmp.path().join("cal.json"), stdout(&cal)).unwrap();
    let o = hilsim(
        tmp.path(),
        &[
            "smooth",
            "board",
            "--calibration",
            "cal.json",
            "--start-distance",
            "3.0",
            "--csv",
            "d.csv",
        ],
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("lidar.innovation_size"),
        "{}",
        stderr(&o)
    );
    assert!(tmp.path().join("d.csv").exists());
    let o = hilsim(
        tmp.path(),
        &[
            "smooth",
            "board",
            "--calibration",
            "cal.json",
            "--csv",
            "d.csv",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// The landmark method's and the ground-truth baseline's checks pass on the runs they
/// are made for.
#[test]
fn landmarks_and_groundtruth_pass_their_checks_on_their_runs() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path(), "landmarks-5.toml", "landmarks");
    record(tmp.path(), "straight-board.toml", "board");
    for (rec, method, expected) in [
        (
            "landmarks",
            "landmarks",
            &[
                "landmarks.distance_span_m",
                "landmarks.triangulation_angle_deg",
                "landmarks.association_consistent",
            ][..],
        ),
        ("board", "groundtruth", &["lidar.residuals_white"][..]),
    ] {
        let v = json(&hilsim(
            tmp.path(),
            &["calibrate", rec, "--method", method, "--json"],
        ));
        let checks = v["checks"].as_array().unwrap();
        for name in expected {
            let c = checks
                .iter()
                .find(|c| c["name"] == *name)
                .unwrap_or_else(|| panic!("{name} missing: {v}"));
            assert_eq!(c["pass"], true, "{c}");
        }
    }
}

/// A prior on the sonar's scale (the speed of sound at a known temperature) makes the
/// drive's speed error identifiable. Straight-board at seed 3 draws a speed error the commands
/// do not know: without the prior EM's lidar model scores an MSE ratio of 5.3, with it 86 (the
/// true model's is 87.5; `python3 docs/em-priors-check.py` measures 24 runs). Tolerances: at
/// least 1.5× the ratio without the prior and 50 (0.57 of the true model's): the prior must
/// recover most of what the speed error costs.
#[test]
fn a_prior_on_the_sonar_scale_recovers_the_lidar_model() {
    let tmp = tempfile::tempdir().unwrap();
    let path = repo_file("scenarios/straight-board.toml");
    let o = hilsim(
        tmp.path(),
        &[
            "record",
            path.to_str().unwrap(),
            "--seed",
            "3",
            "--out",
            "rec",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let ratio = |extra: &[&str]| {
        let mut args = vec!["calibrate", "rec", "--method", "em", "--json"];
        args.extend(extra);
        let v = json(&hilsim(tmp.path(), &args));
        let r = v["metrics"]["lidar_model"]["mse_ratio"].as_f64().unwrap();
        (r, v)
    };
    let (without, _) = ratio(&[]);
    let (with, v) = ratio(&["--prior", "sonar.alpha1=1.028±0.003"]);
    assert!(with >= 1.5 * without && with >= 50.0, "{without} -> {with}");
    // q and the speed scale estimated together still converge (they once crept along a ridge).
    assert_eq!(v["converged"], true, "{v}");
    let notes = v["notes"].to_string();
    assert!(notes.contains("the commands' speed scale"), "{notes}");
    assert!(notes.contains("sonar.alpha1=1.028±0.003"), "{notes}");
    // `+-` for `±`.
    let (plus_minus, _) = ratio(&["--prior", "sonar.alpha1=1.028+-0.003"]);
    assert_eq!(plus_minus, with);

    for (args, says) in [
        (
            &[
                "calibrate",
                "rec",
                "--method",
                "em",
                "--prior",
                "sonar.alpha1=1.028",
            ][..],
            "--prior",
        ),
        (
            &[
                "calibrate",
                "rec",
                "--method",
                "em",
                "--prior",
                "sonar.beta0=0.01±0.001",
            ][..],
            "alpha only",
        ),
        (
            &[
                "calibrate",
                "rec",
                "--method",
                "groundtruth",
                "--prior",
                "sonar.alpha1=1.028±0.003",
            ][..],
            "--method em",
        ),
    ] {
        let o = hilsim(tmp.path(), args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(stderr(&o).contains(says), "{}", stderr(&o));
    }
}

#[test]
fn calibration_messages_name_the_method_run_and_the_range_expected() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path(), "straight-board.toml", "rec");
    let run = |args: &[&str]| assert_bad_input(&hilsim(tmp.path(), args));
    // Absurd options are refused before the data are blamed for them.
    for (flag, value, says) in [
        (
            "--prior",
            "sonar.alpha1=1e300±1e-300",
            "the value must be from -100 to 100",
        ),
        (
            "--prior",
            "sonar.alpha1=1±1e-300",
            "the sd must be positive: from 1e-6 to 100",
        ),
        (
            "--start-distance",
            "1e300",
            "expected a distance from 0.01 to 1000 m, found 1e300",
        ),
        (
            "--start-distance",
            "1e-300",
            "expected a distance from 0.01 to 1000 m, found 1e-300",
        ),
    ] {
        let err = run(&["calibrate", "rec", "--method", "em", flag, value]);
        assert!(err.contains(says), "{flag} {value}: {err}");
        assert!(!err.contains("singular"), "{err}");
    }
    // A recording without a lidar: each method's message names that method once, and no other.
    let nolidar = tmp.path().join("nolidar");
    std::fs::create_dir(&nolidar).unwrap();
    for entry in std::fs::read_dir(tmp.path().join("rec")).unwrap() {
        let path = entry.unwrap().path();
        if path.file_name().unwrap() != "lidar.csv" {
            std::fs::copy(&path, nolidar.join(path.file_name().unwrap())).unwrap();
        }
    }
    for method in ["landmarks", "groundtruth", "em"] {
        let err = run(&["calibrate", "nolidar", "--method", method]);
        assert!(
            err.starts_with(&format!(
                "hilsim: nolidar: {method}: the recording has no lidar.csv"
            )),
            "{err}"
        );
        assert_eq!(err.matches(method).count(), 1, "{err}");
        assert!(!err.contains("EM") || method == "em", "{err}");
    }
}

#[test]
fn a_byte_order_mark_before_a_csv_header_or_a_calibration_is_skipped() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path(), "straight-board.toml", "rec");
    let plain = hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "em", "--json"],
    );
    let lidar = tmp.path().join("rec/lidar.csv");
    let mut marked = "\u{feff}".as_bytes().to_vec();
    marked.extend(std::fs::read(&lidar).unwrap());
    std::fs::write(&lidar, marked).unwrap();
    let with_mark = hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "em", "--json"],
    );
    assert_eq!(json(&with_mark), json(&plain));
    let cal = format!("\u{feff}{}", stdout(&plain));
    std::fs::write(tmp.path().join("cal.json"), cal).unwrap();
    let o = hilsim(
        tmp.path(),
        &[
            "smooth",
            "rec",
            "--calibration",
            "cal.json",
            "--csv",
            "d.csv",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn smooth_refuses_a_calibration_that_is_ambiguous_or_not_one() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path(), "straight-board.toml", "rec");
    let cal = json(&hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "em", "--json"],
    ));
    let text = cal.to_string();
    let mut sd = cal.clone();
    sd["sensors"]["lidar"]["alpha_sd"] = serde_json::json!([0.1]);
    let mut method = cal.clone();
    method["method"] = serde_json::json!("<script>");
    for (name, content, says) in [
        (
            "dup-keys.json",
            format!("{},\"sensors\":{{}}}}", &text[..text.len() - 1]),
            "the key `sensors` appears twice",
        ),
        (
            "method.json",
            method.to_string(),
            r#"`method` must be em, landmarks, groundtruth or odometry, found "<script>""#,
        ),
        (
            "results.json",
            serde_json::json!({"scenario": "x", "calibrations": [cal]}).to_string(),
            "a run's results (a `calibrations` list), not one calibration",
        ),
        (
            "sd.json",
            sd.to_string(),
            "sensors.lidar.alpha_sd has 1 standard errors for 3 alpha coefficients",
        ),
    ] {
        std::fs::write(tmp.path().join(name), content).unwrap();
        let err = assert_bad_input(&hilsim(
            tmp.path(),
            &["smooth", "rec", "--calibration", name],
        ));
        assert!(err.contains(says), "{name}: {err}");
    }
}

#[test]
fn a_key_meta_toml_does_not_define_is_noted() {
    let tmp = tempfile::tempdir().unwrap();
    record(tmp.path(), "straight-board.toml", "rec");
    let meta = tmp.path().join("rec/meta.toml");
    let text = std::fs::read_to_string(&meta).unwrap();
    std::fs::write(&meta, text + "[bogus]\nx = 1\n").unwrap();
    let cal = json(&hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "em", "--json"],
    ));
    let notes: Vec<&str> = cal["notes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|n| n.as_str())
        .collect();
    assert!(
        notes.contains(&"meta.toml: `bogus` is not a key of the recording format; ignored"),
        "{notes:?}"
    );
}
