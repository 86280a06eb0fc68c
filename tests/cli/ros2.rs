//! `hilsim import` and `hilsim export`: a recording exported as ROS 2 messages and
//! imported again is the recording, and bad bags are one-line errors.

use std::fs;

use hilsim_recording::Recording;

use crate::common::{assert_bad_input, hilsim, repo_file, stderr, stdout};

/// What an export keeps of each table, compared field by field: the LaserScan has no field for
/// the strength-warning flag or the simulator's true range, its per-reading times are the stamp
/// plus i × a float32 increment (within a microsecond of the original), and a yaw goes through
/// a quaternion (within 1e-12 rad). Everything else comes back exactly.
fn assert_round_trip(original: &Recording, back: &Recording) {
    assert_eq!(back.meta, original.meta);
    assert_eq!(back.commands.len(), original.commands.len());
    for (a, b) in original.commands.iter().zip(&back.commands) {
        assert_eq!(a.t_s, b.t_s);
        assert!((a.left_mps - b.left_mps).abs() < 1e-12, "{a:?} {b:?}");
        assert!((a.right_mps - b.right_mps).abs() < 1e-12, "{a:?} {b:?}");
    }
    assert_eq!(back.odometry, original.odometry);
    assert_eq!(
        back.sonar.as_ref().map(Vec::len),
        original.sonar.as_ref().map(Vec::len)
    );
    for (a, b) in original
        .sonar
        .iter()
        .flatten()
        .zip(back.sonar.iter().flatten())
    {
        assert_eq!((a.t_s, a.range_m), (b.t_s, b.range_m));
    }
    let (truth, truth_back) = (
        original.truth.as_ref().unwrap(),
        back.truth.as_ref().unwrap(),
    );
    assert_eq!(truth.len(), truth_back.len());
    for (a, b) in truth.iter().zip(truth_back) {
        assert_eq!((a.t_s, a.x_m, a.y_m), (b.t_s, b.x_m, b.y_m));
        let d = hilsim_recording::wrap_angle(a.yaw_rad - b.yaw_rad);
        assert!(d.abs() < 1e-12, "{a:?} {b:?}");
    }
    let (lidar, lidar_back) = (
        original.lidar.as_ref().unwrap(),
        back.lidar.as_ref().unwrap(),
    );
    assert_eq!(lidar.len(), lidar_back.len());
    for (a, b) in lidar.iter().zip(lidar_back) {
        let same = (a.rev, a.angle_deg, a.range_m, a.strength, a.invalid);
        assert_eq!(same, (b.rev, b.angle_deg, b.range_m, b.strength, b.invalid));
        assert!((a.t_s - b.t_s).abs() <= 1.000_001e-6, "{a:?} {b:?}");
    }
}

