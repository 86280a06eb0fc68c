"""Third-party ROS libraries against `hilsim import` and `hilsim export`.

    rosbags_check.py write BAGDIR [VARIANT]  write a ROS 2 bag with rosbags (MCAP storage;
                                             VARIANT: rosbag2 compression, file or message,
                                             or sqlite3 storage)
    rosbags_check.py write-ros1 BAG C        the same messages as a ROS 1 bag (rosbags.rosbag1;
                                             chunks compressed with C: none, bz2, lz4)
    rosbags_check.py rewrite BAGDIR OUT C    the same messages through the mcap library's
                                             writer, chunks compressed with C (zstd, lz4)
    rosbags_check.py imported BAGDIR RECDIR  check hilsim's import of that bag
    rosbags_check.py exported MCAP RECDIR    read hilsim's export with rosbags and mcap-ros2
                                             (messages, and the TF tree: connected, base_link at
                                             the truth)
    rosbags_check.py write-foreign BAGDIR    a split bag of another robot's ways (see below)
    rosbags_check.py foreign-imported REC JOINTS_REC   check its imports (Odometry, JointState)
    rosbags_check.py resave MCAP BAGDIR      hilsim's export re-serialized by rosbags (SQLite3,
                                             big-endian, namespaced)
    rosbags_check.py same-calibration A B    two `calibrate --json` outputs agree

Each check compares message contents with the recording's CSV files and exits non-zero with a
line saying what differs.
"""

import bisect
import csv
import math
import sys
import tomllib
from pathlib import Path

import numpy as np
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

# The bag: a lidar of 720 readings 0.5 degrees apart at 10 Hz, odometry at 20 Hz, unstamped
# Twist commands at 5 Hz and a sonar at 10 Hz, for 3 s, stamped from a clock that starts at
# 1,700,000,000 s (wall time, as a real robot's).
T0_NS = 1_700_000_000 * 10**9
SCANS = 30
READINGS = 720
WHEEL_BASE = 0.3
RANGE_MIN, RANGE_MAX = 0.1, 12.0
ODOM_AFTER_NS = 20_000_000


def scan_ranges(k):
    """Ranges of scan k: a smooth room with NaN, +inf, below-minimum and above-maximum holes."""
    out = []
    for i in range(READINGS):
        r = 2.0 + math.sin(math.radians(0.5 * i) * 3 + 0.1 * k)
        if i % 97 == 0:
            r = float("nan")
        elif i % 89 == 0:
            r = float("inf")
        elif i % 83 == 0:
            r = 0.05
        elif i % 79 == 0:
            r = 20.0
        out.append(r)
    return np.array(out, dtype=np.float32)


def odom_pose(j):
    """The robot's pose at odometry message j: driving a gentle left arc."""
    t = 0.05 * j
    yaw = 0.4 * t
    return 0.2 * t * math.cos(0.2 * t), 0.2 * t * math.sin(0.2 * t), yaw


# The lidar's mount the bag's /tf_static says: base_link -> laser_mount -> laser, the laser
# 0.12 m ahead and 0.03 m to the left of the robot's centre, turned round (180 degrees).
MOUNT = (0.12, 0.03, 180.0)


