#!/usr/bin/env python3
"""Where the error of fixed-step runs after the impact lives: in time and in frequency.

Takes the output directories of three runs of one deck at steps h, h/2, h/4 (every step
written for the node, `OUTPUT NODES 23 EVERY 1`) and compares them at the instants of the
coarsest run:
- per 0.125 s window, the largest |x(h) - x(h/2)| and |x(h/2) - x(h/4)| (m) and their
  ratio (4 for order 2, 2 for order 1): how the error grows in time and converges;
- per window 0.6-1 s and 1-1.5 s, the frequency where the difference peaks above 50 Hz
  and the share of its power above 50 Hz (Hann window): bar vibration or the swing itself.

Commands in docs/accuracy.md ("Where the error after the impact lives"). Needs numpy.
"""
import sys

import numpy as np


def load(d, node):
    return np.loadtxt(f"{d}/node_{node}.csv", delimiter=",", skiprows=1, usecols=(0, 1, 2, 3))


def main():
    if len(sys.argv) < 4:
        sys.exit("usage: error_spectrum.py DIR_h DIR_h/2 DIR_h/4 [NODE=23]")
    node = int(sys.argv[4]) if len(sys.argv) > 4 else 23
    runs = [load(d, node) for d in sys.argv[1:4]]
    base = runs[0]
    n = len(base)
    same = [base] + [r[:: 2**k][:n] for k, r in enumerate(runs[1:], 1)]
    for r in same:
        if len(r) < n or not np.allclose(r[:, 0], base[:, 0], atol=1e-9):
            sys.exit("the runs must be at h, h/2, h/4 with a row at every step")
    t = base[:, 0]
    dt = t[1] - t[0]
    d1 = same[0][:, 1:] - same[1][:, 1:]
    d2 = same[1][:, 1:] - same[2][:, 1:]
    e1, e2 = np.linalg.norm(d1, axis=1), np.linalg.norm(d2, axis=1)
    print(f"node {node}, h = {dt:.4g} s")
    print("window (s)   |x(h)-x(h/2)|  |x(h/2)-x(h/4)|  ratio")
    for w0 in np.arange(0.0, t[-1] - 1e-9, 0.125):
        m = (t >= w0) & (t < w0 + 0.125)
        if m.sum() == 0:
            continue
        a, b = e1[m].max(), e2[m].max()
        print(f"{w0:5.3f}        {a:.2e}       {b:.2e}        {a / b if b > 0 else float('nan'):.2f}")
    for name, d in (("x(h)-x(h/2)", d1), ("x(h/2)-x(h/4)", d2)):
        for lo, hi in ((0.6, 1.0), (1.0, 1.5)):
            m = (t >= lo) & (t < hi)
            if m.sum() < 16:
                continue
            parts = []
            for c in range(3):
                s = d[m, c] - d[m, c].mean()
                spec = np.abs(np.fft.rfft(s * np.hanning(len(s))))
                f = np.fft.rfftfreq(len(s), dt)
                power = spec**2
                share = power[f > 50].sum() / power.sum()
                peak = f[np.argmax(spec * (f > 50))]
                parts.append(f"{'xyz'[c]}: peak {peak:.0f} Hz, {share * 100:.0f} % above 50 Hz")
            print(f"{name}, {lo}-{hi} s: " + "; ".join(parts))


if __name__ == "__main__":
    main()
