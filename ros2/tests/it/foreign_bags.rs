//! Bags as other ROS 2 libraries and robots write them: wheel joints instead of
//! Odometry, split bags, scans that turn clockwise or start off zero, NaN and inf readings,
//! other frame names, `ros2idl` schemas, big-endian CDR and namespaced topics. Each bag is
//! written here with the `mcap` crate, message by message, as such a writer lays it out.

use std::collections::BTreeMap;
use std::fs;
use std::path::Path;

use byteorder::{BigEndian, LittleEndian};
use hilsim_recording::{OdometrySample, Recording};
use hilsim_ros2::msgs::{
    Header, JointState, LaserScan, Odometry, Quaternion, Range, TfMessage, Time, Transform,
    TransformStamped, Vector3,
};
use hilsim_ros2::{import, ImportOptions, Role};
use mcap::records::MessageHeader;
use serde::Serialize;

/// The bag's clock starts at 1,700,000,000 s, as a robot's wall clock.
const T0_NS: i64 = 1_700_000_000_000_000_000;

/// One message to write: topic, type, time since T0 (stamp and log time), CDR bytes.
struct Message {
    topic: &'static str,
    type_name: &'static str,
    t_ns: i64,
    data: Vec<u8>,
}

fn header(t_ns: i64, frame: &str) -> Header {
    Header {
        stamp: Time::from_ns(T0_NS + t_ns),
        frame_id: frame.to_string(),
    }
}

/// Little-endian CDR, as ROS 2 writes on x86 and ARM.
fn cdr<T: Serialize>(message: &T) -> Vec<u8> {
    let mut out = vec![0, 1, 0, 0];
    cdr_encoding::to_writer::<T, LittleEndian, _>(&mut out, message).unwrap();
    out
}

/// Big-endian CDR (representation 0x0000), which a big-endian host's DDS writes.
fn cdr_big_endian<T: Serialize>(message: &T) -> Vec<u8> {
    let mut out = vec![0, 0, 0, 0];
    cdr_encoding::to_writer::<T, BigEndian, _>(&mut out, message).unwrap();
    out
}

/// An MCAP file of `messages`, schemas of `schema_encoding` (`ros2msg` or `ros2idl`; the
/// text is not read by hilsim, only the type's name).
fn write_mcap(path: &Path, schema_encoding: &str, messages: &[Message]) {
    let file = fs::File::create(path).unwrap();
    let mut writer = mcap::Writer::new(std::io::BufWriter::new(file)).unwrap();
    let mut channels = BTreeMap::new();
    for (sequence, m) in messages.iter().enumerate() {
        let id = *channels.entry(m.topic).or_insert_with(|| {
            let schema = writer
                .add_schema(m.type_name, schema_encoding, b"# not read")
                .unwrap();
            writer
                .add_channel(schema, m.topic, "cdr", &BTreeMap::new())
                .unwrap()
        });
        let time = u64::try_from(T0_NS + m.t_ns).unwrap();
        let header = MessageHeader {
            channel_id: id,
            sequence: u32::try_from(sequence).unwrap(),
            log_time: time,
            publish_time: time,
        };
        writer.write_to_known_channel(&header, &m.data).unwrap();
    }
    writer.finish().unwrap();
}

fn joint_state(t_ns: i64, names: &[&str], positions: &[f64]) -> Message {
    Message {
        topic: "/joint_states",
        type_name: "sensor_msgs/msg/JointState",
        t_ns,
        data: cdr(&JointState {
            header: header(t_ns, ""),
            name: names.iter().map(|n| (*n).to_string()).collect(),
            position: positions.to_vec(),
            velocity: vec![0.0; positions.len()],
            effort: Vec::new(),
        }),
    }
}

fn options(wheel_radius_m: Option<f64>) -> ImportOptions {
    ImportOptions {
        wheel_radius_m,
        ..ImportOptions::default()
    }
}

