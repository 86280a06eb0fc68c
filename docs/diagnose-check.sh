#!/usr/bin/env bash
# Checks the diagnosis on every checked-in scenario and each catalogued effect (docs/diagnose.md):
#   bash docs/diagnose-check.sh effects   # each effect concealed in diagnose-room (seed 77),
#                                         # diagnosed with truth.csv and without it
#   bash docs/diagnose-check.sh nominal   # faithful runs of every checked-in scenario (its own
#                                         # seed, 101 and 102), with truth.csv and without it
#   bash docs/diagnose-check.sh quiet     # every checked-in scenario at its own seed
#                                         # and five more (101-105), without truth.csv; exit 1
#                                         # when any names a catalogued effect
# Prints one line per diagnosis: the run, the verdict, the fitted parameters, where.
# Needs only the release binary (built here) and python3 for reading the JSON.
set -euo pipefail
cd "$(dirname "$0")/.."
hilsim="$(bash .ci/hilsim-binary --release)"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
room=scenarios/diagnose-room.toml

show() { # NAME JSON
    python3 -c 'import json,sys; d=json.load(open(sys.argv[2])); print(sys.argv[1], d["effect"], d["params"], (d.get("located") or {}).get("where"))' "$1" "$2"
}

diagnose_both() { # NAME SCENARIO RECORDING
    cp -r "$3" "$3-nt" && rm "$3-nt/truth.csv"
    for v in "" "-nt"; do
        "$hilsim" diagnose --sim "$2" --real "$3$v" --json > "$work/out.json"
        show "$1${v:+ (no truth)}" "$work/out.json"
    done
}

case "${1:-}" in
effects)
    declare -A effect=(
        [lidar_incidence_angle]='coefficient = 0.02'
        [lidar_reflectivity]='coefficient_m = 0.015'
        [lidar_mixed_pixels]='half_width_deg = 1.0'
        [lidar_motion_skew]=''
        [lidar_warmup_drift]=$'coefficient_per_m = 0.007\ntime_constant_s = 12.0'
        [sonar_beam_width]='half_angle_deg = 14.0'
        [sonar_speed_of_sound]='air_temperature_c = 40.0'
        [odometer_wheel_slip]='gain_s = 0.06'
        [drive_motor_lag]='time_constant_s = 0.25'
    )
    for name in "${!effect[@]}"; do
        printf '%s\n\n[effects.%s]\n%s\n' "$(cat "$room")" "$name" "${effect[$name]}" > "$work/$name.toml"
        "$hilsim" record "$work/$name.toml" --seed 77 --out "$work/$name" > /dev/null
        diagnose_both "$name" "$room" "$work/$name"
    done
    ;;
nominal)
    for scenario in scenarios/*.toml; do
        [ "$(basename "$scenario")" = Cargo.toml ] && continue
        name=$(basename "$scenario" .toml)
        for seed in own 101 102; do
            args=()
            [ "$seed" = own ] || args=(--seed "$seed")
            "$hilsim" record "$scenario" "${args[@]}" --out "$work/$name-$seed" > /dev/null
            diagnose_both "$name seed $seed" "$scenario" "$work/$name-$seed"
        done
    done
    ;;
quiet)
    named=0
    for scenario in scenarios/*.toml; do
        [ "$(basename "$scenario")" = Cargo.toml ] && continue
        name=$(basename "$scenario" .toml)
        for seed in own 101 102 103 104 105; do
            args=()
            [ "$seed" = own ] || args=(--seed "$seed")
            "$hilsim" record "$scenario" "${args[@]}" --out "$work/run" > /dev/null
            rm -f "$work/run/truth.csv"
            "$hilsim" diagnose --sim "$scenario" --real "$work/run" --json > "$work/out.json"
            show "$name seed $seed (no truth)" "$work/out.json"
            if python3 -c 'import json,sys; sys.exit(0 if json.load(open(sys.argv[1]))["effects"] else 1)' "$work/out.json"; then
                named=$((named + 1))
            fi
            rm -rf "$work/run"
        done
    done
    echo "faithful runs naming a catalogued effect: $named"
    [ "$named" -eq 0 ]
    ;;
*)
    echo "usage: bash docs/diagnose-check.sh effects|nominal|quiet" >&2
    exit 2
    ;;
esac