def events(store):
    """The bag's messages, in log-time order: (log ns, topic, message, type), for a ROS 2 or a
    ROS 1 typestore (whose Header has a `seq`)."""
    t = store.types
    Time = t["builtin_interfaces/msg/Time"]
    Header = t["std_msgs/msg/Header"]
    ros1 = "seq" in Header.__dataclass_fields__

    def header(ns, frame):
        stamp = Time(sec=ns // 10**9, nanosec=ns % 10**9)
        if ros1:
            return Header(seq=0, stamp=stamp, frame_id=frame)
        return Header(stamp=stamp, frame_id=frame)

    Vector3 = t["geometry_msgs/msg/Vector3"]
    Point = t["geometry_msgs/msg/Point"]
    Quaternion = t["geometry_msgs/msg/Quaternion"]
    Pose = t["geometry_msgs/msg/Pose"]
    Twist = t["geometry_msgs/msg/Twist"]
    cov = np.zeros(36, dtype=np.float64)

    def yaw_quaternion(yaw):
        return Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))

    def transform(parent, child, x, y, yaw_deg):
        return t["geometry_msgs/msg/TransformStamped"](
            header=header(T0_NS, parent),
            child_frame_id=child,
            transform=t["geometry_msgs/msg/Transform"](
                translation=Vector3(x=x, y=y, z=0.1),
                rotation=yaw_quaternion(math.radians(yaw_deg)),
            ),
        )

    x, y, yaw = MOUNT
    # laser_mount at (x - 0.01, y) facing left; the laser 0.01 m to its right, turned a further
    # 90 degrees: composed, the mount above.
    tf_static = t["tf2_msgs/msg/TFMessage"](
        transforms=[
            transform("base_link", "laser_mount", x - 0.01, y, 90.0),
            transform("laser_mount", "laser", 0.0, -0.01, yaw - 90.0),
        ]
    )
    out = [(T0_NS - 1_000_000, "/tf_static", tf_static, "tf2_msgs/msg/TFMessage")]
    for k in range(SCANS):
        ns = T0_NS + k * 100_000_000
        msg = t["sensor_msgs/msg/LaserScan"](
            header=header(ns, "laser"),
            angle_min=0.0,
            angle_max=math.radians(359.5),
            angle_increment=math.radians(0.5),
            time_increment=0.1 / READINGS,
            scan_time=0.1,
            range_min=RANGE_MIN,
            range_max=RANGE_MAX,
            ranges=scan_ranges(k),
            intensities=np.full(READINGS, 100.0 + k, dtype=np.float32),
        )
        # Logged when the revolution ends, after the odometry stamped later: t = 0 is
        # still the first scan's stamp.
        out.append((ns + 100_000_000, "/scan", msg, "sensor_msgs/msg/LaserScan"))
        sonar = t["sensor_msgs/msg/Range"](
            header=header(ns + 5_000_000, "sonar"),
            radiation_type=0,
            field_of_view=math.radians(30.0),
            min_range=0.02,
            max_range=4.0,
            range=float("inf") if k == 3 else 1.0 + 0.01 * k,
        )
        out.append((ns + 5_000_000, "/range", sonar, "sensor_msgs/msg/Range"))
    for j in range(2 * SCANS):
        ns = T0_NS + ODOM_AFTER_NS + j * 50_000_000
        x, y, yaw = odom_pose(j)
        odom = t["nav_msgs/msg/Odometry"](
            header=header(ns, "odom"),
            child_frame_id="base_link",
            pose=t["geometry_msgs/msg/PoseWithCovariance"](
                pose=Pose(position=Point(x=x, y=y, z=0.0), orientation=yaw_quaternion(yaw)),
                covariance=cov,
            ),
            twist=t["geometry_msgs/msg/TwistWithCovariance"](
                twist=Twist(linear=Vector3(x=0.2, y=0.0, z=0.0), angular=Vector3(x=0.0, y=0.0, z=0.4)),
                covariance=cov,
            ),
        )
        out.append((ns, "/odom", odom, "nav_msgs/msg/Odometry"))
    for c in range(SCANS // 2):
        # Unstamped: the recorder's log time is its time (on the stamps' clock here).
        ns = T0_NS + c * 200_000_000 + 1_000_000
        twist = Twist(linear=Vector3(x=0.2, y=0.0, z=0.0), angular=Vector3(x=0.0, y=0.0, z=0.4 + 0.01 * c))
        out.append((ns, "/cmd_vel", twist, "geometry_msgs/msg/Twist"))
    return sorted(out, key=lambda e: e[0])


def write(bagdir, variant="none"):
    """`variant`: rosbag2's compression mode, `none`, `file` (each file one zstd stream) or
    `message`; or `sqlite3`, rosbag2's other storage (rosbags' default), uncompressed."""
    from rosbags.rosbag2.writer import CompressionFormat, CompressionMode

    store = get_typestore(Stores.ROS2_HUMBLE)
    storage = StoragePlugin.SQLITE3 if variant == "sqlite3" else StoragePlugin.MCAP
    writer = Writer(bagdir, version=8, storage_plugin=storage)
    if variant in ("file", "message"):
        writer.set_compression(CompressionMode[variant.upper()], CompressionFormat.ZSTD)
    with writer:
        connections = {}
        for ns, topic, msg, kind in events(store):
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, kind, typestore=store)
            writer.write(connections[topic], ns, store.serialize_cdr(msg, kind))


