#!/usr/bin/env bash
# Parallel speed-up of a local sweep: the 20 cases of sweeps/speedup.toml (the pendulum
# to 0.8 s, about 1 s each) run one by one (--jobs 1) and on two cores (--jobs 2), each
# into a fresh directory; prints the wall-clock times and their ratio, and the per-case
# overhead: (wall time of --jobs 1 − the cases' own seconds) / 20.
# Usage: benches/sweep_speedup.sh [path/to/mecano-rs]   (after cargo build --release)
set -euo pipefail
cd "$(dirname "$0")/.."
B=${1:-target/release/mecano-rs}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
calc() { awk "BEGIN { printf \"%.3f\", $1 }"; }
wall() { local s e; s=$(date +%s.%N); "$@" >/dev/null 2>&1; e=$(date +%s.%N); calc "$e - $s"; }
w1=$(wall "$B" sweep sweeps/speedup.toml -o "$T/j1" --jobs 1 -q)
w2=$(wall "$B" sweep sweeps/speedup.toml -o "$T/j2" --jobs 2 -q)
runs=$(awk -F, 'NR > 1 { s += $(NF - 1) } END { printf "%.3f", s }' "$T/j1/sweep.csv")
printf 'jobs 1: %.2f s wall (the runs themselves: %s s)\njobs 2: %.2f s wall\nspeed-up: %.2f\n' "$w1" "$runs" "$w2" "$(calc "$w1 / $w2")"
printf 'per-case overhead: %.1f ms\n' "$(calc "($w1 - $runs) / 20 * 1000")"
