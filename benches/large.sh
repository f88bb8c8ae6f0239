#!/usr/bin/env bash
# Large models (issue 29): a steel cantilever divided into n two-node beams (0.01 m each,
# a tip force, 10 steps of 1e-5 s) with the default OUTPUT, at 10k, 100k and 1M unknowns
# (6 per node). Prints steps per second (wall and CPU) and the peak memory per unknown
# (/usr/bin/time -v), under `ulimit -n 1024`. Times include the set-up (parse, mesh, symbolic
# LU): steps per CPU second is the figure that a loaded machine does not spoil.
#
#   cargo build --release && bash benches/large.sh [n ...]      (default: 1667 16667 166667)
#
# Run it on a quiet machine: the 1M case takes a few seconds of CPU and 2.3 GB.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=target/release/mecano-rs
TIME=/usr/bin/time
[ -x "$TIME" ] || { echo "needs GNU time: apt-get install time" >&2; exit 2; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(1667 16667 166667)
printf '%10s %10s %8s %10s %10s %12s %12s %10s\n' unknowns beams steps wall_s cpu_s steps_per_s steps_per_cpu_s B_per_unk
for n in "${sizes[@]}"; do
  len=$(awk -v n="$n" 'BEGIN { printf "%.2f", n * 0.01 }')
  cat > "$WORK/c$n.dat" <<DECK
TITLE cantilever of $n beams
MATERIALS
  1 E 2.1e11 NU 0.3 RHO 7800
SECTIONS
  1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8 K 0.8333333333333334
NODES
  1 0 0 0 FIX ALL
  2 $len 0 0
ELEMENTS
  1 BEAM 1 2 MAT 1 SEC 1 AXIS2 0 0 1 DIVIDE $n
LOADS
  FORCE 2 0 -100 0
ANALYSIS DYNAMIC STEP 1e-5 END 1e-4
OUTPUT NODES 2
DECK
  ( ulimit -n 1024; "$TIME" -v "$BIN" -q --checkpoint 0 -o "$WORK/o$n" "$WORK/c$n.dat" ) 2> "$WORK/t$n" >/dev/null
  unk=$(( 6 * n ))
  wall=$(awk -F': ' '/Elapsed/ { split($2, a, ":"); s = 0; for (i = 1; i <= length(a); i++) s = s * 60 + a[i]; print s }' "$WORK/t$n")
  cpu=$(awk -F': ' '/User time|System time/ { s += $2 } END { print s }' "$WORK/t$n")
  rss=$(awk -F': ' '/Maximum resident/ { print $2 * 1024 }' "$WORK/t$n")
  steps=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['stats']['steps'])" "$WORK/o$n/summary.json")
  awk -v u="$unk" -v n="$n" -v s="$steps" -v w="$wall" -v c="$cpu" -v r="$rss" \
    'BEGIN { printf "%10d %10d %8d %10.2f %10.2f %12.2f %12.2f %10.0f\n", u, n, s, w, c, s / w, s / c, r / u }'
done
