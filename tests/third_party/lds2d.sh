#!/usr/bin/env bash
# A third-party driver (lds2d from PyPI, in a virtual environment made here) reads
# `hilsim serve` from its pty in real time; every revolution must equal `hilsim record`'s.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$root"
venv="$root/target/third-party-venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet --disable-pip-version-check "lds2d==0.7.0" "pyserial>=3.4"

hilsim="$(bash "$root/.ci/hilsim-binary")"
tmp="$(mktemp -d)"
trap 'kill "${serve_pid:-}" 2>/dev/null || true; rm -rf "$tmp"' EXIT
scenario=scenarios/room-tour.toml
"$hilsim" record "$scenario" --out "$tmp/rec" --seed 5
"$hilsim" serve "$scenario" --realtime --seed 5 > "$tmp/serve.out" &
serve_pid=$!
# Up to three minutes: on a loaded machine the server builds its world slowly (over a minute
# was seen while another job kept both cores busy); stop early if it has exited.
for _ in $(seq 1800); do
    grep -q '^serial: ' "$tmp/serve.out" 2>/dev/null && break
    kill -0 "$serve_pid" 2>/dev/null || break
    sleep 0.1
done
port="$(sed -n 's/^serial: //p' "$tmp/serve.out")"
[ -n "$port" ] || { echo "lds2d.sh: hilsim serve printed no port:" >&2; cat "$tmp/serve.out" >&2; exit 1; }
timeout 60 "$venv/bin/python" tests/third_party/lds2d_client.py "$port" 20 "$tmp/rec/lidar.csv"