/// A TurtleBot-like robot's joint states: the wheels among other joints, every 50 ms, and an
/// arm's joints published in messages of their own on the same topic.
fn wheel_bag(path: &Path, names: [&str; 3]) {
    let mut messages = Vec::new();
    for k in 0..20 {
        let t_ns = i64::from(k) * 50_000_000;
        let left = 0.5 + 0.1 * f64::from(k);
        let right = -0.25 + 0.3 * f64::from(k);
        messages.push(joint_state(t_ns, &names, &[1.5, left, right]));
        messages.push(joint_state(
            t_ns + 1_000,
            &["shoulder", "elbow"],
            &[0.1, 0.2],
        ));
    }
    write_mcap(path, "ros2msg", &messages);
}

#[test]
fn wheel_joint_angles_times_the_radius_are_the_wheel_travel() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("joints.mcap");
    wheel_bag(
        &bag,
        ["caster_joint", "wheel_left_joint", "wheel_right_joint"],
    );
    let out = dir.path().join("rec");
    let radius = 0.033;
    let report = import(&bag, &out, &options(Some(radius))).unwrap();
    let odometry = Recording::read_dir(&out).unwrap().odometry.unwrap();
    assert_eq!(odometry.len(), 20);
    for (k, o) in odometry.iter().enumerate() {
        let k = k as f64;
        let expected = OdometrySample {
            t_s: 0.05 * k,
            left_m: ((0.5 + 0.1 * k) - 0.5) * radius,
            right_m: ((-0.25 + 0.3 * k) + 0.25) * radius,
        };
        // The angles' sums and differences round at 1e-16 rad.
        assert!((o.t_s - expected.t_s).abs() < 1e-12, "{o:?} {expected:?}");
        assert!(
            (o.left_m - expected.left_m).abs() < 1e-15,
            "{o:?} {expected:?}"
        );
        assert!(
            (o.right_m - expected.right_m).abs() < 1e-15,
            "{o:?} {expected:?}"
        );
    }
    // The arm's messages are skipped, and said so.
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.starts_with("20 JointState messages without a position")),
        "{:?}",
        report.notes
    );
}

#[test]
fn wheel_joints_that_are_not_plain_are_named_or_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("skid.mcap");
    // A skid-steer robot: two wheels a side, none of them told apart by `wheel`.
    let names = ["front_left_wheel", "rear_left_wheel", "right_wheel"];
    wheel_bag(&bag, names);
    let out = dir.path().join("rec");
    let err = import(&bag, &out, &options(Some(0.1)))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(
            "skid.mcap: topic /joint_states, message 1: which joints are the wheels? several"
        ) && err.ends_with("name the wheels with --wheel-joints LEFT,RIGHT"),
        "{err}"
    );
    assert!(!err.contains('\n'));
    assert!(!out.exists());
    let named = ImportOptions {
        wheel_joints: Some(["rear_left_wheel".into(), "right_wheel".into()]),
        ..options(Some(0.1))
    };
    import(&bag, &out, &named).unwrap();
    let odometry = Recording::read_dir(&out).unwrap().odometry.unwrap();
    assert!((odometry[10].right_m - 3.0 * 0.1).abs() < 1e-12);

    // Without the radius: an error when the joints are asked for, a note when the topic was
    // only found by its type.
    let asked = ImportOptions {
        wheel_joints: Some(["rear_left_wheel".into(), "right_wheel".into()]),
        ..ImportOptions::default()
    };
    let err = import(&bag, &dir.path().join("r2"), &asked)
        .unwrap_err()
        .to_string();
    assert!(
        err.ends_with("its wheel angles need --wheel-radius-m R to become wheel travel"),
        "{err}"
    );
    let named_topic = ImportOptions {
        topics: BTreeMap::from([(Role::Odometry, "/joint_states".to_string())]),
        ..ImportOptions::default()
    };
    assert!(import(&bag, &dir.path().join("r3"), &named_topic).is_err());
    let found = import(&bag, &dir.path().join("r4"), &ImportOptions::default());
    assert!(found.unwrap().notes.iter().any(|n| n.contains("skipped")));

    // Joints named that no message has.
    let absent = ImportOptions {
        wheel_joints: Some(["l".into(), "r".into()]),
        ..options(Some(0.1))
    };
    let err = import(&bag, &dir.path().join("r5"), &absent)
        .unwrap_err()
        .to_string();
    assert!(
        err.ends_with("no JointState message has positions for the joints l and r"),
        "{err}"
    );
}

