#!/bin/sh
# The whole pykalman comparison: venv, export from the Rust bench, compare.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
python=$("$here/setup.sh" | tail -n 1)
out="${CARGO_TARGET_DIR:-$root/target}/pykalman-compare"
(cd "$root" && EM_BENCH_PYKALMAN_DIR="$out" cargo bench -p hilsim-calibrator --bench em)
"$python" "$here/compare.py" "$out"
