#!/usr/bin/env bash
# ESDIRK3 against HHT on the seed scene's converged mesh (flexible1, one beam of order 8 per
# bar, CLIP OFF, t <= 1.5 s): errors against the space-time reference and CPU seconds, the
# runs interleaved ROUNDS times (docs/accuracy.md, "A third-order integrator").
#
#   benches/esdirk_ratio.sh [OUT] [ROUNDS] [ESDIRK_STEP] [EVERY] [SCHEME]
#
# SCHEME is the ANALYSIS keyword of the stage scheme: ESDIRK3 (default) or ESDIRK5.
# OUT (default out/esdirk) keeps the decks and runs; the reference (two elements of order 8
# per bar, HHT at h = 3.90625e-6 s, as benches/order_ratio.sh makes it) is made once and
# reused. HHT runs at h = 1.5625e-5 s (the step decks/pendulum_converged.dat needs for
# 1e-3 m), ESDIRK3 at ESDIRK_STEP (default 3.90625e-5 s) with output every EVERY steps
# (default 2): the output interval must stay 7.8125e-5 s, the instants compared. CPU is
# user seconds (/usr/bin/time), less sensitive to the shared machine's load than wall time.
# Needs a release build (cargo build --release) and python3 (standard library only).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/esdirk}
rounds=${2:-3}
he=${3:-3.90625e-5}
every=${4:-2}
scheme=${5:-ESDIRK3}
bin=target/release/mecano-rs
mkdir -p "$out"

# A flexible1 deck with each bar ONE beam card `DIVIDE d ORDER p`, step h, output every k
# steps, and the integrator's ANALYSIS keywords.
mk() { # name divide order step every integrator
  sed -e "s/^  2 TO 12 LINE  0 0 0   1 0 0/  2 0 0 0\n  12 1 0 0/" \
    -e "s/^  13 TO 23 LINE  1 0 0   1.8660254037844386 0 0.5/  13 1 0 0\n  23 1.8660254037844386 0 0.5/" \
    -e "s/^  2 TO 11  BEAM 2 3  MAT 1 SEC 1/  2 BEAM 2 12 MAT 1 SEC 1 DIVIDE $2 ORDER $3/" \
    -e "s/^  13 TO 22 BEAM 13 14  MAT 1 SEC 1/  13 BEAM 13 23 MAT 1 SEC 1 DIVIDE $2 ORDER $3/" \
    -e "s/ALPHA -0.1 STEP 1e-4 END 2.0/$6 STEP $4 END 1.5/" -e "s/EVERY 10/EVERY $5/" \
    decks/pendulum_flexible1.dat >"$out/$1.dat"
}
mk ref 2 8 3.90625e-6 20 "ALPHA -0.1"
mk hht 1 8 1.5625e-5 5 "ALPHA -0.1"
mk esdirk 1 8 "$he" "$every" "$scheme"

[ -f "$out/out_ref/summary.json" ] || "$bin" "$out/ref.dat" -o "$out/out_ref" --quiet --checkpoint 0
user() { /usr/bin/time -f %U "$@" 2>&1 >/dev/null | tail -1; }
a=() b=()
for r in $(seq 1 "$rounds"); do
  a+=("$(user "$bin" "$out/hht.dat" -o "$out/out_hht" --quiet --checkpoint 0 --force)")
  b+=("$(user "$bin" "$out/esdirk.dat" -o "$out/out_esdirk" --quiet --checkpoint 0 --force)")
  echo "round $r: HHT ${a[-1]} s, $scheme ${b[-1]} s (user CPU)"
done
python3 benches/order_study.py "$out" ref hht esdirk
for d in hht esdirk; do
  python3 -c "import json,sys; s=json.load(open(sys.argv[1]))['stats']; print(sys.argv[2], 'steps', s['steps'], 'Newton', s['newton_iterations'], 'factorisations', s['factorizations'], 'rejected', s['rejected_steps'], 'restarts', s['restarts'])" "$out/out_$d/summary.json" "$d"
done
python3 - "${a[*]}" "${b[*]}" "$scheme" <<'PY'
import statistics, sys
a = [float(x) for x in sys.argv[1].split()]
b = [float(x) for x in sys.argv[2].split()]
n = sys.argv[3]
print(f"user CPU HHT: best {min(a):.2f} s, median {statistics.median(a):.2f} s; "
      f"{n}: best {min(b):.2f} s, median {statistics.median(b):.2f} s")
print(f"{n}/HHT: best/best {min(b) / min(a):.3f}, median/median {statistics.median(b) / statistics.median(a):.3f}, "
      f"per round {', '.join(f'{y / x:.3f}' for x, y in zip(a, b))}")
PY