fn scan(t_ns: i64, angle_min: f32, increment: f32, ranges: Vec<f32>) -> LaserScan {
    LaserScan {
        header: header(t_ns, "base_scan"),
        angle_min,
        angle_max: angle_min + increment * (ranges.len() as f32 - 1.0),
        angle_increment: increment,
        time_increment: 0.0,
        scan_time: 0.1,
        range_min: 0.12,
        range_max: 3.5,
        ranges,
        intensities: Vec::new(),
    }
}

/// A clockwise scan from +90° (negative increment, as some drivers mounted upside down send),
/// no time increment, no intensities, NaN, ±inf and out-of-range readings; a sonar's NaN and
/// inf; an Odometry of `base_footprint`; all under a robot's namespace, in a bag split into two
/// files that metadata.yaml lists, the second big-endian with `ros2idl` schemas.
#[test]
fn foreign_scans_ranges_frames_and_split_bags_import() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("bag");
    fs::create_dir(&bag).unwrap();
    let step = 1f64.to_radians() as f32;
    let ranges = |k: i64| -> Vec<f32> {
        (0..181)
            .map(|i| match i {
                0 => f32::NAN,
                1 => f32::INFINITY,
                2 => f32::NEG_INFINITY,
                3 => 0.05,
                4 => 9.0,
                _ => 1.0 + 0.001 * (i + k) as f32,
            })
            .collect()
    };
    // The second file's channels have other ids (a log topic comes first there).
    let log = Message {
        topic: "/rosout",
        type_name: "rcl_interfaces/msg/Log",
        t_ns: 500_000_000,
        data: vec![0, 1, 0, 0],
    };
    let mut files: [Vec<Message>; 2] = [Vec::new(), vec![log]];
    for k in 0..10 {
        let t_ns = k * 100_000_000;
        let scan_message = scan(t_ns, 90f64.to_radians() as f32, -step, ranges(k));
        let range = Range {
            header: header(t_ns + 10_000_000, "sonar_link"),
            radiation_type: 0,
            field_of_view: 0.5,
            min_range: 0.02,
            max_range: 4.0,
            range: [f32::NAN, f32::INFINITY, 1.5][usize::try_from(k % 3).unwrap()],
        };
        let odometry = Odometry {
            header: header(t_ns + 20_000_000, "odom"),
            child_frame_id: "base_footprint".into(),
            ..Odometry::default()
        };
        let file = &mut files[usize::from(k >= 5)];
        let bytes = |big: bool, le: Vec<u8>, be: Vec<u8>| if big { be } else { le };
        let big = k >= 5;
        file.push(Message {
            topic: "/robot1/scan",
            type_name: "sensor_msgs/msg/LaserScan",
            t_ns,
            data: bytes(big, cdr(&scan_message), cdr_big_endian(&scan_message)),
        });
        file.push(Message {
            topic: "/robot1/range",
            type_name: "sensor_msgs/msg/Range",
            t_ns: t_ns + 10_000_000,
            data: bytes(big, cdr(&range), cdr_big_endian(&range)),
        });
        let mut odometry = odometry;
        odometry.pose.pose.position = Vector3 {
            x: 0.01 * k as f64,
            y: 0.0,
            z: 0.0,
        };
        odometry.pose.pose.orientation = Quaternion::from_yaw(0.0);
        file.push(Message {
            topic: "/robot1/odom",
            type_name: "nav_msgs/msg/Odometry",
            t_ns: t_ns + 20_000_000,
            data: bytes(big, cdr(&odometry), cdr_big_endian(&odometry)),
        });
    }
    write_mcap(&bag.join("run_0.mcap"), "ros2msg", &files[0]);
    write_mcap(&bag.join("run_1.mcap"), "ros2idl", &files[1]);
    fs::write(
        bag.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  version: 8\n  storage_identifier: mcap\n  \
         relative_file_paths:\n    - run_0.mcap\n    - run_1.mcap\n",
    )
    .unwrap();
    let out = dir.path().join("rec");
    let report = import(&bag, &out, &ImportOptions::default()).unwrap();
    let rec = Recording::read_dir(&out).unwrap();
    let lidar = rec.lidar.unwrap();
    assert_eq!(lidar.len(), 10 * 181);
    for (n, r) in lidar.iter().enumerate() {
        let (k, i) = (n / 181, n % 181);
        assert_eq!(r.rev, k as u64);
        // Clockwise from 90°: 90, 89, …, 0, 359, …, 270.
        let angle = (90.0 - i as f64).rem_euclid(360.0);
        assert_eq!(r.angle_deg, angle, "{r:?}");
        // No time increment: every reading at the scan's stamp.
        assert_eq!(r.t_s, k as f64 / 10.0);
        assert_eq!(r.strength, 0);
        assert_eq!(r.invalid, i < 5, "{r:?}");
        let range = if i < 5 {
            0.0
        } else {
            f64::from(1.0 + 0.001 * (i + k) as f32)
        };
        // The float32 as the decimal it was written as.
        assert!((r.range_m - range).abs() < 1e-6, "{r:?}");
    }
    let sonar = rec.sonar.unwrap();
    // k % 3 == 2 only: NaN and inf are no echo.
    assert_eq!(sonar.len(), 3);
    assert!(sonar.iter().all(|s| s.range_m == 1.5));
    assert!(report
        .notes
        .iter()
        .any(|n| n.starts_with("7 sonar readings")));
    let odometry = rec.odometry.unwrap();
    assert_eq!(odometry.len(), 10);
    assert!((odometry[9].left_m - 0.09).abs() < 1e-9, "{odometry:?}");
    assert_eq!(report.chosen[&Role::Lidar].0, "/robot1/scan");
}