def write_ros1(path, compression):
    """The same messages as a ROS 1 bag, rosbags' rosbag1 writer, chunks of 64 kB (several)
    compressed with `compression` (none, bz2, lz4)."""
    from rosbags.rosbag1 import Writer as Ros1Writer

    from rosbags.typesys import get_types_from_msg

    store = get_typestore(Stores.ROS1_NOETIC)
    # Noetic's store lacks tf2_msgs: its one message, as tf2_msgs/msg/TFMessage.msg has it.
    store.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"))
    writer = Ros1Writer(path)
    if compression != "none":
        writer.set_compression(Ros1Writer.CompressionFormat[compression.upper()])
    writer.chunk_threshold = 64 * 1024
    with writer:
        connections = {}
        for ns, topic, msg, kind in events(store):
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, kind, typestore=store)
            writer.write(connections[topic], ns, store.serialize_ros1(msg, kind))


# The foreign bag: a robot under a namespace, its lidar mounted upside down (clockwise from
# +90 degrees: a negative increment), no time increment and no intensities; a sonar that
# reports NaN and inf; Odometry of base_footprint; wheel joints with an arm's joints published
# in messages of their own. Split in two files, the second big-endian CDR with ros2idl schemas.
FOREIGN_SCANS = 10
FOREIGN_READINGS = 181
WHEEL_RADIUS = 0.033


def foreign_ranges(k):
    out = [1.0 + 0.001 * (i + k) for i in range(FOREIGN_READINGS)]
    out[0:5] = [float("nan"), float("inf"), float("-inf"), 0.05, 9.0]
    return np.array(out, dtype=np.float32)


def wheel_angles(k):
    return 0.5 + 0.1 * k, -0.25 + 0.3 * k


