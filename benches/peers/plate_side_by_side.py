#!/usr/bin/env python3
"""The solid plate pendulum side by side: mecano-rs (decks/superelement/plate_solid_pendulum.dat)
against Exudyn's ObjectFFRFreducedOrder (plate_exudyn.py), fed the same K.mtx, M.mtx, nodes.csv
(issue 38's plate target; docs/superelements.md, "The plate against Exudyn").

    benches/peers/.venv/bin/python benches/peers/plate_side_by_side.py [--mecano PATH]

(a Python with exudyn 1.13.6 and scipy). For each fixed-interface mode count K in MODES and
each step h in STEPS (and h/2 for its error), both codes run the 0.3 s of the deck; the
compared quantity is the tip's path (the far corner's rigid patch, its centroid: mecano-rs's
node 2, Exudyn's MarkerSuperElementPosition over the same 8 nodes) sampled every 1e-3 s.

* D(K, h): the largest distance between the two codes' tip paths;
* E_c(K, h) = 4/3 max |x_c(h) - x_c(h/2)|: each code's own time error at h, by step halving
  (Richardson, both schemes are the trapezoidal rule, order 2);
* T_c(K) = max |x_c(K) - x_c(K_max)| at the smallest step: each code's modal truncation.

Exudyn runs twice: as shipped (its LoadMassProportional gives the frame the weight's moment
with the undeformed centre of mass) and with the deformation's moment added
(plate_exudyn.py --gravity-moment); D is the latter's distance, "D as shipped" the former's.

The two codes reduce on the same basis (the same two rigid interfaces, the same K
fixed-interface modes: the frequencies are printed), so the truncation is the same error in
both and their difference is bounded by the time errors alone: they agree when
D <= E_mecano + E_exudyn. The wider tolerance of issue 38 (time errors plus both
truncations) is printed beside it.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
import plate_exudyn  # noqa: E402

DECK = os.path.join(ROOT, "decks", "superelement", "plate_solid_pendulum.dat")
MODES = [2, 6, 12, 24]
STEPS = [1e-3, 5e-4, 2.5e-4, 1.25e-4, 6.25e-5]
PERIOD, TEND = 1e-3, 0.3


def run_mecano(exe, modes, h):
    with tempfile.TemporaryDirectory() as out:
        r = subprocess.run([exe, DECK, "--set", f"modes={modes}", "--set", f"h={h}", "-o", out, "--force"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"mecano-rs failed (modes {modes}, h {h}): {r.stderr}")
        d = np.loadtxt(os.path.join(out, "node_2.csv"), delimiter=",", skiprows=1, usecols=(0, 1, 2, 3))
    j = np.rint(d[:, 0] / PERIOD)
    d = d[np.abs(d[:, 0] - j * PERIOD) < 0.25 * h]
    return d


def dist(a, b):
    n = min(len(a), len(b))
    assert np.allclose(a[:n, 0], b[:n, 0], atol=1e-9) and n == int(round(TEND / PERIOD)) + 1
    return np.linalg.norm(a[:n, 1:] - b[:n, 1:], axis=1).max()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mecano", default=os.path.join(ROOT, "target", "release", "mecano-rs"))
    a = ap.parse_args()
    paths = {}
    for k in MODES:
        for h in STEPS:
            paths["mecano-rs", k, h] = run_mecano(a.mecano, k, h)
            for code, gm in (("exudyn", True), ("exudyn as shipped", False)):
                d, rec = plate_exudyn.run(k, h, TEND, gravity_moment=gm)
                if not rec["ok"]:
                    sys.exit(f"exudyn failed: {rec}")
                paths[code, k, h] = d
        print(f"K = {k}: fixed-interface modes (Exudyn's eigsh) {rec['fixed_interface_hz']} Hz", flush=True)
    ref = paths["mecano-rs", MODES[-1], STEPS[-1]]
    amp = np.linalg.norm(ref[:, 1:] - ref[0, 1:], axis=1).max()
    print(f"tip path amplitude (largest distance from its start over {TEND} s): {amp:.4f} m")
    hmin = STEPS[-1]
    trunc = {(c, k): dist(paths[c, k, hmin], paths[c, MODES[-1], hmin])
             for c in ("mecano-rs", "exudyn") for k in MODES}
    print()
    print("| modes | h (s) | D as shipped (m) | D (m) | D / amplitude | E mecano-rs | E Exudyn | "
          "E sum | D <= E sum | T mecano-rs | T Exudyn | E + T sum |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for k in MODES:
        for h, h2 in zip(STEPS[:-1], STEPS[1:]):
            d0 = dist(paths["mecano-rs", k, h], paths["exudyn as shipped", k, h])
            d = dist(paths["mecano-rs", k, h], paths["exudyn", k, h])
            em = 4 / 3 * dist(paths["mecano-rs", k, h], paths["mecano-rs", k, h2])
            ee = 4 / 3 * dist(paths["exudyn", k, h], paths["exudyn", k, h2])
            tm, te = trunc["mecano-rs", k], trunc["exudyn", k]
            print(f"| {k} | {h:g} | {d0:.2e} | {d:.2e} | {d / amp:.1e} | {em:.2e} | {ee:.2e} | {em + ee:.2e} | "
                  f"{'yes' if d <= em + ee else 'NO'} | {tm:.1e} | {te:.1e} | {em + ee + tm + te:.2e} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
