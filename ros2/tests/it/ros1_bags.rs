//! ROS 1 bags (rosbag format 2.0), written here record by record as `rosbag record` lays them
//! out: chunks uncompressed, bz2 and lz4, connections in the chunks and again in the index,
//! messages in ROS 1's serialisation. Each is imported through the same converter as a ROS 2
//! bag; damage is counted in notes, never a panic.

use std::fs;
use std::io::Write;
use std::path::Path;

use hilsim_recording::Recording;
use hilsim_ros2::{import, ImportOptions, ImportReport, Role};
use proptest::prelude::*;

/// The bag's clock starts at 1,700,000,000 s, as a robot's wall clock.
const T0_S: u32 = 1_700_000_000;

/// A ROS 1 message's bytes, field by field.
#[derive(Default, Clone)]
struct Ros1(Vec<u8>);

impl Ros1 {
    fn u32(mut self, v: u32) -> Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn f32s(mut self, v: &[f32]) -> Self {
        self.0.extend(v.iter().flat_map(|x| x.to_le_bytes()));
        self
    }
    fn f64s(mut self, v: &[f64]) -> Self {
        self.0.extend(v.iter().flat_map(|x| x.to_le_bytes()));
        self
    }
    fn string(self, s: &str) -> Self {
        let mut out = self.u32(s.len() as u32);
        out.0.extend_from_slice(s.as_bytes());
        out
    }
    /// `std_msgs/Header`: seq, stamp, frame.
    fn header(self, t_ms: u32, frame: &str) -> Self {
        self.u32(7)
            .u32(T0_S + t_ms / 1000)
            .u32((t_ms % 1000) * 1_000_000)
            .string(frame)
    }
}

fn yaw_quaternion(yaw: f64) -> [f64; 4] {
    [0.0, 0.0, (0.5 * yaw).sin(), (0.5 * yaw).cos()]
}

/// A LaserScan of four readings a quarter-turn apart from -90°, 0.1 ms apart.
fn scan(t_ms: u32, ranges: [f32; 4]) -> Vec<u8> {
    let q = std::f32::consts::FRAC_PI_2;
    Ros1::default()
        .header(t_ms, "laser")
        .f32s(&[-q, q * 2.0, q, 1e-4, 0.1, 0.12, 8.0])
        .u32(4)
        .f32s(&ranges)
        .u32(0)
        .0
}

fn odometry(t_ms: u32, x: f64, yaw: f64) -> Vec<u8> {
    let mut pose = vec![x, 0.0, 0.0];
    pose.extend(yaw_quaternion(yaw));
    Ros1::default()
        .header(t_ms, "odom")
        .string("base_link")
        .f64s(&pose)
        .f64s(&[0.0; 36])
        .f64s(&[0.0; 6])
        .f64s(&[0.0; 36])
        .0
}

/// A TFMessage of (parent, child, x, y, yaw) transforms.
fn tf(t_ms: u32, transforms: &[(&str, &str, f64, f64, f64)]) -> Vec<u8> {
    let mut m = Ros1::default().u32(transforms.len() as u32);
    for (parent, child, x, y, yaw) in transforms {
        let mut pose = vec![*x, *y, 0.2];
        pose.extend(yaw_quaternion(*yaw));
        m = m.header(t_ms, parent).string(child).f64s(&pose);
    }
    m.0
}

/// A record: its header fields and its data.
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

fn connection(id: u32, topic: &str, type_name: &str) -> Vec<u8> {
    let mut data = Vec::new();
    for field in [
        format!("topic={topic}"),
        format!("type={type_name}"),
        "md5sum=*".to_string(),
        "message_definition=# not read".to_string(),
    ] {
        data.extend((field.len() as u32).to_le_bytes());
        data.extend(field.as_bytes());
    }
    record(
        &[
            ("op", &[0x07]),
            ("conn", &id.to_le_bytes()),
            ("topic", topic.as_bytes()),
        ],
        &data,
    )
}