/// A simulator's bag: stamps on simulated time from 0 (the first odometry stamped exactly 0,
/// which also means "no stamp"), logged on the recorder's wall clock. Every row is on the
/// simulated clock, the first odometry at 0, not at its wall-clock log time.
#[test]
fn a_simulators_first_stamp_at_zero_is_on_the_simulated_clock() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("sim.mcap");
    let sim_header = |t_ns: i64, frame: &str| Header {
        stamp: Time::from_ns(t_ns),
        frame_id: frame.to_string(),
    };
    let mut messages = Vec::new();
    for k in 0..10 {
        let t_ns = k * 50_000_000;
        let mut odometry = Odometry {
            header: sim_header(t_ns, "odom"),
            child_frame_id: "base_link".into(),
            ..Odometry::default()
        };
        odometry.pose.pose.position.x = 0.01 * k as f64;
        messages.push(Message {
            topic: "/odom",
            type_name: "nav_msgs/msg/Odometry",
            t_ns,
            data: cdr(&odometry),
        });
        let mut scan_message = scan(0, 0.0, 1f64.to_radians() as f32, vec![1.0; 360]);
        scan_message.header = sim_header(t_ns + 10_000_000, "laser");
        messages.push(Message {
            topic: "/scan",
            type_name: "sensor_msgs/msg/LaserScan",
            t_ns: t_ns + 10_000_000,
            data: cdr(&scan_message),
        });
    }
    write_mcap(&bag, "ros2msg", &messages);
    let out = dir.path().join("rec");
    let report = import(&bag, &out, &ImportOptions::default()).unwrap();
    let rec = Recording::read_dir(&out).unwrap();
    let times: Vec<f64> = rec.odometry.unwrap().iter().map(|o| o.t_s).collect();
    // t = 0 is the earliest non-zero stamp, the first scan's (0.01 s): the odometry stamped
    // 0 comes before it and is put at 0, said so.
    assert_eq!(
        times[1..],
        [0.04, 0.09, 0.14, 0.19, 0.24, 0.29, 0.34, 0.39, 0.44]
    );
    assert_eq!(times[0], 0.0);
    assert_eq!(rec.lidar.unwrap()[0].t_s, 0.0);
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.starts_with("1 odometry rows came before")),
        "{:?}",
        report.notes
    );
}

