#!/usr/bin/env python3
"""Beams of order p against two-node beams on the seed scene (docs/accuracy.md, "Beams of
order p"): position error of nodes 12 and 23 per 0.25 s window up to 1.5 s, against a
reference run, and the CPU seconds of each run (from summary.json).

    python3 benches/order_study.py OUT REF RUN [RUN ...]

OUT holds one output directory per run (out_<name>, as written by
`mecano-rs <name>.dat -o OUT/out_<name>`); the runs must write nodes 12 and 23 at common
instants (OUTPUT ... EVERY chosen so that the output interval is the same). The decks are
made by `mecano::scenes::pendulum_order_deck(divide, order, ..)` or, equivalently, from
decks/pendulum_flexible1.dat with each bar one BEAM card `DIVIDE d ORDER p` (the shell
loop in docs/accuracy.md). Standard library only.
"""
import csv
import json
import os
import sys


def load(d, n):
    out = {}
    with open(f"{d}/node_{n}.csv") as f:
        for row in csv.DictReader(f):
            out[round(float(row["t"]), 9)] = (float(row["x"]), float(row["y"]), float(row["z"]))
    return out


def main():
    base, ref, runs = sys.argv[1], sys.argv[2], sys.argv[3:]
    r = {n: load(f"{base}/out_{ref}", n) for n in (12, 23)}
    wins = [(0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 1.0), (1.0, 1.25), (1.25, 1.5)]
    print("run", *[f"{a}-{b} s" for a, b in wins], "max", "CPU s", "steps", sep="\t")
    for run in runs:
        d = f"{base}/out_{run}"
        if not os.path.exists(f"{d}/summary.json"):
            continue
        errs = [0.0] * len(wins)
        for n in (12, 23):
            for t, x in load(d, n).items():
                if t in r[n] and t <= 1.5 + 1e-9:
                    e = sum((a - b) ** 2 for a, b in zip(x, r[n][t])) ** 0.5
                    for i, (a, b) in enumerate(wins):
                        if a <= t <= b + 1e-12:
                            errs[i] = max(errs[i], e)
        s = json.load(open(f"{d}/summary.json"))["stats"]
        print(run, *[f"{e:.1e}" for e in errs], f"{max(errs):.1e}",
              f"{s['cpu_seconds']:.1f}", s["steps"], sep="\t")


if __name__ == "__main__":
    main()
