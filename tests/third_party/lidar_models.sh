#!/usr/bin/env bash
# Each lidar model's third-party drivers (from PyPI, in a virtual environment made here) read
# `hilsim serve --pty --realtime` of its checked-in scenario for 5 s: at least 95 % of their
# points must be readings of `hilsim record`'s recording (angle within 0.2°, distance within
# 2 mm), at the unit's rate within 1 % (tests/third_party/lidar_models_client.py).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$root"
venv="$root/target/third-party-venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet --disable-pip-version-check "lds2d==0.7.0" "pyserial>=3.4" \
    "rplidar-roboticia==0.9.5" "pyrplidar==0.1.2" "hokuyolx==0.9.0"

hilsim="$(bash "$root/.ci/hilsim-binary")"
tmp="$(mktemp -d)"
trap 'kill "${serve_pid:-}" 2>/dev/null || true; rm -rf "$tmp"' EXIT

# model, then each driver that reads it
while read -r model drivers; do
    scenario="scenarios/lidar-$model.toml"
    "$hilsim" record "$scenario" --out "$tmp/$model" > /dev/null
    for driver in $drivers; do
        "$hilsim" serve "$scenario" --realtime > "$tmp/serve.out" &
        serve_pid=$!
        # Up to three minutes: on a loaded machine the server builds its world slowly (over a
        # minute was seen while another job kept both cores busy); stop early if it has exited.
        for _ in $(seq 1800); do
            grep -q '^serial: ' "$tmp/serve.out" 2>/dev/null && break
            kill -0 "$serve_pid" 2>/dev/null || break
            sleep 0.1
        done
        port="$(sed -n 's/^serial: //p' "$tmp/serve.out")"
        [ -n "$port" ] || { echo "lidar_models.sh: hilsim serve printed no port:" >&2; cat "$tmp/serve.out" >&2; exit 1; }
        timeout 60 "$venv/bin/python" tests/third_party/lidar_models_client.py \
            "$driver" "$port" "$tmp/$model/lidar.csv" 5
        kill "$serve_pid" 2>/dev/null || true
        wait "$serve_pid" 2>/dev/null || true
    done
done <<'MODELS'
rplidar-a1 lds2d:RPLIDAR-A1 rplidar pyrplidar
lds-01 lds2d:LDS-01
lds-02rr lds2d:XIAOMI-LDS02RR
ld06 lds2d:LDROBOT-LD06
ydlidar-x4 lds2d:YDLIDAR-X4
urg-04lx hokuyolx
MODELS
