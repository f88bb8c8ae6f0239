#!/usr/bin/env bash
# Proof of no behaviour change (issue 27 §2): runs two mecano-rs binaries on the same
# cases and diffs every output file byte for byte.
#
#   scripts/identical_outputs.sh OLD_BINARY NEW_BINARY [WORKDIR]
#
# e.g. build main and the branch in release, copy each target/release/mecano-rs aside,
# and pass both. Cases (a few minutes on 2 cores): decks/pendulum_short.dat (flexible,
# through the impact) and decks/pendulum_rigid.dat cut to 0.6 s, `plot trajectory` and
# `plot history` (SVG and PNG) and `plot animate`, `compare` (its report, and exit code), a
# `study` quick case, and the sweep sweeps/bounce.toml (cases, sweep.csv, statistics.csv,
# figures). Excluded: CPU and wall times (summary.json's timing fields, the study's CPU
# columns and its work-precision diagram, whose x axis is CPU time; the sweep's timing
# columns and the figures of the sweeps' `cpu` quantity), which differ between any two runs.
# Exit 0 when every other file is identical. REUSE=1 compares the outputs already in WORKDIR.
set -u
old=$(realpath "$1"); new=$(realpath "$2")
work=${3:-$(mktemp -d /tmp/identical_outputs.XXXXXX)}
repo=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
run_all() { # $1 binary, $2 out root
  local b=$1 o=$2
  rm -rf "$o"; mkdir -p "$o"
  cd "$repo"
  "$b" -q --checkpoint 0 decks/pendulum_short.dat -o "$o/short" > "$o/short.stdout" 2>&1; echo "run short: $?" >> "$o/codes"
  sed 's/END 2.0/END 0.6/' decks/pendulum_rigid.dat > "$o/rigid.dat"
  "$b" -q --checkpoint 0 "$o/rigid.dat" -o "$o/rigid" > "$o/rigid.stdout" 2>&1; echo "run rigid: $?" >> "$o/codes"
  "$b" plot trajectory "$o/short" "$o/rigid" --nodes 12 23 -o "$o/plots/trajectory.svg" >> "$o/plots.stdout" 2>&1; echo "plot trajectory svg: $?" >> "$o/codes"
  "$b" plot trajectory "$o/short" --nodes 23 -o "$o/plots/trajectory.png" >> "$o/plots.stdout" 2>&1; echo "plot trajectory png: $?" >> "$o/codes"
  "$b" plot history "$o/short" "$o/rigid" --node 23 --columns rx,vy,ay -o "$o/plots/history.svg" >> "$o/plots.stdout" 2>&1; echo "plot history svg: $?" >> "$o/codes"
  "$b" plot history "$o/short" --node 23 --columns y -o "$o/plots/history.png" >> "$o/plots.stdout" 2>&1; echo "plot history png: $?" >> "$o/codes"
  sed -e 's/END 0.6/END 0.2/' -e 's/^OUTPUT NODES 2 12 23/OUTPUT NODES ALL/' decks/pendulum_short.dat > "$o/all.dat"
  "$b" -q --checkpoint 0 "$o/all.dat" -o "$o/all" > "$o/all.stdout" 2>&1; echo "run all nodes: $?" >> "$o/codes"
  "$b" plot animate "$o/all" --frames 20 -o "$o/plots/animate.gif" >> "$o/plots.stdout" 2>&1; echo "plot animate: $?" >> "$o/codes"
  "$b" compare "$o/short" "$o/rigid" > "$o/compare.stdout" 2>&1; echo "compare: $?" >> "$o/codes"
  "$b" compare "$o/short" "$o/rigid" --tol 1e-3 > "$o/compare_tol.stdout" 2>&1; echo "compare --tol: $?" >> "$o/codes"
  "$b" study decks/pendulum_short.dat --steps 4e-4,2e-4,1e-4 --until 0.2 -o "$o/study" > "$o/study.stdout" 2>&1; echo "study: $?" >> "$o/codes"
  cp sweeps/bounce.toml "$o/bounce.toml"; sed -i "s|\.\./decks/|$repo/decks/|" "$o/bounce.toml"
  "$b" sweep "$o/bounce.toml" -o "$o/sweep" -j 1 --quiet > "$o/sweep.stdout" 2>&1; echo "sweep: $?" >> "$o/codes"
  # A 1-D sweep draws figures (quantity against k, SVG and PNG): bounce.toml without zeta.
  python3 -c 'import re,sys; t=open(sys.argv[1]).read(); open(sys.argv[2],"w").write(re.sub(r"\[\[parameter\]\]\nname = \"zeta\"\nvalues = \[[^]]*\]\n", "", t))' "$o/bounce.toml" "$o/bounce_1d.toml"
  "$b" sweep "$o/bounce_1d.toml" -o "$o/sweep_1d" -j 1 --quiet > "$o/sweep_1d.stdout" 2>&1; echo "sweep 1-D: $?" >> "$o/codes"
}
# Both binaries run in the same directory ($work/run), so paths written into files agree.
if [ "${REUSE:-0}" = 1 ] && [ -d "$work/old" ] && [ -d "$work/new" ]; then
  echo "reusing the outputs in $work"