#[test]
fn a_recording_exported_and_imported_is_the_recording() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = repo_file("scenarios/straight-board.toml");
    let out = hilsim(
        tmp.path(),
        &[
            "record",
            scenario.to_str().unwrap(),
            "--out",
            "rec",
            "--mcap",
            "rec.mcap",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let out = hilsim(
        tmp.path(),
        &[
            "import",
            "rec.mcap",
            "--out",
            "back",
            "--meta",
            "rec/meta.toml",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.contains("lidar     /scan (sensor_msgs/msg/LaserScan): "),
        "{text}"
    );
    assert!(
        text.contains("sonar     /sonar (sensor_msgs/msg/Range): "),
        "{text}"
    );
    let original = Recording::read_dir(&tmp.path().join("rec")).unwrap();
    let back = Recording::read_dir(&tmp.path().join("back")).unwrap();
    assert_round_trip(&original, &back);

    // `export` writes the same file as `record --mcap`, and a bag directory reads as its file.
    let out = hilsim(
        tmp.path(),
        &[
            "export",
            "rec",
            "--mcap",
            "again.mcap",
            "--scenario",
            scenario.to_str().unwrap(),
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        fs::read(tmp.path().join("rec.mcap")).unwrap(),
        fs::read(tmp.path().join("again.mcap")).unwrap()
    );
    let bag = tmp.path().join("bag");
    fs::create_dir(&bag).unwrap();
    fs::rename(tmp.path().join("again.mcap"), bag.join("bag_0.mcap")).unwrap();
    fs::write(
        bag.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  \
         relative_file_paths:\n    - bag_0.mcap\n",
    )
    .unwrap();
    let out = hilsim(tmp.path(), &["import", "bag", "--out", "back2"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("note: no --meta: a minimal meta.toml"));
    let back2 = Recording::read_dir(&tmp.path().join("back2")).unwrap();
    assert_eq!(back2.lidar, back.lidar);
    // The sonar's beam comes from the Range messages when meta.toml does not say.
    assert_eq!(back2.meta.sonar.unwrap().half_angle_deg, 15.0);
}

/// With a calibration, the export carries the calibrated scans as a second LaserScan topic:
/// the import then asks which lidar topic is meant, and the calibrated one is nearer the truth.
#[test]
fn a_calibrated_export_carries_the_calibrated_scans() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = repo_file("scenarios/straight-board.toml");
    let out = hilsim(
        tmp.path(),
        &["record", scenario.to_str().unwrap(), "--out", "rec"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let out = hilsim(
        tmp.path(),
        &["calibrate", "rec", "--method", "em", "--json"],
    );
    fs::write(tmp.path().join("em.json"), &out.stdout).unwrap();
    let args = [
        "export",
        "rec",
        "--mcap",
        "c.mcap",
        "--calibration",
        "em.json",
    ];
    let out = hilsim(tmp.path(), &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = hilsim(tmp.path(), &["import", "c.mcap", "--out", "r"]);
    let err = assert_bad_input(&out);
    assert!(err.ends_with("2 topics of type sensor_msgs/msg/LaserScan: /scan, /scan_calibrated; choose the lidar's with --lidar TOPIC\n"), "{err}");
    let args = [
        "import",
        "c.mcap",
        "--out",
        "r",
        "--lidar",
        "/scan_calibrated",
    ];
    let out = hilsim(tmp.path(), &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let raw = Recording::read_dir(&tmp.path().join("rec")).unwrap();
    let calibrated = Recording::read_dir(&tmp.path().join("r")).unwrap();
    let mse = |rec: &Recording| {
        let pairs: Vec<(f64, f64)> = rec
            .lidar
            .as_ref()
            .unwrap()
            .iter()
            .zip(raw.lidar.as_ref().unwrap())
            .filter(|(s, _)| !s.invalid && s.angle_deg == 0.0)
            .map(|(s, truth)| (s.range_m, truth.true_range_m.unwrap()))
            .collect();
        pairs.iter().map(|(r, d)| (r - d).powi(2)).sum::<f64>() / pairs.len() as f64
    };
    // EM's own figure for this run is an MSE ratio above 3 (scenarios/straight-board.toml).
    assert!(
        mse(&raw) > 3.0 * mse(&calibrated),
        "{} {}",
        mse(&raw),
        mse(&calibrated)
    );
}

#[test]
fn bad_bags_are_one_line_errors_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(tmp.path().join("notes.mcap"), "not a bag\n").unwrap();
    let out = hilsim(tmp.path(), &["import", "notes.mcap", "--out", "r"]);
    let err = assert_bad_input(&out);
    assert!(err.contains("notes.mcap: not an MCAP file"), "{err}");
    assert!(!tmp.path().join("r").exists());

    let scenario = repo_file("scenarios/straight-board.toml");
    let rec = hilsim(
        tmp.path(),
        &[
            "record",
            scenario.to_str().unwrap(),
            "--out",
            "rec",
            "--mcap",
            "full.mcap",
        ],
    );
    assert!(rec.status.success(), "{}", stderr(&rec));
    let full = fs::read(tmp.path().join("full.mcap")).unwrap();
    fs::write(tmp.path().join("cut.mcap"), &full[..full.len() / 2]).unwrap();
    let out = hilsim(tmp.path(), &["import", "cut.mcap", "--out", "r"]);
    let err = assert_bad_input(&out);
    assert!(err.contains("cut.mcap: "), "{err}");
    assert!(!tmp.path().join("r").exists());

    let out = hilsim(
        tmp.path(),
        &["import", "full.mcap", "--out", "r", "--lidar", "/odom"],
    );
    let err = assert_bad_input(&out);
    assert!(
        err.contains(
            "topic /odom is nav_msgs/msg/Odometry; --lidar takes sensor_msgs/msg/LaserScan"
        ),
        "{err}"
    );
    let out = hilsim(tmp.path(), &["import", "nowhere", "--out", "r"]);
    assert!(assert_bad_input(&out).contains("nowhere: "));
    let out = hilsim(tmp.path(), &["export", "nowhere", "--mcap", "x.mcap"]);
    assert!(assert_bad_input(&out).contains("nowhere"));
    assert!(!tmp.path().join("x.mcap").exists());
}

#[test]
fn wheel_joints_are_two_names() {
    let tmp = tempfile::tempdir().unwrap();
    for joints in ["left_wheel", "a,b,c", ",right", "w,w"] {
        let args = ["import", "x.mcap", "--out", "r", "--wheel-joints", joints];
        let err = assert_bad_input(&hilsim(tmp.path(), &args));
        assert!(
            err.contains("--wheel-joints: expected LEFT,RIGHT, two different joint names"),
            "{joints}: {err}"
        );
    }
}

/// A bag's topic holding terminal sequences reaches stdout as visible escapes, not as the
/// sequences themselves.
#[test]
fn topic_names_reach_the_terminal_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let string = |b: &[u8]| [&u32::try_from(b.len()).unwrap().to_le_bytes()[..], b].concat();
    let record =
        |op: u8, body: &[u8]| [&[op][..], &(body.len() as u64).to_le_bytes(), body].concat();
    // A LaserScan of no readings: stamp 1 s, frame "", pad to 4, 7 float32 zeros, two empty
    // sequences.
    let mut scan = vec![0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0];
    scan.extend_from_slice(&[0; 36]);
    let mut message = [1u16.to_le_bytes().to_vec(), 0u32.to_le_bytes().to_vec()].concat();
    message.extend_from_slice(&1_000_000_000u64.to_le_bytes());
    message.extend_from_slice(&1_000_000_000u64.to_le_bytes());
    message.extend_from_slice(&scan);
    let magic = b"\x89MCAP0\r\n";
    let bag = [
        magic.to_vec(),
        record(1, &[string(b"ros2"), string(b"test")].concat()),
        record(
            3,
            &[
                &1u16.to_le_bytes()[..],
                &string(b"sensor_msgs/msg/LaserScan"),
                &string(b"ros2msg"),
                &string(b""),
            ]
            .concat(),
        ),
        record(
            4,
            &[
                &1u16.to_le_bytes()[..],
                &1u16.to_le_bytes(),
                &string(b"/scan\x1b[31m\x1b]0;x\x07"),
                &string(b"cdr"),
                &string(b""),
            ]
            .concat(),
        ),
        record(5, &message),
        record(0x0F, &0u32.to_le_bytes()),
        record(2, &[0u8; 20]),
        magic.to_vec(),
    ]
    .concat();
    fs::write(tmp.path().join("escapes.mcap"), bag).unwrap();
    let out = hilsim(tmp.path(), &["import", "escapes.mcap", "--out", "r"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let shown = stdout(&out);
    assert!(
        shown.contains("lidar     /scan\\e[31m\\e]0;x\\u{7} (sensor_msgs/msg/LaserScan): 0 rows"),
        "{shown}"
    );
    assert!(!shown.contains('\u{1b}'), "{shown}");
}

/// A recording time beyond what a ROS 2 stamp holds is refused in one line, not exported
/// wrapped.
#[test]
fn export_refuses_times_no_stamp_holds() {
    use hilsim_recording::{Meta, Recording, TruthSample};
    let tmp = tempfile::tempdir().unwrap();
    let mut rec = Recording::new(Meta::default());
    let pose = |t_s| TruthSample {
        t_s,
        x_m: 0.0,
        y_m: 0.0,
        yaw_rad: 0.0,
    };
    rec.truth = Some(vec![pose(0.0), pose(3.7e292)]);
    rec.write_dir(&tmp.path().join("far")).unwrap();
    let out = hilsim(tmp.path(), &["export", "far", "--mcap", "far.mcap"]);
    let err = assert_bad_input(&out);
    assert!(
        err.contains("truth.csv: row 2: t_s 3.7e292 s, beyond what a ROS 2 stamp holds"),
        "{err}"
    );
    assert!(!tmp.path().join("far.mcap").exists());
}
