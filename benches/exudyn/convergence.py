#!/usr/bin/env python3
"""Exudyn's own convergence on the pendulum: max over each time window of the distance between
a node's position at step h and at the finest step (the reference).

Usage:
    python3 convergence.py REF.csv RUN1.csv [RUN2.csv ...] [--node 23] [--windows 0,0.5,1.0,1.5,2.0]

The CSVs are those written by pendulum_exudyn.py (t,x12,y12,z12,x23,y23,z23, t = k*1e-3 s);
a directory is read as a mecano-rs run's output (OUTPUT NODES 12 23 EVERY 1).
Prints a Markdown table, one row per run, one column per window (metres).
"""
import argparse
import os
import numpy as np


def load(path):
    """A CSV of pendulum_exudyn.py, or a mecano-rs output directory (its node_12.csv and
    node_23.csv, interpolated linearly onto t = k*1e-3 s: 2e-8 m at h <= 4e-5 s)."""
    if os.path.isdir(path):
        cols = []
        for n in (12, 23):
            h = np.genfromtxt(os.path.join(path, f"node_{n}.csv"), delimiter=",", names=True)
            if not cols:
                cols.append(np.arange(0, int(np.floor(h["t"][-1] * 1000 + 1e-9)) + 1) * 1e-3)
            cols += [np.interp(cols[0], h["t"], h[k]) for k in "xyz"]
        d = np.column_stack(cols)
    else:
        d = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return np.rint(d[:, 0] * 1000).astype(int), d


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("ref")
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--node", type=int, choices=[12, 23], default=23)
    ap.add_argument("--windows", default="0,0.5,1.0,1.5")
    a = ap.parse_args()
    col = {12: 1, 23: 4}[a.node]
    edges = [float(x) for x in a.windows.split(",")]
    kr, ref = load(a.ref)
    rmap = {k: i for i, k in enumerate(kr)}
    head = " | ".join(f"[{lo:g}, {hi:g}] s" for lo, hi in zip(edges[:-1], edges[1:]))
    print(f"node {a.node}, reference {a.ref}")
    print(f"| run | {head} |")
    print("|---" * len(edges) + "|")
    for path in a.runs:
        k, d = load(path)
        idx = np.array([rmap.get(x, -1) for x in k])
        ok = idx >= 0
        t = d[ok, 0]
        err = np.linalg.norm(d[ok, col:col + 3] - ref[idx[ok], col:col + 3], axis=1)
        cells = []
        for lo, hi in zip(edges[:-1], edges[1:]):
            w = (t >= lo - 1e-9) & (t <= hi + 1e-9)
            full = w.sum() == int(round((hi - lo) * 1000)) + 1
            cells.append(f"{err[w].max():.2e}" + ("" if full else " (partial)") if w.any() else "–")
        print(f"| {path} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