/// A driver that leaves `range_min` 0 and sends 0 for no echo: a range of 0 is no reading.
#[test]
fn a_range_of_zero_is_no_echo() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("zero.mcap");
    let mut scan_message = scan(0, 0.0, 1f64.to_radians() as f32, vec![0.0, 1.25, 0.0]);
    scan_message.range_min = 0.0;
    let range = Range {
        header: header(0, "sonar"),
        max_range: 4.0,
        range: 0.0,
        ..Range::default()
    };
    let messages = [
        Message {
            topic: "/scan",
            type_name: "sensor_msgs/msg/LaserScan",
            t_ns: 0,
            data: cdr(&scan_message),
        },
        Message {
            topic: "/sonar",
            type_name: "sensor_msgs/msg/Range",
            t_ns: 0,
            data: cdr(&range),
        },
    ];
    write_mcap(&bag, "ros2msg", &messages);
    let out = dir.path().join("rec");
    import(&bag, &out, &ImportOptions::default()).unwrap();
    let rec = Recording::read_dir(&out).unwrap();
    let invalid: Vec<bool> = rec.lidar.unwrap().iter().map(|r| r.invalid).collect();
    assert_eq!(invalid, [true, false, true]);
    assert!(rec.sonar.unwrap().is_empty());
}

/// rosbag2's own compression modes: a whole file as one zstd stream (`name.mcap.zstd`), and each
/// message's bytes compressed apart; a cut-off compressed file is a one-line error.
#[test]
fn rosbag2_file_and_message_compression_read() {
    let dir = tempfile::tempdir().unwrap();
    let scans = |compress: bool| -> Vec<Message> {
        (0..3)
            .map(|k| {
                let message = scan(
                    k * 100_000_000,
                    0.0,
                    0.5f64.to_radians() as f32,
                    vec![1.5; 720],
                );
                let data = cdr(&message);
                Message {
                    topic: "/scan",
                    type_name: "sensor_msgs/msg/LaserScan",
                    t_ns: k * 100_000_000,
                    data: if compress {
                        zstd::encode_all(&data[..], 3).unwrap()
                    } else {
                        data
                    },
                }
            })
            .collect()
    };
    let plain = dir.path().join("plain.mcap");
    write_mcap(&plain, "ros2msg", &scans(false));
    let whole = dir.path().join("run.mcap.zstd");
    fs::write(
        &whole,
        zstd::encode_all(&fs::read(&plain).unwrap()[..], 3).unwrap(),
    )
    .unwrap();
    let each = dir.path().join("each.mcap");
    write_mcap(&each, "ros2msg", &scans(true));
    let expected = {
        import(&plain, &dir.path().join("p"), &ImportOptions::default()).unwrap();
        fs::read(dir.path().join("p/lidar.csv")).unwrap()
    };
    assert_eq!(
        expected.iter().filter(|&&b| b == b'\n').count(),
        1 + 3 * 720
    );
    for (bag, name) in [(&whole, "w"), (&each, "e")] {
        import(bag, &dir.path().join(name), &ImportOptions::default()).unwrap();
        let csv = fs::read(dir.path().join(name).join("lidar.csv")).unwrap();
        assert!(csv == expected, "{name}");
    }
    let cut = dir.path().join("cut.mcap.zstd");
    let bytes = fs::read(&whole).unwrap();
    fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let err = import(&cut, &dir.path().join("c"), &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with(&format!("{}: ", cut.display())) && !err.contains('\n'),
        "{err}"
    );
}