else
echo "old: $old"; run_all "$old" "$work/run"; rm -rf "$work/old"; mv "$work/run" "$work/old"
echo "new: $new"; run_all "$new" "$work/run"; rm -rf "$work/new"; mv "$work/run" "$work/new"
fi
# Normalise what is timing, then compare everything else byte for byte.
norm() { # file -> stdout: timing fields and columns replaced by T
  python3 - "$1" <<'PY'
import csv, io, json, re, sys
p = sys.argv[1]
timing = lambda k: re.search(r"cpu|wall|seconds|elapsed", k) is not None
text = open(p, encoding="utf-8", errors="replace").read()
if p.endswith(".json"):
    def scrub(v):
        if isinstance(v, dict):
            names = v.get("quantity_names")
            out = {k: ("T" if timing(k) else scrub(x)) for k, x in v.items()}
            if names and isinstance(v.get("quantities"), list):
                out["quantities"] = ["T" if timing(n) else q for n, q in zip(names, v["quantities"])]
            return out
        return [scrub(x) for x in v] if isinstance(v, list) else v
    print(json.dumps(scrub(json.loads(text)), sort_keys=True))
elif p.endswith(".csv") and "/sweep" in p:
    rows = list(csv.reader(io.StringIO(text)))
    keep = [i for i, h in enumerate(rows[0]) if not timing(h)] if rows else []
    for r in rows:
        if r and timing(r[0]):
            continue  # statistics.csv: the row of a timing quantity
        print(",".join(r[i] for i in keep if i < len(r)))
elif p.endswith(".stdout"):
    print(re.sub(r"[0-9.]+(e-?[0-9]+)? ?(s|ms|µs)\b", "T", text))
else:
    sys.stdout.write(text)
PY
}
status=0; n=0; skipped=0; timing=0
while IFS= read -r f; do
  rel=${f#"$work/old/"}
  case "$rel" in
    study/*|study.stdout) skipped=$((skipped+1)); continue ;;
    sweep*/figures/cpu_*) timing=$((timing+1)); continue ;;  # a figure of the CPU time quantity
  esac
  n=$((n+1))
  if [ ! -e "$work/new/$rel" ]; then echo "MISSING in new: $rel"; status=1; continue; fi
  if ! cmp -s <(norm "$f") <(norm "$work/new/$rel"); then echo "DIFFERS: $rel"; status=1; fi
done < <(find "$work/old" -type f | sort)
extra=$(cd "$work/new" && find . -type f | sed 's|^\./||' | sort | while read -r r; do [ -e "$work/old/$r" ] || echo "$r"; done)
[ -n "$extra" ] && { echo "ONLY in new: $extra"; status=1; }
echo "exit codes (old):"; sed 's/^/  /' "$work/old/codes"
echo "$n files compared byte for byte (timing fields normalised), $skipped study files checked separately, $timing figures of CPU time not compared"
# The study: its tables carry CPU times; compare the columns that are not timing.
for f in study.csv study_windows.csv; do
  if [ -e "$work/old/study/$f" ]; then
    h=$(head -1 "$work/old/study/$f")
    cols=$(echo "$h" | tr ',' '\n' | grep -n -v -i -E 'cpu|wall|time_s|seconds' | cut -d: -f1 | paste -sd,)
    if cmp -s <(cut -d, -f"$cols" "$work/old/study/$f") <(cut -d, -f"$cols" "$work/new/study/$f"); then
      echo "study/$f: identical but for CPU columns"
    else echo "DIFFERS: study/$f (non-CPU columns)"; status=1; fi
  fi
done
[ $status = 0 ] && echo "IDENTICAL" || echo "DIFFERENCES FOUND ($work)"
exit $status
