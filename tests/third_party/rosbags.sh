#!/usr/bin/env bash
# Third-party ROS libraries (rosbags, mcap and mcap-ros2-support from PyPI, in a virtual
# environment made here): a bag rosbags writes (ROS 2, and ROS 1) is what `hilsim import` reads,
# its /tf_static the lidar's mount in meta.toml, and `hilsim export`'s file is what rosbags and
# mcap-ros2-support read, message for message.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$root"
venv="$root/target/ros2-venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet --disable-pip-version-check \
    "rosbags==0.11.9" "mcap==1.6.0" "mcap-ros2-support==0.6.0"

hilsim="$(bash "$root/.ci/hilsim-binary")"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
check="tests/third_party/rosbags_check.py"

# rosbags → hilsim import (a bag directory, metadata.yaml and MCAP), with the robot's meta.toml
# (no [lidar]: the mount is /tf_static's).
"$venv/bin/python" "$check" write "$tmp/bag"
printf 'format = "hilsim-recording/1"\n[robot]\nwheel_base_m = 0.3\n' > "$tmp/meta.toml"
"$hilsim" import "$tmp/bag" --out "$tmp/imported" --meta "$tmp/meta.toml"
"$venv/bin/python" "$check" imported "$tmp/bag" "$tmp/imported"
# The same messages in single MCAP files from the mcap library's writer, chunks compressed.
for compression in zstd lz4; do
    "$venv/bin/python" "$check" rewrite "$tmp/bag" "$tmp/$compression.mcap" "$compression"
    "$hilsim" import "$tmp/$compression.mcap" --out "$tmp/$compression" --meta "$tmp/meta.toml"
    "$venv/bin/python" "$check" imported "$tmp/$compression.mcap" "$tmp/$compression"
done

# rosbag2's own compression modes: each file one zstd stream (`file`), each message (`message`);
# and its other storage, SQLite3 (rosbags' and Humble's default).
for mode in file message sqlite3; do
    "$venv/bin/python" "$check" write "$tmp/bag-$mode" "$mode"
    "$hilsim" import "$tmp/bag-$mode" --out "$tmp/rec-$mode" --meta "$tmp/meta.toml"
    "$venv/bin/python" "$check" imported "$tmp/bag-$mode" "$tmp/rec-$mode"
done

# The same messages as ROS 1 bags (rosbags.rosbag1, several chunks each: uncompressed, bz2,
# lz4): the same recording, the lidar's mount from /tf_static as in the ROS 2 bags.
for compression in none bz2 lz4; do
    "$venv/bin/python" "$check" write-ros1 "$tmp/ros1-$compression.bag" "$compression"
    "$hilsim" import "$tmp/ros1-$compression.bag" --out "$tmp/ros1-$compression" --meta "$tmp/meta.toml"
    "$venv/bin/python" "$check" imported "$tmp/ros1-$compression.bag" "$tmp/ros1-$compression"
done

# Another robot's bag: namespaced topics, a clockwise scan without intensities, NaN and inf,
# wheel joints, split in two files (the second big-endian, ros2idl schemas).
"$venv/bin/python" "$check" write-foreign "$tmp/foreign"
"$hilsim" import "$tmp/foreign" --out "$tmp/foreign-rec" --meta "$tmp/meta.toml"
"$hilsim" import "$tmp/foreign" --out "$tmp/foreign-joints" --meta "$tmp/meta.toml" \
    --odom /joint_states --wheel-radius-m 0.033
"$venv/bin/python" "$check" foreign-imported "$tmp/foreign-rec" "$tmp/foreign-joints"

# A run calibrated through another library's bag: the landmarks run, every message serialized
# again by rosbags (big-endian, SQLite3 storage, topics under /robot), imports and calibrates
# as the recording itself does.
"$hilsim" record scenarios/landmarks-5.toml --out "$tmp/lm" --mcap "$tmp/lm.mcap" > /dev/null
"$venv/bin/python" "$check" resave "$tmp/lm.mcap" "$tmp/lm-resaved"
"$hilsim" import "$tmp/lm-resaved" --out "$tmp/lm-imported" --meta "$tmp/lm/meta.toml"
"$hilsim" calibrate "$tmp/lm" --method landmarks --json > "$tmp/lm.json"
"$hilsim" calibrate "$tmp/lm-imported" --method landmarks --json > "$tmp/lm-imported.json"
"$venv/bin/python" "$check" same-calibration "$tmp/lm.json" "$tmp/lm-imported.json"

# hilsim record --mcap → rosbags and mcap-ros2-support.
scenario=scenarios/straight-board.toml
"$hilsim" record "$scenario" --out "$tmp/rec" --mcap "$tmp/run.mcap"
"$venv/bin/python" "$check" exported "$tmp/run.mcap" "$tmp/rec"
echo "rosbags.sh: ok"