def write_foreign(bagdir):
    import shutil
    import tempfile

    store = get_typestore(Stores.ROS2_HUMBLE)
    t = store.types
    Time = t["builtin_interfaces/msg/Time"]
    Header = t["std_msgs/msg/Header"]

    def header(ns, frame):
        return Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=frame)

    bagdir = Path(bagdir)
    bagdir.mkdir()
    half = FOREIGN_SCANS // 2
    with tempfile.TemporaryDirectory() as tmp:
        for part in (0, 1):
            little = part == 0
            with Writer(Path(tmp) / f"part{part}", version=8, storage_plugin=StoragePlugin.MCAP) as w:
                scan_c = w.add_connection("/robot1/scan", "sensor_msgs/msg/LaserScan", typestore=store)
                range_c = w.add_connection("/robot1/range", "sensor_msgs/msg/Range", typestore=store)
                odom_c = w.add_connection("/robot1/odom", "nav_msgs/msg/Odometry", typestore=store)
                joints_c = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=store)

                def put(conn, ns, msg, kind):
                    w.write(conn, ns, store.serialize_cdr(msg, kind, little_endian=little))

                for k in range(part * half, (part + 1) * half):
                    ns = T0_NS + k * 100_000_000
                    put(scan_c, ns, t["sensor_msgs/msg/LaserScan"](
                        header=header(ns, "base_scan"),
                        angle_min=math.radians(90.0),
                        angle_max=math.radians(-90.0),
                        angle_increment=-math.radians(1.0),
                        time_increment=0.0,
                        scan_time=0.1,
                        range_min=0.12,
                        range_max=3.5,
                        ranges=foreign_ranges(k),
                        intensities=np.array([], dtype=np.float32),
                    ), "sensor_msgs/msg/LaserScan")
                    put(range_c, ns + 10_000_000, t["sensor_msgs/msg/Range"](
                        header=header(ns + 10_000_000, "sonar_link"),
                        radiation_type=0,
                        field_of_view=0.5,
                        min_range=0.02,
                        max_range=4.0,
                        range=[float("nan"), float("inf"), 1.5][k % 3],
                    ), "sensor_msgs/msg/Range")
                    cov = np.zeros(36, dtype=np.float64)
                    odom = t["nav_msgs/msg/Odometry"](
                        header=header(ns + 20_000_000, "odom"),
                        child_frame_id="base_footprint",
                        pose=t["geometry_msgs/msg/PoseWithCovariance"](
                            pose=t["geometry_msgs/msg/Pose"](
                                position=t["geometry_msgs/msg/Point"](x=0.01 * k, y=0.0, z=0.0),
                                orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                            ),
                            covariance=cov,
                        ),
                        twist=t["geometry_msgs/msg/TwistWithCovariance"](
                            twist=t["geometry_msgs/msg/Twist"](
                                linear=t["geometry_msgs/msg/Vector3"](x=0.1, y=0.0, z=0.0),
                                angular=t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                            ),
                            covariance=cov,
                        ),
                    )
                    put(odom_c, ns + 20_000_000, odom, "nav_msgs/msg/Odometry")
                    left, right = wheel_angles(k)
                    for names, positions in (
                        (["caster_joint", "wheel_left_joint", "wheel_right_joint"], [1.5, left, right]),
                        (["shoulder", "elbow"], [0.1, 0.2]),
                    ):
                        put(joints_c, ns + 30_000_000, t["sensor_msgs/msg/JointState"](
                            header=header(ns + 30_000_000, ""),
                            name=names,
                            position=np.array(positions, dtype=np.float64),
                            velocity=np.array([], dtype=np.float64),
                            effort=np.array([], dtype=np.float64),
                        ), "sensor_msgs/msg/JointState")
            shutil.copy(Path(tmp) / f"part{part}" / f"part{part}.mcap", bagdir / f"foreign_{part}.mcap")
        yaml = (Path(tmp) / "part0" / "metadata.yaml").read_text()
        yaml = yaml.replace("  relative_file_paths:\n  - part0.mcap\n",
                            "  relative_file_paths:\n  - foreign_0.mcap\n  - foreign_1.mcap\n")
        if "foreign_1.mcap" not in yaml:
            fail("rosbags' metadata.yaml has no relative_file_paths list to split")
        (bagdir / "metadata.yaml").write_text(yaml)
    # The second file's schemas as ros2idl (hilsim reads only a schema's name).
    from mcap.reader import make_reader
    from mcap.writer import Writer as McapWriter

    second = bagdir / "foreign_1.mcap"
    with open(second, "rb") as f:
        records = list(make_reader(f).iter_messages())
    with open(second, "wb") as f:
        writer = McapWriter(f)
        writer.start(profile="ros2", library="rosbags_check")
        schemas, channels = {}, {}
        for schema, channel, message in records:
            if schema.name not in schemas:
                schemas[schema.name] = writer.register_schema(schema.name, "ros2idl", schema.data)
            if channel.topic not in channels:
                channels[channel.topic] = writer.register_channel(channel.topic, "cdr", schemas[schema.name])
            writer.add_message(channels[channel.topic], log_time=message.log_time,
                               data=message.data, publish_time=message.publish_time)
        writer.finish()


def foreign_imported(rec, joints_rec):
    rec, joints_rec = Path(rec), Path(joints_rec)
    lidar = table(rec / "lidar.csv")
    if len(lidar) != FOREIGN_SCANS * FOREIGN_READINGS:
        fail(f"foreign lidar.csv has {len(lidar)} rows")
    for n, row in enumerate(lidar):
        k, i = divmod(n, FOREIGN_READINGS)
        r = float(foreign_ranges(k)[i])
        valid = math.isfinite(r) and 0.12 <= r <= 3.5
        if float(row["angle_deg"]) != (90 - i) % 360 or int(row["rev"]) != k:
            fail(f"foreign lidar row {k},{i}: angle {row['angle_deg']} rev {row['rev']}")
        close(float(row["t_s"]), 0.1 * k, 1e-9, f"foreign lidar row {k},{i} t_s")
        if int(row["invalid"]) != (0 if valid else 1) or int(row["strength"]) != 0:
            fail(f"foreign lidar row {k},{i}: {row}")
        close(float(row["range_m"]), r if valid else 0.0, 1e-6, f"foreign lidar row {k},{i}")
    sonar = table(rec / "sonar.csv")
    if [float(s["range_m"]) for s in sonar] != [1.5] * sum(1 for k in range(FOREIGN_SCANS) if k % 3 == 2):
        fail(f"foreign sonar rows {sonar}")
    odometry = table(rec / "odometry.csv")
    if len(odometry) != FOREIGN_SCANS:
        fail(f"foreign odometry.csv has {len(odometry)} rows")
    close(float(odometry[-1]["left_m"]), 0.01 * (FOREIGN_SCANS - 1), 1e-9, "foreign odometry")
    wheels = table(joints_rec / "odometry.csv")
    if len(wheels) != FOREIGN_SCANS:
        fail(f"JointState odometry.csv has {len(wheels)} rows")
    l0, r0 = wheel_angles(0)
    for k, row in enumerate(wheels):
        left, right = wheel_angles(k)
        close(float(row["t_s"]), 0.1 * k + 0.03, 1e-9, f"JointState row {k} t_s")
        close(float(row["left_m"]), (left - l0) * WHEEL_RADIUS, 1e-12, f"JointState row {k} left")
        close(float(row["right_m"]), (right - r0) * WHEEL_RADIUS, 1e-12, f"JointState row {k} right")
    print(f"rosbags_check: hilsim imported the foreign split bag: {len(lidar)} lidar readings, "
          f"{len(sonar)} sonar, {len(odometry)} odometry and {len(wheels)} wheel-joint rows agree")


