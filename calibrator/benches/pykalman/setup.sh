#!/bin/sh
# Creates a Python virtual environment with pykalman and numpy for compare.py, under the cargo
# target directory (ignored by git). Prints the interpreter to use.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
venv="${CARGO_TARGET_DIR:-$root/target}/pykalman-venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet pykalman numpy
echo "$venv/bin/python"
