#!/usr/bin/env bash
# The cheapest integrator and step for decks/pendulum_converged.dat (issue 26, Done-when):
# candidates made from the deck itself by changing its ANALYSIS card (integrator, step) and
# its output interval, errors of nodes 12 and 23 against the space-time reference of
# benches/esdirk_ratio.sh (two elements of order 8 per bar, HHT at 3.90625e-6 s), user CPU of
# runs interleaved ROUNDS times (docs/accuracy.md, "The cheapest configuration for 1e-3 m").
#
#   benches/converged_deck.sh [OUT] [ROUNDS] [CANDIDATES...]
#
# A candidate is NAME:STEP:INTEGRATOR[:EVERY] with INTEGRATOR one of hht, ga0.8, ga0.9,
# esdirk (ESDIRK3), esdirk5 (default: the list below). Each candidate runs once with output every step (for its
# error: benches/converged_deck.py interpolates the reference at the run's instants) and
# ROUNDS times with output every EVERY steps (timed; default: 1e-3 s, which STEP must then
# divide; STEP must divide the END, 1.5 s). The reference is made once in OUT (as benches/esdirk_ratio.sh does) or
# taken from OUT/out_ref. Needs a release build and python3 (standard library only).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/converged}
rounds=${2:-2}
shift $(($# < 2 ? $# : 2))
cands=("$@")
[ ${#cands[@]} -gt 0 ] || cands=(
  hht16:1.5625e-5:hht hht20:2e-5:hht hht25:2.5e-5:hht
  ga8_16:1.5625e-5:ga0.8 ga8_20:2e-5:ga0.8 ga8_25:2.5e-5:ga0.8
  ga9_16:1.5625e-5:ga0.9 ga9_1875:1.875e-5:ga0.9:80 ga9_20:2e-5:ga0.9 ga9_25:2.5e-5:ga0.9
  es25:2.5e-5:esdirk es31:3.125e-5:esdirk es40:4e-5:esdirk
  es5_3125:3.125e-4:esdirk5:4 es5_3906:3.90625e-4:esdirk5:4 es5_4688:4.6875e-4:esdirk5:4
)
bin=target/release/mecano-rs
mkdir -p "$out"
deck=decks/pendulum_converged.dat
# The reference (flexible1, two elements of order 8 per bar, HHT at 3.90625e-6 s, output
# every 7.8125e-5 s), as benches/esdirk_ratio.sh makes it.
if [ ! -f "$out/out_ref/summary.json" ]; then
  sed -e "s/^  2 TO 12 LINE  0 0 0   1 0 0/  2 0 0 0\n  12 1 0 0/" \
    -e "s/^  13 TO 23 LINE  1 0 0   1.8660254037844386 0 0.5/  13 1 0 0\n  23 1.8660254037844386 0 0.5/" \
    -e "s/^  2 TO 11  BEAM 2 3  MAT 1 SEC 1/  2 BEAM 2 12 MAT 1 SEC 1 DIVIDE 2 ORDER 8/" \
    -e "s/^  13 TO 22 BEAM 13 14  MAT 1 SEC 1/  13 BEAM 13 23 MAT 1 SEC 1 DIVIDE 2 ORDER 8/" \
    -e "s/ALPHA -0.1 STEP 1e-4 END 2.0/ALPHA -0.1 STEP 3.90625e-6 END 1.5/" -e "s/EVERY 10/EVERY 20/" \
    decks/pendulum_flexible1.dat >"$out/ref.dat"
  "$bin" "$out/ref.dat" -o "$out/out_ref" --quiet --checkpoint 0
fi
mk() { # name step integrator every suffix
  local card
  case $3 in
    hht) card="ALPHA -0.1" ;;
    ga*) card="GENALPHA RHOINF ${3#ga}" ;;
    esdirk) card="ESDIRK3" ;;
    esdirk5) card="ESDIRK5" ;;
    *) echo "unknown integrator $3" >&2; exit 2 ;;
  esac
  sed -e "s/^ANALYSIS DYNAMIC .*/ANALYSIS DYNAMIC $card STEP $2 END 1.5/" \
    -e "s/^\(OUTPUT .*\) EVERY [0-9]*/\1 EVERY $4/" "$deck" >"$out/$1$5.dat"
}
user() { /usr/bin/time -f %U "$@" 2>&1 >/dev/null | tail -1; }
runs=()
for c in "${cands[@]}"; do
  IFS=: read -r name step integ every <<<"$c"
  [ -n "$every" ] || every=$(python3 -c "import sys; k=1e-3/float(sys.argv[1]); assert abs(k-round(k))<1e-9, 'step must divide 1e-3 s'; print(round(k))" "$step")
  mk "$name" "$step" "$integ" 1 _dense
  mk "$name" "$step" "$integ" "$every" ""
  [ -f "$out/out_${name}_dense/summary.json" ] ||
    "$bin" "$out/${name}_dense.dat" -o "$out/out_${name}_dense" --quiet --checkpoint 0 --force
  runs+=("$out/out_${name}_dense")
done
python3 benches/converged_deck.py "$out/out_ref" "${runs[@]}"
for r in $(seq 1 "$rounds"); do
  line="round $r:"
  for c in "${cands[@]}"; do
    IFS=: read -r name _ _ _ <<<"$c"
    line="$line $name $(user "$bin" "$out/$name.dat" -o "$out/out_$name" --quiet --checkpoint 0 --force)"
  done
  echo "$line (user CPU s)"
done