def resave(mcap_path, bagdir):
    """hilsim's export as another library's bag: every message deserialized and serialized
    again by rosbags, big-endian, into SQLite3 storage, topics under /robot (TF and markers
    left out)."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    with AnyReader([Path(mcap_path)], default_typestore=store) as reader, \
            Writer(Path(bagdir), version=8, storage_plugin=StoragePlugin.SQLITE3) as writer:
        connections = {}
        for c in reader.connections:
            if not c.msgtype.startswith(("visualization_msgs", "tf2_msgs")):
                connections[c.id] = writer.add_connection("/robot" + c.topic, c.msgtype, typestore=store)
        for c, ts, raw in reader.messages():
            if c.id in connections:
                msg = reader.deserialize(raw, c.msgtype)
                writer.write(connections[c.id], ts, store.serialize_cdr(msg, c.msgtype, little_endian=False))


def same_calibration(a, b):
    import json

    a, b = (json.loads(Path(p).read_text()) for p in (a, b))
    for key in ("sensors", "landmarks", "order", "converged"):
        if a.get(key) != b.get(key):
            fail(f"calibration {key} differs: {a.get(key)} != {b.get(key)}")
    print("rosbags_check: the calibration of the rosbags-resaved bag is the recording's, digit for digit")


def table(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def fail(what):
    print(f"rosbags_check: {what}", file=sys.stderr)
    sys.exit(1)


def close(a, b, tol, what):
    if not abs(a - b) <= tol:
        fail(f"{what}: {a} != {b} (tolerance {tol})")


def imported(bagdir, rec):
    rec = Path(rec)
    lidar = table(rec / "lidar.csv")
    if len(lidar) != SCANS * READINGS:
        fail(f"lidar.csv has {len(lidar)} rows, expected {SCANS * READINGS}")
    for k in range(SCANS):
        ranges = scan_ranges(k)
        for i in range(READINGS):
            row = lidar[k * READINGS + i]
            r = float(ranges[i])
            valid = math.isfinite(r) and RANGE_MIN <= r <= RANGE_MAX
            want_t = k * 0.1 + i * float(np.float32(0.1 / READINGS))
            close(float(row["t_s"]), want_t, 1.01e-6, f"lidar row {k},{i} t_s")
            if int(row["rev"]) != k or float(row["angle_deg"]) != 0.5 * i:
                fail(f"lidar row {k},{i}: rev {row['rev']} angle {row['angle_deg']}")
            if int(row["invalid"]) != (0 if valid else 1):
                fail(f"lidar row {k},{i}: invalid {row['invalid']} for range {r}")
            close(float(row["range_m"]), r if valid else 0.0, 1e-6, f"lidar row {k},{i} range")
            if int(row["strength"]) != 100 + k:
                fail(f"lidar row {k},{i}: strength {row['strength']}")
    odometry = table(rec / "odometry.csv")
    if len(odometry) != 2 * SCANS:
        fail(f"odometry.csv has {len(odometry)} rows")
    left = right = 0.0
    for j in range(1, 2 * SCANS):
        (x0, y0, a0), (x1, y1, a1) = odom_pose(j - 1), odom_pose(j)
        turn = a1 - a0
        heading = a0 + turn / 2
        ds = (x1 - x0) * math.cos(heading) + (y1 - y0) * math.sin(heading)
        left += ds - turn * WHEEL_BASE / 2
        right += ds + turn * WHEEL_BASE / 2
        close(float(odometry[j]["left_m"]), left, 1e-8, f"odometry row {j} left")
        close(float(odometry[j]["right_m"]), right, 1e-8, f"odometry row {j} right")
        close(float(odometry[j]["t_s"]), 0.02 + 0.05 * j, 1e-9, f"odometry row {j} t_s")
    commands = table(rec / "commands.csv")
    if len(commands) != SCANS // 2:
        fail(f"commands.csv has {len(commands)} rows")
    for c, row in enumerate(commands):
        w = 0.4 + 0.01 * c
        close(float(row["t_s"]), 0.2 * c + 0.001, 1e-9, f"command {c} t_s")
        close(float(row["left_mps"]), 0.2 - w * WHEEL_BASE / 2, 1e-12, f"command {c} left")
        close(float(row["right_mps"]), 0.2 + w * WHEEL_BASE / 2, 1e-12, f"command {c} right")
    sonar = table(rec / "sonar.csv")
    if len(sonar) != SCANS - 1:
        fail(f"sonar.csv has {len(sonar)} rows (the +inf one is no echo)")
    for row, k in zip(sonar, [k for k in range(SCANS) if k != 3]):
        close(float(row["range_m"]), 1.0 + 0.01 * k, 1e-6, f"sonar {k}")
        close(float(row["t_s"]), 0.1 * k + 0.005, 1e-9, f"sonar {k} t_s")
    with open(rec / "meta.toml", "rb") as f:
        lidar_mount = tomllib.load(f).get("lidar", {})
    got = tuple(lidar_mount.get(k, 0.0) for k in ("x_m", "y_m", "yaw_deg"))
    for g, want, what in zip(got, MOUNT, ("x_m", "y_m", "yaw_deg")):
        close(g, want, 1e-9, f"meta.toml [lidar] {what} (from /tf_static)")
    print(f"rosbags_check: hilsim imported the rosbags bag: {len(lidar)} lidar readings, "
          f"{len(odometry)} odometry, {len(commands)} commands, {len(sonar)} sonar rows agree")


def yaw_of(q):
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


def check_messages(name, messages, rec):
    """`messages`: (topic, log time ns, decoded message) of hilsim's export, in file order."""
    lidar = table(rec / "lidar.csv")
    truth = table(rec / "truth.csv")
    commands = table(rec / "commands.csv")
    sonar = table(rec / "sonar.csv") if (rec / "sonar.csv").exists() else []
    by_topic = {}
    for topic, _, msg in messages:
        by_topic.setdefault(topic, []).append(msg)
    revs = {}
    for row in lidar:
        revs.setdefault(int(row["rev"]), []).append(row)
    scans = by_topic.get("/scan", [])
    if len(scans) != len(revs):
        fail(f"{name}: {len(scans)} LaserScans for {len(revs)} revolutions")
    for scan, (rev, rows) in zip(scans, sorted(revs.items())):
        if scan.header.frame_id != "laser":
            fail(f"{name}: scan frame {scan.header.frame_id}")
        stamp = scan.header.stamp.sec + scan.header.stamp.nanosec * 1e-9 - 1.0
        close(stamp, float(rows[0]["t_s"]), 1e-9, f"{name}: revolution {rev} stamp")
        for row in rows:
            angle = math.radians(float(row["angle_deg"]))
            i = round((angle - scan.angle_min) / scan.angle_increment)
            r = float(scan.ranges[i])
            if int(row["invalid"]):
                if not math.isnan(r):
                    fail(f"{name}: revolution {rev} reading {i}: invalid but {r}")
            else:
                close(r, float(row["range_m"]), 1e-6, f"{name}: revolution {rev} reading {i}")
            close(float(scan.intensities[i]), float(row["strength"]), 0, f"{name}: strength")
    poses = by_topic.get("/ground_truth/pose", [])
    if len(poses) != len(truth):
        fail(f"{name}: {len(poses)} poses for {len(truth)} truth rows")
    for pose, row in zip(poses, truth):
        close(pose.pose.position.x, float(row["x_m"]), 0, f"{name}: truth x")
        close(pose.pose.position.y, float(row["y_m"]), 0, f"{name}: truth y")
        d = yaw_of(pose.pose.orientation) - float(row["yaw_rad"])
        close(math.remainder(d, 2 * math.pi), 0.0, 1e-12, f"{name}: truth yaw")
    twists = by_topic.get("/cmd_vel", [])
    if len(twists) != len(commands):
        fail(f"{name}: {len(twists)} commands for {len(commands)} rows")
    for twist, row in zip(twists, commands):
        v = 0.5 * (float(row["left_mps"]) + float(row["right_mps"]))
        close(twist.twist.linear.x, v, 1e-12, f"{name}: command speed")
    ranges = by_topic.get("/sonar", [])
    if len(ranges) != len(sonar):
        fail(f"{name}: {len(ranges)} Range messages for {len(sonar)} sonar rows")
    for msg, row in zip(ranges, sonar):
        close(msg.range, float(row["range_m"]), 1e-6, f"{name}: sonar")
    check_frames(name, by_topic, truth)
    markers = [m for a in by_topic.get("/world", []) for m in a.markers]
    if not markers:
        fail(f"{name}: no world markers")
    print(f"rosbags_check: {name} read hilsim's export: {len(scans)} scans, {len(poses)} poses, "
          f"{len(twists)} commands, {len(ranges)} ranges, {len(markers)} markers agree")


