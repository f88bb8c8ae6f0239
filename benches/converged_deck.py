#!/usr/bin/env python3
"""Error of runs of the seed scene against a reference run whose output instants need not be
theirs (docs/accuracy.md, "The cheapest configuration for 1e-3 m"): the reference's
positions of nodes 12 and 23 are interpolated at each run's output instants by cubic
Hermite interpolation of its positions and velocities (interpolation error h^4 |x''''|/384:
for the 346 Hz bar mode at the reference's output interval 7.8125e-5 s, 2e-6 of that mode's
amplitude), and the largest distance per 0.25 s window up to 1.5 s is printed with the
run's steps, Newton iterations and factorisations (summary.json).

    python3 benches/converged_deck.py REF_DIR RUN_DIR [RUN_DIR ...]

Standard library only.
"""
import bisect
import csv
import json
import sys

NODES = (12, 23)
WINDOWS = [(0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 1.0), (1.0, 1.25), (1.25, 1.5)]


def load(d, n):
    t, x, v = [], [], []
    with open(f"{d}/node_{n}.csv") as f:
        for row in csv.DictReader(f):
            t.append(float(row["t"]))
            x.append([float(row[k]) for k in ("x", "y", "z")])
            v.append([float(row[k]) for k in ("vx", "vy", "vz")])
    return t, x, v


def hermite(ref, t):
    """The reference at time t (cubic Hermite between its two neighbouring outputs)."""
    ts, xs, vs = ref
    i = bisect.bisect_left(ts, t)
    if i < len(ts) and abs(ts[i] - t) <= 1e-9:
        return xs[i]
    if i == 0 or i >= len(ts):
        return None
    t0, t1 = ts[i - 1], ts[i]
    h = t1 - t0
    s = (t - t0) / h
    h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
    h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
    return [
        h00 * a + h10 * h * va + h01 * b + h11 * h * vb
        for a, va, b, vb in zip(xs[i - 1], vs[i - 1], xs[i], vs[i])
    ]


def main():
    ref_dir, runs = sys.argv[1], sys.argv[2:]
    ref = {n: load(ref_dir, n) for n in NODES}
    print("run", *[f"{a}-{b} s" for a, b in WINDOWS], "max", "steps", "Newton", "factorisations",
          sep="\t")
    for d in runs:
        errs = [0.0] * len(WINDOWS)
        for n in NODES:
            ts, xs, _ = load(d, n)
            for t, x in zip(ts, xs):
                if t > 1.5 + 1e-9:
                    continue
                r = hermite(ref[n], t)
                if r is None:
                    continue
                e = sum((a - b) ** 2 for a, b in zip(x, r)) ** 0.5
                for i, (a, b) in enumerate(WINDOWS):
                    if a <= t <= b + 1e-12:
                        errs[i] = max(errs[i], e)
        s = json.load(open(f"{d}/summary.json"))["stats"]
        print(d.rstrip("/").split("/")[-1], *[f"{e:.2e}" for e in errs], f"{max(errs):.2e}",
              s["steps"], s["newton_iterations"], s["factorizations"], sep="\t")


if __name__ == "__main__":
    main()
