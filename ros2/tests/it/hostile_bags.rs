//! Bags made to break an import, written record by record as a hostile writer would: a chunk
//! that inflates to gigabytes, names of megabytes, a summary that contradicts the data, messages
//! of another type, names that hold terminal escapes, paths out of the bag's directory. Each
//! must be refused in one line saying what is wrong, in bounded time and memory, or imported
//! without losing a message or writing a number that is not finite.

use std::fs;
use std::path::Path;

use byteorder::LittleEndian;
use hilsim_recording::Recording;
use hilsim_ros2::msgs::{Header, LaserScan, Odometry, Range, Time};
use hilsim_ros2::{import, ImportOptions};
use serde::Serialize;

const MAGIC: &[u8] = b"\x89MCAP0\r\n";
const LASER_SCAN: &str = "sensor_msgs/msg/LaserScan";
const ODOMETRY: &str = "nav_msgs/msg/Odometry";
const T0_NS: u64 = 1_700_000_000_000_000_000;

fn string(bytes: &[u8]) -> Vec<u8> {
    let mut out = u32::try_from(bytes.len()).unwrap().to_le_bytes().to_vec();
    out.extend_from_slice(bytes);
    out
}

fn record(opcode: u8, body: &[u8]) -> Vec<u8> {
    let mut out = vec![opcode];
    out.extend_from_slice(&(body.len() as u64).to_le_bytes());
    out.extend_from_slice(body);
    out
}

fn schema(id: u16, name: &[u8]) -> Vec<u8> {
    let mut body = id.to_le_bytes().to_vec();
    body.extend([string(name), string(b"ros2msg"), string(b"")].concat());
    record(0x03, &body)
}

fn channel(id: u16, schema_id: u16, topic: &[u8]) -> Vec<u8> {
    let mut body = [id.to_le_bytes(), schema_id.to_le_bytes()].concat();
    body.extend([string(topic), string(b"cdr"), string(b"")].concat());
    record(0x04, &body)
}

fn message(channel_id: u16, k: u64, data: &[u8]) -> Vec<u8> {
    let log = T0_NS + k * 100_000_000;
    let mut body = channel_id.to_le_bytes().to_vec();
    body.extend_from_slice(&u32::try_from(k).unwrap().to_le_bytes());
    body.extend_from_slice(&log.to_le_bytes());
    body.extend_from_slice(&log.to_le_bytes());
    body.extend_from_slice(data);
    record(0x05, &body)
}

/// A zstd chunk of `records` whose header says it holds `declared` bytes (its CRC 0: not
/// checked).
fn chunk(records: &[u8], declared: u64) -> Vec<u8> {
    let compressed = zstd::encode_all(records, 3).unwrap();
    let mut body = [
        0u64.to_le_bytes(),
        0u64.to_le_bytes(),
        declared.to_le_bytes(),
    ]
    .concat();
    body.extend_from_slice(&0u32.to_le_bytes());
    body.extend(string(b"zstd"));
    body.extend_from_slice(&(compressed.len() as u64).to_le_bytes());
    body.extend(compressed);
    record(0x06, &body)
}

/// A whole file: the magic and header, `data`, the data end, a summary section of `summary`
/// (none when empty) and the footer.
fn mcap(data: &[u8], summary: &[u8]) -> Vec<u8> {
    let mut out = MAGIC.to_vec();
    out.extend(record(0x01, &[string(b"ros2"), string(b"test")].concat()));
    out.extend_from_slice(data);
    out.extend(record(0x0F, &0u32.to_le_bytes()));
    let summary_start = if summary.is_empty() {
        0
    } else {
        out.len() as u64
    };
    out.extend_from_slice(summary);
    let footer = [summary_start.to_le_bytes(), 0u64.to_le_bytes()].concat();
    out.extend(record(
        0x02,
        &[footer, 0u32.to_le_bytes().to_vec()].concat(),
    ));
    out.extend_from_slice(MAGIC);
    out
}

fn cdr<T: Serialize>(message: &T) -> Vec<u8> {
    let mut out = vec![0, 1, 0, 0];
    cdr_encoding::to_writer::<T, LittleEndian, _>(&mut out, message).unwrap();
    out
}

fn header(k: u64) -> Header {
    Header {
        stamp: Time::from_ns(i64::try_from(T0_NS + k * 100_000_000).unwrap()),
        frame_id: "laser".into(),
    }
}

fn scan(k: u64) -> Vec<u8> {
    cdr(&LaserScan {
        header: header(k),
        angle_increment: 1f32.to_radians(),
        range_min: 0.1,
        range_max: 6.0,
        ranges: vec![1.5; 360],
        ..LaserScan::default()
    })
}