def stamp_ns(stamp):
    return stamp.sec * 10**9 + stamp.nanosec


def slerp(q0, q1, f):
    """Quaternions (x, y, z, w) interpolated the shorter way, as tf2 does."""
    dot = sum(a * b for a, b in zip(q0, q1))
    if dot < 0:
        q1, dot = [-c for c in q1], -dot
    if dot > 1 - 1e-12:
        return q0
    theta = math.acos(min(1.0, dot))
    s0, s1 = math.sin((1 - f) * theta) / math.sin(theta), math.sin(f * theta) / math.sin(theta)
    return [s0 * a + s1 * b for a, b in zip(q0, q1)]


def quat(q):
    return [q.x, q.y, q.z, q.w]


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz]


def rotate(q, v):
    x, y, z, _ = qmul(qmul(q, [v[0], v[1], v[2], 0.0]), [-q[0], -q[1], -q[2], q[3]])
    return [x, y, z]


def check_frames(name, by_topic, truth):
    """The frames make one tree rooted at `map` (REP 105), every message's frame is in it, and
    looking base_link up in map at each truth stamp (tf2's way: the latest transform at or
    before, interpolated with the next) gives the truth's pose."""
    edges = {}
    for topic in ("/tf", "/tf_static"):
        for m in by_topic.get(topic, []):
            for tf in m.transforms:
                parent = edges.setdefault(tf.child_frame_id, tf.header.frame_id)
                if parent != tf.header.frame_id:
                    fail(f"{name}: {tf.child_frame_id} has two parents, {parent} and {tf.header.frame_id}")

    def root(frame):
        for _ in range(10):
            if frame not in edges:
                return frame
            frame = edges[frame]
        fail(f"{name}: the frames have a cycle")

    frames = {"base_link"}
    for topic, msgs in by_topic.items():
        for m in msgs:
            if hasattr(m, "header") and m.header.frame_id:
                frames.add(m.header.frame_id)
            if hasattr(m, "child_frame_id"):
                frames.add(m.child_frame_id)
    for frame in sorted(frames):
        if root(frame) != "map":
            fail(f"{name}: frame {frame} is not connected to map (root {root(frame)}; {edges})")
    for odom in by_topic.get("/odom", []):
        if (odom.header.frame_id, odom.child_frame_id) != ("odom", "base_link"):
            fail(f"{name}: /odom in {odom.header.frame_id} -> {odom.child_frame_id}")
    series = {}
    for m in by_topic.get("/tf", []):
        for tf in m.transforms:
            series.setdefault(tf.child_frame_id, []).append(tf)
    stamps_of = {child: [stamp_ns(tf.header.stamp) for tf in tfs] for child, tfs in series.items()}

    def lookup(child, t):
        """child in its parent at stamp t, interpolated."""
        tfs, stamps = series[child], stamps_of[child]
        after = bisect.bisect_right(stamps, t)
        a = tfs[max(after - 1, 0)]
        b = tfs[min(after, len(tfs) - 1)]
        ta, tb = stamp_ns(a.header.stamp), stamp_ns(b.header.stamp)
        f = (t - ta) / (tb - ta) if tb > ta else 0.0
        pa, pb = a.transform.translation, b.transform.translation
        p = [pa.x + f * (pb.x - pa.x), pa.y + f * (pb.y - pa.y), pa.z + f * (pb.z - pa.z)]
        return p, slerp(quat(a.transform.rotation), quat(b.transform.rotation), f)

    poses = by_topic.get("/ground_truth/pose", [])
    for pose, row in zip(poses, truth):
        t = stamp_ns(pose.header.stamp)
        frame, p, q = "base_link", [0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]
        while frame != "map":
            if frame in series:
                pp, pq = lookup(frame, t)
            else:
                fail(f"{name}: no moving transform for {frame}")
            p = [a + b for a, b in zip(pp, rotate(pq, p))]
            q = qmul(pq, q)
            frame = edges[frame]
        close(p[0], float(row["x_m"]), 1e-9, f"{name}: base_link in map, x at {row['t_s']}")
        close(p[1], float(row["y_m"]), 1e-9, f"{name}: base_link in map, y at {row['t_s']}")
        yaw = math.atan2(2 * (q[3] * q[2] + q[0] * q[1]), 1 - 2 * (q[1] ** 2 + q[2] ** 2))
        d = math.remainder(yaw - float(row["yaw_rad"]), 2 * math.pi)
        close(d, 0.0, 1e-9, f"{name}: base_link in map, yaw at {row['t_s']}")


