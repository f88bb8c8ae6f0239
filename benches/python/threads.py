"""Issue 36 target: four threads running four decks give at least 1.8 times the throughput
of one thread on a 2-core machine, with histories identical to serial runs.

Four copies of decks/pendulum.dat with different Young's moduli (E × 1, 0.9, 0.8, 0.7:
four different runs of about the same cost) are run
  * one after the other on one thread (`mecano.run_many(decks, threads=1)`), and
  * on four threads (`mecano.run_many(decks, threads=4)`; the GIL is released),
REPEAT times, interleaved; throughput ratio = wall(1 thread) / wall(4 threads), each the
minimum of its repeats. The process's CPU seconds are reported too: on a machine other
work shares, the wall-time ratio is bounded by the cores left free, and CPU(4) ≈ CPU(1)
shows the threads do not cost more work. The histories of the threaded runs are
compared with the serial ones, every node, element and the energy, bit for bit.
Needs a release wheel (`pip install ./python`).

    python benches/python/threads.py [--repeat 3] [--threads 4]
"""

import argparse

import numpy as np

import mecano

from common import ROOT, Measure, header, load


def same(a, b):
    if a.nodes != b.nodes or a.elements != b.elements:
        return False
    return (
        all(np.array_equal(a.node(n).array, b.node(n).array) for n in a.nodes)
        and all(np.array_equal(a.element(e).array, b.element(e).array) for e in a.elements)
        and np.array_equal(a.energy.array, b.energy.array)
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=4)
    a = ap.parse_args()
    header(f"{a.threads} decks on 1 thread vs {a.threads} threads")
    base = mecano.Deck.read(ROOT / "decks" / "pendulum_sweep.dat")
    e0 = base.parameters["E"]
    decks = [base.with_parameters(E=e0 * (1 - 0.1 * k)) for k in range(a.threads)]
    one, many = [], []
    for r in range(a.repeat):
        with Measure() as m1:
            serial = mecano.run_many(decks, threads=1)
        one.append((m1.wall, m1.cpu))
        with Measure() as mn:
            threaded = mecano.run_many(decks, threads=a.threads)
        many.append((mn.wall, mn.cpu))
        ok = all(same(s, t) for s, t in zip(serial, threaded))
        print(f"  round {r + 1}: 1 thread {m1.wall:.3f} s wall {m1.cpu:.3f} s CPU; "
              f"{a.threads} threads {mn.wall:.3f} s wall {mn.cpu:.3f} s CPU; "
              f"histories identical: {ok}")
        assert ok, "threaded histories differ from the serial ones"
        assert all(s.complete for s in serial)
    w1, wn = min(x[0] for x in one), min(x[0] for x in many)
    c1, cn = min(x[1] for x in one), min(x[1] for x in many)
    print(f"1 thread : min {w1:.3f} s wall, {c1:.3f} s CPU")
    print(f"{a.threads} threads: min {wn:.3f} s wall, {cn:.3f} s CPU")
    print(f"throughput ratio (wall) {w1 / wn:.2f}x; CPU ratio {cn / c1:.2f}")
    (l1, l5, l15), n = load()
    print(f"# load average {l1:.2f} {l5:.2f} {l15:.2f} on {n} cores (after)")


if __name__ == "__main__":
    main()