fn odometry(k: u64, x: f64) -> Vec<u8> {
    let mut odometry = Odometry {
        header: header(k),
        ..Odometry::default()
    };
    odometry.pose.pose.position.x = x;
    cdr(&odometry)
}

/// A bag of `n` scans on `/scan`, in one chunk.
fn scans(n: u64) -> Vec<u8> {
    let mut records = [schema(1, LASER_SCAN.as_bytes()), channel(1, 1, b"/scan")].concat();
    for k in 0..n {
        records.extend(message(1, k, &scan(k)));
    }
    records
}

/// The error of importing `bytes` written as `name`, which must be one line naming the file.
fn refused(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let bag = dir.join(name);
    fs::write(&bag, bytes).unwrap();
    let out = dir.join(format!("{name}.out"));
    let err = import(&bag, &out, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.starts_with(&bag.display().to_string()), "{err}");
    assert!(!err.contains('\n'), "{err}");
    assert!(!out.exists());
    err
}

#[test]
fn a_chunk_is_held_to_its_declared_size_and_the_size_limit_before_it_inflates() {
    let dir = tempfile::tempdir().unwrap();
    let zeros = vec![0u8; 8 << 20];
    // 16 GiB declared: refused from the header, before any of it is decompressed.
    let err = refused(
        dir.path(),
        "huge.mcap",
        &mcap(&chunk(&zeros, 16 << 30), &[]),
    );
    assert!(
        err.contains(
            "a chunk of 17179869184 bytes uncompressed (as its header says), beyond the 128 MiB"
        ),
        "{err}"
    );
    // A header that says less than comes out: stopped where it says.
    let mut lying = scans(3);
    lying.extend_from_slice(&zeros);
    let err = refused(dir.path(), "lying.mcap", &mcap(&chunk(&lying, 1000), &[]));
    assert!(
        err.contains("a chunk that does not decompress as its header says"),
        "{err}"
    );
}

#[test]
fn zero_bytes_where_a_record_starts_are_named_not_called_truncated() {
    let dir = tempfile::tempdir().unwrap();
    let zeros = vec![0u8; 1 << 20];
    let err = refused(
        dir.path(),
        "zeros.mcap",
        &mcap(&chunk(&zeros, 1 << 20), &[]),
    );
    assert!(err.contains("a record of opcode 0x00"), "{err}");
    assert!(!err.contains("truncated"), "{err}");
    let err = refused(dir.path(), "empty.mcap", b"");
    assert!(err.ends_with("an empty file (0 bytes), not a bag"), "{err}");
}

#[test]
fn names_longer_than_a_ros_name_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let long = vec![b'A'; 300];
    let records = [schema(7, &long), scans(2)].concat();
    let err = refused(
        dir.path(),
        "schema.mcap",
        &mcap(&chunk(&records, records.len() as u64), &[]),
    );
    assert!(
        err.contains("schema 7: a type name of 300 bytes, longer than any ROS 2 name"),
        "{err}"
    );
    let records = [scans(2), channel(9, 1, &long)].concat();
    let err = refused(dir.path(), "topic.mcap", &mcap(&records, &[]));
    assert!(err.contains("channel 9: a topic of 300 bytes"), "{err}");
}

#[test]
fn a_summary_that_contradicts_the_data_section_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut data = [schema(1, ODOMETRY.as_bytes()), channel(1, 1, b"/odom")].concat();
    for k in 0..5 {
        data.extend(message(1, k, &odometry(k, 0.01 * k as f64)));
    }
    let summary = [schema(1, LASER_SCAN.as_bytes()), channel(1, 1, b"/scan")].concat();
    let err = refused(
        dir.path(),
        "lies.mcap",
        &mcap(&chunk(&data, data.len() as u64), &summary),
    );
    assert!(
        err.contains(
            "channel 1 is /odom (nav_msgs/msg/Odometry) in the data section but /scan \
             (sensor_msgs/msg/LaserScan) in the summary section"
        ),
        "{err}"
    );
    // A summary without the data's channel would lose its messages as well.
    let data = scans(3);
    let summary = [schema(1, LASER_SCAN.as_bytes()), channel(2, 1, b"/scan")].concat();
    let err = refused(dir.path(), "missing.mcap", &mcap(&data, &summary));
    assert!(err.contains("channel 1 (/scan (sensor_msgs/msg/LaserScan)) is in the data section but not in the summary"), "{err}");
    // The summary as the data says: read.
    let summary = [schema(1, LASER_SCAN.as_bytes()), channel(1, 1, b"/scan")].concat();
    let bag = dir.path().join("honest.mcap");
    fs::write(&bag, mcap(&data, &summary)).unwrap();
    let report = import(&bag, &dir.path().join("honest"), &ImportOptions::default()).unwrap();
    assert_eq!(report.rows.values().sum::<u64>(), 3 * 360);
}