fn message(conn: u32, t_ms: u32, data: &[u8]) -> Vec<u8> {
    let time = (u64::from((t_ms % 1000) * 1_000_000) << 32) | u64::from(T0_S + t_ms / 1000);
    record(
        &[
            ("op", &[0x02]),
            ("conn", &conn.to_le_bytes()),
            ("time", &time.to_le_bytes()),
        ],
        data,
    )
}

/// A chunk of `records`, compressed as named (`none`, `bz2`, `lz4`).
fn chunk(compression: &str, records: &[u8]) -> Vec<u8> {
    let data = match compression {
        "bz2" => {
            let mut e = bzip2::write::BzEncoder::new(Vec::new(), bzip2::Compression::best());
            e.write_all(records).unwrap();
            e.finish().unwrap()
        }
        "lz4" => {
            let mut e = lz4::EncoderBuilder::new().build(Vec::new()).unwrap();
            e.write_all(records).unwrap();
            let (out, result) = e.finish();
            result.unwrap();
            out
        }
        _ => records.to_vec(),
    };
    record(
        &[
            ("op", &[0x05]),
            ("compression", compression.as_bytes()),
            ("size", &(records.len() as u32).to_le_bytes()),
        ],
        &data,
    )
}

/// A whole bag: the magic, the bag header (pointing at the index when `indexed`), the chunks,
/// then the index's connection records.
fn bag(chunks: &[Vec<u8>], connections: &[Vec<u8>], indexed: bool) -> Vec<u8> {
    let mut body: Vec<u8> = chunks.concat();
    let header_len = record(
        &[
            ("op", &[0x03]),
            ("index_pos", &0u64.to_le_bytes()),
            ("conn_count", &0u32.to_le_bytes()),
            ("chunk_count", &0u32.to_le_bytes()),
        ],
        &[b' '; 64],
    )
    .len();
    let magic = b"#ROSBAG V2.0\n";
    let index_pos = if indexed {
        (magic.len() + header_len + body.len()) as u64
    } else {
        0
    };
    let mut out = magic.to_vec();
    out.extend(record(
        &[
            ("op", &[0x03]),
            ("index_pos", &index_pos.to_le_bytes()),
            ("conn_count", &(connections.len() as u32).to_le_bytes()),
            ("chunk_count", &(chunks.len() as u32).to_le_bytes()),
        ],
        &[b' '; 64],
    ));
    out.append(&mut body);
    if indexed {
        out.extend(connections.concat());
    }
    out
}

/// A robot's bag: /scan, /odom and /tf_static (base_link → plate → laser, the laser turned
/// round), in three chunks: uncompressed, bz2, lz4.
fn robot_bag(compressions: [&str; 3], indexed: bool) -> Vec<u8> {
    let conns = [
        connection(0, "/scan", "sensor_msgs/LaserScan"),
        connection(1, "/odom", "nav_msgs/Odometry"),
        connection(2, "/tf_static", "tf2_msgs/TFMessage"),
    ];
    let mut chunks = Vec::new();
    for (c, compression) in compressions.iter().enumerate() {
        let mut records = Vec::new();
        if c == 0 {
            records.extend(conns.concat());
            records.extend(message(
                2,
                0,
                &tf(
                    0,
                    &[
                        ("/base_link", "plate", 0.1, 0.0, 0.0),
                        ("plate", "laser", 0.02, 0.0, std::f64::consts::PI),
                    ],
                ),
            ));
        }
        for k in 0..2u32 {
            let t_ms = (c as u32 * 2 + k) * 100;
            let r = t_ms as f32 / 1000.0;
            records.extend(message(
                0,
                t_ms + 5,
                &scan(t_ms, [1.0 + r, f32::NAN, 0.05, 2.5]),
            ));
            records.extend(message(
                1,
                t_ms + 1,
                &odometry(t_ms, 0.01 * f64::from(t_ms / 100), 0.0),
            ));
        }
        chunks.push(chunk(compression, &records));
    }
    bag(&chunks, &conns, indexed)
}

