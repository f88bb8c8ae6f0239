#!/usr/bin/env bash
# One element of order 8 per bar against the cheapest two-node mesh that reaches 1e-3 m, side
# by side on the seed scene (flexible1, t <= 1.5 s): errors against the space-time reference
# and CPU seconds, the two runs interleaved ROUNDS times (docs/accuracy.md, "Beams of order p").
#
#   benches/order_ratio.sh [OUT] [ROUNDS] [LINEAR_BEAMS_PER_BAR]
#
# OUT (default out/order) keeps the decks and runs; the reference (two elements of order 8 per
# bar at h = 3.90625e-6 s, ~20-40 s of CPU) is made once and reused. ROUNDS defaults to 3,
# the two-node mesh to 112 beams per bar (the fewest that reach 1e-3 m: 110 and 111 do not).
# Needs a release build (cargo build --release) and python3 (standard library only).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/order}
rounds=${2:-3}
lin=${3:-112}
bin=target/release/mecano-rs
mkdir -p "$out"

# A flexible1 deck with each bar ONE beam card `DIVIDE d ORDER p`, step h, output every k steps.
mk() { # name divide order step every
  sed -e "s/^  2 TO 12 LINE  0 0 0   1 0 0/  2 0 0 0\n  12 1 0 0/" \
    -e "s/^  13 TO 23 LINE  1 0 0   1.8660254037844386 0 0.5/  13 1 0 0\n  23 1.8660254037844386 0 0.5/" \
    -e "s/^  2 TO 11  BEAM 2 3  MAT 1 SEC 1/  2 BEAM 2 12 MAT 1 SEC 1 DIVIDE $2 ORDER $3/" \
    -e "s/^  13 TO 22 BEAM 13 14  MAT 1 SEC 1/  13 BEAM 13 23 MAT 1 SEC 1 DIVIDE $2 ORDER $3/" \
    -e "s/STEP 1e-4 END 2.0/STEP $4 END 1.5/" -e "s/EVERY 10/EVERY $5/" \
    decks/pendulum_flexible1.dat >"$out/$1.dat"
}
# Output every 7.8125e-5 s for the compared runs, every 1.953125e-5 s for the reference.
mk ref 2 8 3.90625e-6 5
mk p8d1 1 8 1.5625e-5 5
mk "l$lin" "$lin" 1 1.5625e-5 5

[ -f "$out/out_ref/summary.json" ] || "$bin" "$out/ref.dat" -o "$out/out_ref" --quiet --checkpoint 0
cpu() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['stats']['cpu_seconds'])" "$1/summary.json"; }
p8=() lin_cpu=()
for r in $(seq 1 "$rounds"); do
  "$bin" "$out/p8d1.dat" -o "$out/out_p8d1" --quiet --checkpoint 0
  p8+=("$(cpu "$out/out_p8d1")")
  "$bin" "$out/l$lin.dat" -o "$out/out_l$lin" --quiet --checkpoint 0
  lin_cpu+=("$(cpu "$out/out_l$lin")")
  echo "round $r: p8d1 ${p8[-1]} s, l$lin ${lin_cpu[-1]} s"
done
python3 benches/order_study.py "$out" ref p8d1 "l$lin"
python3 - "${p8[*]}" "${lin_cpu[*]}" <<'EOF'
import statistics, sys
a = [float(x) for x in sys.argv[1].split()]
b = [float(x) for x in sys.argv[2].split()]
print(f"CPU p8d1: best {min(a):.2f} s, median {statistics.median(a):.2f} s; "
      f"two-node: best {min(b):.2f} s, median {statistics.median(b):.2f} s")
print(f"ratio: best/best {min(b) / min(a):.2f}, median/median {statistics.median(b) / statistics.median(a):.2f}, "
      f"per round {', '.join(f'{y / x:.2f}' for x, y in zip(a, b))}")
EOF