#[test]
fn a_message_that_is_not_its_type_names_the_topic_and_message() {
    let dir = tempfile::tempdir().unwrap();
    let mut records = scans(2);
    records.extend(message(1, 2, &odometry(2, 1.0)));
    let err = refused(dir.path(), "odometry-as-scan.mcap", &mcap(&records, &[]));
    assert!(
        err.contains("topic /scan, message 3: not a sensor_msgs/msg/LaserScan ("),
        "{err}"
    );
    let mut records = scans(1);
    let mut long = scan(1);
    long.extend_from_slice(&[1; 100]);
    records.extend(message(1, 1, &long));
    let err = refused(dir.path(), "long.mcap", &mcap(&records, &[]));
    assert!(
        err.contains(
            "message 2: not a sensor_msgs/msg/LaserScan (100 bytes after the message's last field"
        ),
        "{err}"
    );
}

#[test]
fn topic_names_are_shown_escaped_and_ten_at_most() {
    let dir = tempfile::tempdir().unwrap();
    let mut records = vec![schema(1, LASER_SCAN.as_bytes())];
    records.push(channel(1, 1, b"/a\x1b]0;pwned\x07\x1b[2J"));
    for id in 2..14u16 {
        records.push(channel(id, 1, format!("/scan{id:02}").as_bytes()));
    }
    let err = refused(dir.path(), "many.mcap", &mcap(&records.concat(), &[]));
    assert!(
        err.contains(
            "13 topics of type sensor_msgs/msg/LaserScan: /a\\e]0;pwned\\u{7}\\e[2J, /scan02,"
        ),
        "{err}"
    );
    assert!(
        err.contains(", /scan10, and 3 more; choose the lidar's with --lidar TOPIC"),
        "{err}"
    );
    assert!(!err.chars().any(char::is_control), "{err}");
}

/// A bag directory lists its files in `metadata.yaml`: none of them may be outside it.
#[test]
fn bag_directory_files_outside_it_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let outside = dir.path().join("outside.mcap");
    fs::write(&outside, mcap(&scans(2), &[])).unwrap();
    let bag = dir.path().join("bag");
    fs::create_dir(&bag).unwrap();
    let yaml = |name: &str| {
        format!(
            "rosbag2_bagfile_information:\n  storage_identifier: mcap\n  relative_file_paths:\n    - {name}\n"
        )
    };
    let mut listed = vec!["../outside.mcap".to_string(), outside.display().to_string()];
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&outside, bag.join("link.mcap")).unwrap();
        listed.push("link.mcap".to_string());
    }
    for name in listed {
        fs::write(bag.join("metadata.yaml"), yaml(&name)).unwrap();
        let err = import(&bag, &dir.path().join("out"), &ImportOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.ends_with(&format!("metadata.yaml: relative_file_paths lists {name}, which leaves the bag's directory: refused")),
            "{err}"
        );
    }
    fs::copy(&outside, bag.join("inside.mcap")).unwrap();
    fs::write(bag.join("metadata.yaml"), yaml("./inside.mcap")).unwrap();
    import(&bag, &dir.path().join("out"), &ImportOptions::default()).unwrap();
    // The recording just written, given as the bag.
    let err = import(
        &dir.path().join("out"),
        &dir.path().join("again"),
        &ImportOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.ends_with(
            "a hilsim recording (it has a meta.toml), not a ROS 2 bag: it needs no import"
        ),
        "{err}"
    );
}

fn range(k: u64, field_of_view: f32) -> Vec<u8> {
    cdr(&Range {
        header: header(k),
        field_of_view,
        min_range: 0.02,
        max_range: 4.0,
        range: 1.0,
        ..Range::default()
    })
}