fn imported(dir: &Path, name: &str, bytes: &[u8]) -> (ImportReport, Recording) {
    let path = dir.join(name);
    fs::write(&path, bytes).unwrap();
    let out = dir.join(format!("{name}.rec"));
    let report = import(&path, &out, &ImportOptions::default()).unwrap();
    (report, Recording::read_dir(&out).unwrap())
}

#[test]
fn a_ros1_bag_imports_scans_odometry_and_the_tf_static_mount() {
    let dir = tempfile::tempdir().unwrap();
    for (name, compressions) in [
        ("plain.bag", ["none"; 3]),
        ("mixed.bag", ["none", "bz2", "lz4"]),
    ] {
        let (report, rec) = imported(dir.path(), name, &robot_bag(compressions, true));
        assert_eq!(report.chosen[&Role::Lidar].0, "/scan");
        assert_eq!(report.rows[&Role::Lidar], 24, "{name}");
        let lidar = rec.lidar.as_deref().unwrap();
        // Reading i at -90° + i·90°, at the stamp + i·0.1 ms; NaN and below range_min invalid.
        let rows: Vec<_> = lidar[..4]
            .iter()
            .map(|r| (r.t_s, r.angle_deg, r.range_m, r.invalid))
            .collect();
        assert_eq!(
            rows,
            [
                (0.0, 270.0, 1.0, false),
                (0.0001, 0.0, 0.0, true),
                (0.0002, 90.0, 0.0, true),
                (0.0003, 180.0, 2.5, false)
            ],
            "{name}"
        );
        // The last scan, of the lz4 chunk: stamped 0.5 s.
        assert_eq!(
            (lidar[20].t_s, lidar[20].range_m, lidar[20].rev),
            (0.5, 1.5, 5)
        );
        let odometry = rec.odometry.as_deref().unwrap();
        assert_eq!(odometry.len(), 6);
        // Straight ahead 1 cm a message: each wheel travels what the robot does.
        assert_eq!(
            (odometry[5].t_s, odometry[5].left_m, odometry[5].right_m),
            (0.5, 0.05, 0.05)
        );
        let mount = rec.meta.lidar.unwrap();
        assert_eq!((mount.x_m, mount.y_m, mount.yaw_deg), (0.12, 0.0, 180.0));
        assert!(
            report
                .notes
                .iter()
                .any(|n| n
                    == "lidar mount from /tf_static base_link→laser: x 0.12 m, y 0 m, yaw 180°"),
            "{:?}",
            report.notes
        );
    }
}

/// An unindexed bag (a recording not closed) is read whole for its connections; without an
/// odometry topic the odometry is TF's odom → base_footprint, and the mount is composed from
/// that frame.
#[test]
fn odometry_comes_from_tf_when_the_bag_has_no_odom_topic() {
    let conns = [
        connection(4, "/scan", "sensor_msgs/LaserScan"),
        connection(5, "/tf", "tf/tfMessage"),
        connection(6, "/tf_static", "tf2_msgs/TFMessage"),
    ];
    let mut records = conns.concat();
    records.extend(message(
        6,
        0,
        &tf(
            0,
            &[
                ("base_footprint", "base_link", 0.0, 0.0, 0.0),
                (
                    "base_link",
                    "laser",
                    0.1,
                    -0.05,
                    std::f64::consts::FRAC_PI_2,
                ),
            ],
        ),
    ));
    for k in 0..4u32 {
        let t_ms = k * 100;
        records.extend(message(4, t_ms, &scan(t_ms, [1.0; 4])));
        records.extend(message(
            5,
            t_ms,
            &tf(
                t_ms,
                &[("odom", "base_footprint", 0.0, 0.0, 0.1 * f64::from(k))],
            ),
        ));
    }
    let bytes = bag(&[chunk("bz2", &records)], &[], false);
    let dir = tempfile::tempdir().unwrap();
    let (report, rec) = imported(dir.path(), "tf.bag", &bytes);
    assert_eq!(report.chosen[&Role::Odometry].0, "/tf");
    let odometry = rec.odometry.as_deref().unwrap();
    assert_eq!(odometry.len(), 4);
    // Turning in place 0.1 rad a step: the wheels, 0.23 m apart (the default), travel ∓0.0115 m.
    assert!((odometry[3].right_m - 0.3 * 0.23 / 2.0).abs() < 1e-9);
    assert!((odometry[3].left_m + odometry[3].right_m).abs() < 1e-9);
    let mount = rec.meta.lidar.unwrap();
    assert_eq!((mount.x_m, mount.y_m, mount.yaw_deg), (0.1, -0.05, 90.0));
    let notes = report.notes.join("\n");
    assert!(
        notes.contains("no Odometry topic: the odometry from /tf's odom → base"),
        "{notes}"
    );
    assert!(
        notes.contains("lidar mount from /tf_static base_footprint→laser"),
        "{notes}"
    );
    assert!(
        notes.contains("no --meta: a minimal meta.toml (wheel base 0.23 m, a guess"),
        "{notes}"
    );
}

