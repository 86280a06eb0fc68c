//! `hilsim import` of a ROS 1 bag: the scans and the lidar's mount from `/tf_static` reach the
//! recording and its `meta.toml`, each guess said in a note; a file that is no bag is one line.

use std::fs;

use crate::common::{assert_bad_input, hilsim, stdout};

/// A rosbag 2.0 record: header fields, then data.
fn record(fields: &[(&str, &[u8])], data: &[u8]) -> Vec<u8> {
    let mut header = Vec::new();
    for (name, value) in fields {
        let field = [name.as_bytes(), b"=", value].concat();
        header.extend((field.len() as u32).to_le_bytes());
        header.extend(field);
    }
    let mut out = (header.len() as u32).to_le_bytes().to_vec();
    out.extend(header);
    out.extend((data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
    out
}

fn string(s: &str) -> Vec<u8> {
    [&(s.len() as u32).to_le_bytes()[..], s.as_bytes()].concat()
}

/// `std_msgs/Header` at `sec` seconds.
fn header(sec: u32, frame: &str) -> Vec<u8> {
    [&[0u8; 4][..], &sec.to_le_bytes(), &[0; 4], &string(frame)].concat()
}

/// An uncompressed bag (unindexed, as one not closed): /scan (two readings, 1 m and 2 m, at 0°
/// and 90°) and /tf_static base_link → laser at x 0.12 m turned 180°.
fn robot_bag() -> Vec<u8> {
    let connection = |id: u32, topic: &str, ty: &str| {
        let data = [
            string(&format!("topic={topic}")),
            string(&format!("type={ty}")),
        ]
        .concat();
        let fields: [(&str, &[u8]); 3] = [
            ("op", &[7]),
            ("conn", &id.to_le_bytes()),
            ("topic", topic.as_bytes()),
        ];
        record(&fields, &data)
    };
    let message = |id: u32, sec: u32, data: &[u8]| {
        let fields: [(&str, &[u8]); 3] = [
            ("op", &[2]),
            ("conn", &id.to_le_bytes()),
            ("time", &u64::from(sec).to_le_bytes()),
        ];
        record(&fields, data)
    };
    let mut scan = header(100, "laser");
    let quarter = std::f32::consts::FRAC_PI_2;
    for x in [0.0f32, quarter, quarter, 0.0, 0.1, 0.1, 8.0] {
        scan.extend(x.to_le_bytes());
    }
    scan.extend(2u32.to_le_bytes());
    scan.extend([1.0f32, 2.0].iter().flat_map(|x| x.to_le_bytes()));
    scan.extend(0u32.to_le_bytes());
    let mut tf = 1u32.to_le_bytes().to_vec();
    tf.extend(header(100, "base_link"));
    tf.extend(string("laser"));
    tf.extend(
        [0.12f64, 0.0, 0.3, 0.0, 0.0, 1.0, 0.0]
            .iter()
            .flat_map(|x| x.to_le_bytes()),
    );
    let records = [
        connection(0, "/scan", "sensor_msgs/LaserScan"),
        connection(1, "/tf_static", "tf2_msgs/TFMessage"),
        message(1, 100, &tf),
        message(0, 100, &scan),
    ]
    .concat();
    let fields: [(&str, &[u8]); 3] = [
        ("op", &[5]),
        ("compression", b"none"),
        ("size", &(records.len() as u32).to_le_bytes()),
    ];
    let mut bag = b"#ROSBAG V2.0\n".to_vec();
    bag.extend(record(
        &[("op", &[3]), ("index_pos", &0u64.to_le_bytes())],
        &[],
    ));
    bag.extend(record(&fields, &records));
    bag
}

#[test]
fn a_ros1_bag_imports_with_the_tf_static_lidar_mount() {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(tmp.path().join("robot.bag"), robot_bag()).unwrap();
    let out = hilsim(tmp.path(), &["import", "robot.bag", "--out", "rec"]);
    let text = stdout(&out);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("lidar     /scan (sensor_msgs/msg/LaserScan): 2 rows"),
        "{text}"
    );
    assert!(
        text.contains(
            "note: lidar mount from /tf_static base_link→laser: x 0.12 m, y 0 m, yaw 180°"
        ),
        "{text}"
    );
    assert!(
        text.contains("note: no --meta: a minimal meta.toml"),
        "{text}"
    );
    let meta = fs::read_to_string(tmp.path().join("rec/meta.toml")).unwrap();
    assert!(
        meta.contains("x_m = 0.12") && meta.contains("yaw_deg = 180"),
        "{meta}"
    );
    let lidar = fs::read_to_string(tmp.path().join("rec/lidar.csv")).unwrap();
    assert_eq!(lidar.lines().count(), 3, "{lidar}");

    // A meta.toml's mount overrides the bag's.
    fs::write(
        tmp.path().join("robot.toml"),
        "format = \"hilsim-recording/1\"\n[robot]\nwheel_base_m = 0.3\n[lidar]\nx_m = 0.05\n",
    )
    .unwrap();
    let out = hilsim(
        tmp.path(),
        &[
            "import",
            "robot.bag",
            "--out",
            "rec2",
            "--meta",
            "robot.toml",
        ],
    );
    assert!(out.status.success());
    assert!(!stdout(&out).contains("lidar mount"));
    let meta = fs::read_to_string(tmp.path().join("rec2/meta.toml")).unwrap();
    assert!(meta.contains("x_m = 0.05"), "{meta}");
}

#[test]
fn a_file_named_bag_that_is_not_one_is_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(tmp.path().join("notes.bag"), "not a bag at all\n").unwrap();
    let out = hilsim(tmp.path(), &["import", "notes.bag", "--out", "rec"]);
    let err = assert_bad_input(&out);
    assert!(err.contains("notes.bag: not an MCAP file"), "{err}");
    fs::write(tmp.path().join("old.bag"), b"#ROSBAG V1.2\n").unwrap();
    let out = hilsim(tmp.path(), &["import", "old.bag", "--out", "rec"]);
    let err = assert_bad_input(&out);
    assert!(
        err.contains("old.bag: a ROS 1 bag of format 1.2, not 2.0"),
        "{err}"
    );
}
