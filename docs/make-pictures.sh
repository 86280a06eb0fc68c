#!/usr/bin/env bash
# Regenerates docs/pictures/*.png, the README walkthrough's pictures, from the tool's own output:
# each is one chart of a page `hilsim report` or `hilsim diagnose --report` wrote, rendered by
# headless Chromium. Run from anywhere: bash docs/make-pictures.sh (about 3 minutes).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="$root/docs/pictures"
chromium="$(command -v chromium || command -v chromium-browser || true)"
if [ -z "$chromium" ]; then
    echo "make-pictures.sh: needs Chromium (Debian: apt-get install chromium)" >&2
    exit 1
fi
hilsim="$(bash "$root/.ci/hilsim-binary")"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"

# shot PAGE TITLE PNG: the chart of PAGE (an HTML page or an SVG file) whose text holds TITLE,
# alone on a page of its own size, as PNG.
shot() {
    python3 - "$1" "$2" "$work/chart.html" <<'PY' > "$work/size"
import re, sys
page, title, dest = sys.argv[1:]
text = open(page, encoding="utf-8").read()
charts = re.findall(r"<svg\b.*?</svg>", text, flags=re.S)
chart = next(c for c in charts if title in c)
width = re.search(r'width="([0-9.]+)"', chart).group(1)
height = re.search(r'height="([0-9.]+)"', chart).group(1)
open(dest, "w", encoding="utf-8").write(
    '<!DOCTYPE html><html><head><meta charset="utf-8"><style>body{margin:0}</style></head>'
    f"<body>{chart}</body></html>")
print(f"{round(float(width))},{round(float(height))}")
PY
    "$chromium" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
        --disable-background-networking --disable-component-update --disable-sync \
        --hide-scrollbars --user-data-dir="$work/profile" --window-size="$(cat "$work/size")" \
        --screenshot="$3" "file://$work/chart.html" 2>/dev/null
    echo "wrote $3"
}

# The walkthrough's landmark run: record, calibrate, report.
"$hilsim" record "$root/scenarios/landmarks-5.toml" --out landmarks > /dev/null
"$hilsim" calibrate landmarks --method landmarks --json > landmarks.json
"$hilsim" report landmarks --scenario "$root/scenarios/landmarks-5.toml" \
    --calibration landmarks.json --out landmarks-report > /dev/null
shot landmarks-report/index.html "The world, the paths and the scans" "$out/landmarks-map.png"

# The main job's run, with its report: the lidar's error against distance.
"$hilsim" run --out board --report board-report > /dev/null
shot board-report/index.html "lidar: error against the true distance" "$out/straight-board-lidar-error.png"

# A "real" robot whose lidar has an incidence-angle error the simulation leaves out.
cp "$root/scenarios/diagnose-room.toml" real.toml
printf '\n[effects.lidar_incidence_angle]\ncoefficient = 0.01\n' >> real.toml
"$hilsim" record real.toml --out real > /dev/null
"$hilsim" diagnose --sim "$root/scenarios/diagnose-room.toml" --real real --report diagnosis > /dev/null || true
shot diagnosis/residuals-1-incidence-angle.svg "residual" "$out/diagnose-incidence.png"