#[test]
fn the_sonar_half_angle_is_the_first_usable_field_of_view_or_a_note_says_why_not() {
    let dir = tempfile::tempdir().unwrap();
    let bag = |name: &str, field_of_view: &dyn Fn(u64) -> f32| {
        let mut records = [
            schema(1, b"sensor_msgs/msg/Range"),
            channel(1, 1, b"/range"),
        ]
        .concat();
        for k in 0..5 {
            records.extend(message(1, k, &range(k, field_of_view(k))));
        }
        let path = dir.path().join(name);
        fs::write(&path, mcap(&records, &[])).unwrap();
        let out = dir.path().join(format!("{name}.out"));
        let report = import(&path, &out, &ImportOptions::default()).unwrap();
        (Recording::read_dir(&out).unwrap(), report.notes)
    };
    let (recording, notes) = bag("nan-first.mcap", &|k| if k == 0 { f32::NAN } else { 0.5 });
    assert_eq!(recording.sonar.unwrap().len(), 5);
    let half_angle = recording.meta.sonar.unwrap().half_angle_deg;
    assert!(
        (half_angle - 0.25f64.to_degrees()).abs() < 1e-5,
        "{half_angle}"
    );
    assert!(
        notes
            .iter()
            .any(|n| n.contains("first usable field_of_view; 1 before it")),
        "{notes:?}"
    );
    let (recording, notes) = bag("huge.mcap", &|_| 100.0);
    assert_eq!(recording.sonar.unwrap().len(), 5);
    assert!(recording.meta.sonar.is_none());
    assert!(
        notes
            .iter()
            .any(|n| n
                .starts_with("no [sonar] in meta.toml: no message of /range has a field_of_view")),
        "{notes:?}"
    );
}

#[test]
fn poses_far_apart_give_finite_wheel_travel_or_an_error_never_inf() {
    let dir = tempfile::tempdir().unwrap();
    let bag = |name: &str, x: &dyn Fn(u64) -> f64| {
        let mut records = [schema(1, ODOMETRY.as_bytes()), channel(1, 1, b"/odom")].concat();
        for k in 0..6 {
            records.extend(message(1, k, &odometry(k, x(k))));
        }
        let path = dir.path().join(name);
        fs::write(&path, mcap(&records, &[])).unwrap();
        let out = dir.path().join(format!("{name}.out"));
        import(&path, &out, &ImportOptions::default()).map(|_| Recording::read_dir(&out).unwrap())
    };
    let huge = bag("huge.mcap", &|k| if k % 2 == 1 { 1e300 } else { 0.0 }).unwrap();
    let odometry = huge.odometry.unwrap();
    assert_eq!(odometry.len(), 6);
    assert!(odometry
        .iter()
        .all(|o| o.left_m.is_finite() && o.right_m.is_finite()));
    assert_eq!(odometry[1].left_m, 1e300);
    let err = bag("beyond.mcap", &|k| {
        if k % 2 == 1 {
            f64::MAX
        } else {
            -f64::MAX
        }
    })
    .unwrap_err()
    .to_string();
    assert!(err.contains("topic /odom, message 2: a pose at (1.7976931348623157e308, 0e0) m that puts the wheel travel beyond any number"), "{err}");
}

#[test]
fn sqlite_rows_of_another_type_and_ids_out_of_range_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let bag = |name: &str, id: i64, data: rusqlite::types::Value| {
        let path = dir.path().join(name);
        let db = rusqlite::Connection::open(&path).unwrap();
        db.execute_batch(
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, \
             serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);
             CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, \
             timestamp INTEGER NOT NULL, data BLOB NOT NULL);",
        )
        .unwrap();
        db.execute(
            "INSERT INTO topics VALUES (?1, '/scan', ?2, 'cdr', '')",
            rusqlite::params![id, LASER_SCAN],
        )
        .unwrap();
        db.execute(
            "INSERT INTO messages VALUES (4, ?1, 1700000000000000000, ?2)",
            rusqlite::params![id, data],
        )
        .unwrap();
        drop(db);
        import(
            &path,
            &dir.path().join(format!("{name}.out")),
            &ImportOptions::default(),
        )
        .unwrap_err()
        .to_string()
    };
    let err = bag("negative.db3", -5, rusqlite::types::Value::Blob(scan(0)));
    assert!(
        err.ends_with(
            "negative.db3: table topics: topic /scan: id -5, not a channel id (0 to 65535)"
        ),
        "{err}"
    );
    let err = bag("text.db3", 1, rusqlite::types::Value::Text("a text".into()));
    assert!(err.ends_with("text.db3: table messages, id 4: column data holds text, expected a blob (the message's bytes)"), "{err}");
}

#[test]
fn wheel_joints_without_a_radius_are_refused_whatever_the_odometry() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("scans.mcap");
    fs::write(&bag, mcap(&scans(2), &[])).unwrap();
    let options = ImportOptions {
        wheel_joints: Some(["l".into(), "r".into()]),
        ..ImportOptions::default()
    };
    let err = import(&bag, &dir.path().join("out"), &options)
        .unwrap_err()
        .to_string();
    assert!(
        err.ends_with("its wheel angles need --wheel-radius-m R to become wheel travel"),
        "{err}"
    );
}