/// rosbag2's SQLite3 storage (`.db3`, the default before Iron): its `topics` and `messages`
/// tables, read as an MCAP file's channels and messages; another SQLite database is a one-line
/// error.
#[test]
fn a_sqlite3_bag_reads_as_its_mcap_twin() {
    let dir = tempfile::tempdir().unwrap();
    let messages: Vec<Message> = (0..3)
        .map(|k| Message {
            topic: "/scan",
            type_name: "sensor_msgs/msg/LaserScan",
            t_ns: k * 100_000_000,
            data: cdr(&scan(
                k * 100_000_000,
                0.0,
                1f64.to_radians() as f32,
                vec![2.5; 360],
            )),
        })
        .collect();
    let mcap = dir.path().join("twin.mcap");
    write_mcap(&mcap, "ros2msg", &messages);
    let bag = dir.path().join("bag");
    fs::create_dir(&bag).unwrap();
    let db = rusqlite::Connection::open(bag.join("bag_0.db3")).unwrap();
    db.execute_batch(
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, \
         serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL); \
         CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, \
         timestamp INTEGER NOT NULL, data BLOB NOT NULL); \
         CREATE INDEX timestamp_idx ON messages (timestamp ASC); \
         INSERT INTO topics VALUES (1, '/scan', 'sensor_msgs/msg/LaserScan', 'cdr', '');",
    )
    .unwrap();
    // Inserted out of time order: read in time order.
    for m in messages.iter().rev() {
        db.execute(
            "INSERT INTO messages (topic_id, timestamp, data) VALUES (1, ?1, ?2)",
            rusqlite::params![T0_NS + m.t_ns, m.data],
        )
        .unwrap();
    }
    drop(db);
    fs::write(
        bag.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  relative_file_paths:\n  \
         - bag_0.db3\n",
    )
    .unwrap();
    import(&mcap, &dir.path().join("m"), &ImportOptions::default()).unwrap();
    import(&bag, &dir.path().join("s"), &ImportOptions::default()).unwrap();
    let csv = |name: &str| fs::read(dir.path().join(name).join("lidar.csv")).unwrap();
    assert_eq!(csv("m").len(), csv("s").len());
    assert!(csv("m") == csv("s"));

    let other = dir.path().join("other.db3");
    rusqlite::Connection::open(&other)
        .unwrap()
        .execute_batch("CREATE TABLE t(x); INSERT INTO t VALUES (1);")
        .unwrap();
    let err = import(&other, &dir.path().join("o"), &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with(&format!(
            "{}: not a readable SQLite3 bag (",
            other.display()
        )) && !err.contains('\n'),
        "{err}"
    );
}

/// Drivers that send NaN for "unknown": an Odometry, a truth pose and a command with a NaN are
/// skipped and counted, not written (a recording's numbers are finite), and the rest imports.
#[test]
fn messages_with_nan_are_skipped_and_counted() {
    use hilsim_ros2::msgs::{PoseStamped, Twist, TwistStamped};
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("nan.mcap");
    let mut messages = Vec::new();
    for k in 0..4 {
        let t_ns = k * 100_000_000;
        let bad = if k == 2 { f64::NAN } else { 0.0 };
        let mut odometry = Odometry {
            header: header(t_ns, "odom"),
            ..Odometry::default()
        };
        odometry.pose.pose.position.x = 0.1 * k as f64 + bad;
        let mut pose = PoseStamped {
            header: header(t_ns, "map"),
            ..PoseStamped::default()
        };
        pose.pose.position.y = bad;
        let mut twist = TwistStamped {
            header: header(t_ns, "base_link"),
            twist: Twist::default(),
        };
        twist.twist.angular.z = bad;
        messages.push(Message {
            topic: "/odom",
            type_name: "nav_msgs/msg/Odometry",
            t_ns,
            data: cdr(&odometry),
        });
        messages.push(Message {
            topic: "/pose",
            type_name: "geometry_msgs/msg/PoseStamped",
            t_ns,
            data: cdr(&pose),
        });
        messages.push(Message {
            topic: "/cmd",
            type_name: "geometry_msgs/msg/TwistStamped",
            t_ns,
            data: cdr(&twist),
        });
    }
    write_mcap(&bag, "ros2msg", &messages);
    let out = dir.path().join("rec");
    let report = import(&bag, &out, &ImportOptions::default()).unwrap();
    let rec = Recording::read_dir(&out).unwrap();
    assert_eq!(rec.odometry.unwrap().len(), 3);
    assert_eq!(rec.truth.unwrap().len(), 3);
    assert_eq!(rec.commands.len(), 3);
    for role in ["odometry", "commands", "truth"] {
        let note = format!("1 {role} messages with a value that is not finite (NaN, inf) skipped");
        assert!(report.notes.contains(&note), "{note}: {:?}", report.notes);
    }
}