def exported(mcap_path, rec):
    rec = Path(rec)
    with AnyReader([Path(mcap_path)]) as reader:
        messages = [
            (c.topic, ts, reader.deserialize(raw, c.msgtype))
            for c, ts, raw in reader.messages()
        ]
    check_messages("rosbags", messages, rec)
    from mcap_ros2.reader import read_ros2_messages

    messages = [
        (m.channel.topic, m.log_time_ns, m.ros_msg)
        for m in read_ros2_messages(mcap_path, log_time_order=False)
    ]
    check_messages("mcap-ros2-support", messages, rec)


def rewrite(bagdir, out, compression):
    from mcap.writer import CompressionType, Writer as McapWriter
    from rosbags.rosbag2 import Reader

    with Reader(bagdir) as reader, open(out, "wb") as f:
        writer = McapWriter(f, compression=CompressionType[compression.upper()], chunk_size=1 << 16)
        writer.start(profile="ros2", library="rosbags_check")
        channels = {}
        for c in reader.connections:
            schema = writer.register_schema(c.msgtype, "ros2msg", c.msgdef.data.encode())
            channels[c.id] = writer.register_channel(c.topic, "cdr", schema)
        for c, ts, raw in reader.messages():
            writer.add_message(channels[c.id], log_time=ts, data=bytes(raw), publish_time=ts)
        writer.finish()


if __name__ == "__main__":
    mode = sys.argv[1]
    if mode == "write":
        write(Path(sys.argv[2]), *sys.argv[3:4])
    elif mode == "write-ros1":
        write_ros1(Path(sys.argv[2]), sys.argv[3])
    elif mode == "rewrite":
        rewrite(Path(sys.argv[2]), sys.argv[3], sys.argv[4])
    elif mode == "imported":
        imported(sys.argv[2], sys.argv[3])
    elif mode == "resave":
        resave(sys.argv[2], sys.argv[3])
    elif mode == "same-calibration":
        same_calibration(sys.argv[2], sys.argv[3])
    elif mode == "write-foreign":
        write_foreign(sys.argv[2])
    elif mode == "foreign-imported":
        foreign_imported(sys.argv[2], sys.argv[3])
    elif mode == "exported":
        exported(sys.argv[2], sys.argv[3])
    else:
        fail(f"unknown mode {mode}")