/// A chunk whose bz2 does not decompress, a message of another layout and a file cut short are
/// counted and said; the rest imports.
#[test]
fn damage_is_counted_in_notes_not_refused() {
    let mut bytes = robot_bag(["none", "bz2", "none"], false);
    // The bz2 chunk's compressed bytes start after the first chunk; spoil them.
    let first_chunk = chunk("none", &[]).len();
    let at = bytes
        .windows(3)
        .position(|w| w == b"BZh")
        .unwrap_or(first_chunk);
    bytes[at + 10] ^= 0xff;
    bytes[at + 11] ^= 0xff;
    // A scan one byte short, appended in an uncompressed chunk, and then half a record.
    let mut short = scan(900, [1.0; 4]);
    short.pop();
    bytes.extend(chunk("none", &message(0, 900, &short)));
    bytes.extend(&chunk("none", &message(0, 950, &scan(950, [1.0; 4])))[..30]);
    let dir = tempfile::tempdir().unwrap();
    let (report, rec) = imported(dir.path(), "damaged.bag", &bytes);
    let notes = report.notes.join("\n");
    assert!(
        notes.contains("1 chunks of the bag skipped, damaged"),
        "{notes}"
    );
    assert!(
        notes.contains("1 of /scan's 5 messages skipped: not a sensor_msgs/msg/LaserScan"),
        "{notes}"
    );
    assert!(notes.contains("the bag was read up to byte"), "{notes}");
    assert_eq!(rec.lidar.unwrap().len(), 16);
}

#[test]
fn a_file_that_is_not_a_bag_is_one_line_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes, expected) in [
        (
            "old.bag",
            &b"#ROSBAG V1.2\nxxxx"[..],
            "a ROS 1 bag of format 1.2, not 2.0",
        ),
        ("text.bag", &b"hello"[..], "not an MCAP file"),
    ] {
        let path = dir.path().join(name);
        fs::write(&path, bytes).unwrap();
        let err = import(&path, &dir.path().join("out"), &ImportOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.starts_with(&path.display().to_string()), "{err}");
        assert!(err.contains(expected), "{err}");
        assert!(!err.contains('\n'), "{err}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Bytes after the magic, or a good bag with bytes changed or cut, import or fail in one
    /// line: never a panic.
    #[test]
    fn arbitrary_bytes_never_panic_the_ros1_reader(
        tail in proptest::collection::vec(any::<u8>(), 0..512),
        flips in proptest::collection::vec((any::<usize>(), any::<u8>()), 0..8),
        cut in any::<usize>(),
    ) {
        let dir = tempfile::tempdir().unwrap();
        let mut noise = b"#ROSBAG V2.0\n".to_vec();
        noise.extend(&tail);
        let mut good = robot_bag(["none", "bz2", "lz4"], true);
        for (at, x) in flips {
            let n = good.len();
            good[at % n] ^= x;
        }
        good.truncate(cut % (good.len() + 1));
        for (name, bytes) in [("noise.bag", noise), ("flipped.bag", good)] {
            let path = dir.path().join(name);
            fs::write(&path, &bytes).unwrap();
            if let Err(err) = import(&path, &dir.path().join("out"), &ImportOptions::default()) {
                prop_assert!(!err.to_string().contains('\n'));
            }
        }
    }
}