fn transform(t_ns: i64, parent: &str, child: &str, x: f64, yaw: f64) -> TransformStamped {
    TransformStamped {
        header: header(t_ns, parent),
        child_frame_id: child.to_string(),
        transform: Transform {
            translation: Vector3 { x, y: 0.0, z: 0.3 },
            rotation: Quaternion::from_yaw(yaw),
        },
    }
}

fn tf_message(topic: &'static str, t_ns: i64, transforms: Vec<TransformStamped>) -> Message {
    Message {
        topic,
        type_name: "tf2_msgs/msg/TFMessage",
        t_ns,
        data: cdr(&TfMessage { transforms }),
    }
}

/// A ROS 2 robot's TF: the laser's mount from /tf_static (over base_link → laser_mount →
/// laser, from the odometry's base_footprint) into meta.toml, unless the user's meta.toml has
/// one; without /odom, the odometry from /tf's odom → base_footprint.
#[test]
fn the_lidar_mount_and_odometry_come_from_tf() {
    let dir = tempfile::tempdir().unwrap();
    let statics = tf_message(
        "/tf_static",
        0,
        vec![
            transform(0, "base_footprint", "base_link", 0.0, 0.0),
            transform(
                0,
                "base_link",
                "laser_mount",
                0.2,
                -std::f64::consts::FRAC_PI_2,
            ),
            transform(0, "laser_mount", "laser", 0.05, 0.0),
        ],
    );
    let mut messages = vec![statics];
    for k in 0..5 {
        let t_ns = i64::from(k) * 100_000_000;
        let mut laser = scan(t_ns, 0.0, 0.5f32.to_radians(), vec![1.0; 4]);
        laser.header.frame_id = "laser".into();
        messages.push(Message {
            topic: "/scan",
            type_name: "sensor_msgs/msg/LaserScan",
            t_ns,
            data: cdr(&laser),
        });
        messages.push(tf_message(
            "/tf",
            t_ns,
            vec![transform(
                t_ns,
                "odom",
                "base_footprint",
                0.1 * f64::from(k),
                0.0,
            )],
        ));
    }
    let bag = dir.path().join("tf.mcap");
    write_mcap(&bag, "ros2msg", &messages);
    let out = dir.path().join("rec");
    let report = import(&bag, &out, &ImportOptions::default()).unwrap();
    let rec = Recording::read_dir(&out).unwrap();
    let mount = rec.meta.lidar.unwrap();
    assert_eq!((mount.x_m, mount.y_m, mount.yaw_deg), (0.2, -0.05, -90.0));
    assert!(report
        .notes
        .iter()
        .any(|n| n
            == "lidar mount from /tf_static base_footprint→laser: x 0.2 m, y -0.05 m, yaw -90°"));
    let odometry = rec.odometry.unwrap();
    assert_eq!(odometry.len(), 5);
    assert!((odometry[4].left_m - 0.4).abs() < 1e-9);

    // The user's meta.toml's mount stands.
    let meta = hilsim_recording::Meta {
        lidar: Some(hilsim_recording::Mount {
            x_m: 0.3,
            y_m: 0.0,
            yaw_deg: 0.0,
        }),
        ..hilsim_recording::Meta::default()
    };
    let given = ImportOptions {
        meta: Some(meta),
        ..ImportOptions::default()
    };
    let report = import(&bag, &out, &given).unwrap();
    assert_eq!(
        Recording::read_dir(&out).unwrap().meta.lidar.unwrap().x_m,
        0.3
    );
    assert!(!report.notes.iter().any(|n| n.contains("lidar mount")));
}
