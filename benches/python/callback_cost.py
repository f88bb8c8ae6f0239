"""Issue 36 target: a Python law costs at most 2 µs per call on top of the user's own code.

The arm of decks/pd_arm.dat without its deck PID, held up against gravity by a constant
hinge torque (9.81 N·m: it stays at rest, so every variant takes the same Newton
iterations), run for N steps in a `mecano.Simulation`:
  * held:           add_input(hinge=1, value=9.81): the built-in input, no Python call;
  * differentiated: a law `lambda t, s: 9.81` with sensors [("angle", 1)], called at every
                    Newton iterate and once more per sensor when the matrix is rebuilt;
  * explicit:       a law `lambda t, sim: 9.81`, tangent="explicit", once per step.
The calls are counted in a separate run (a counting law), so that the timed law is the
constant lambda alone. Cost per call on top of the user's code =
  (CPU(law) − CPU(held)) / calls − CPU of the lambda itself called from Python
(the last measured by timeit with the same arguments). Each variant REPEAT times,
interleaved, minimum kept. Needs a release wheel (`pip install ./python`).

    python benches/python/callback_cost.py [--steps 100000] [--repeat 3]
"""

import argparse
import timeit

import mecano

from common import ROOT, Measure, header, load

HOLD = 9.81


def deck(steps):
    text = (ROOT / "decks" / "pd_arm.dat").read_text()
    text = text.replace("  3  PID 1 KP $KP KD $KD TARGET 1 AMPLITUDE $A\n", "")
    text = text.replace("ELEMENTS 1 3", "ELEMENTS 1")
    return mecano.Deck(text, name="pd_arm.dat").with_parameters(H=1.0 / steps)


def simulate(d, kind, law=None):
    sim = mecano.Simulation(d)
    if kind == "held":
        sim.add_input(hinge=1, value=HOLD)
    elif kind == "differentiated":
        sim.add_input(hinge=1, law=law or (lambda t, s: HOLD), sensors=[("angle", 1)])
    else:
        sim.add_input(hinge=1, law=law or (lambda t, sim: HOLD), tangent="explicit")
    sim.t  # started: the preparation is not what is measured
    with Measure() as m:
        sim.advance(1.0)
    stats = sim.run().summary["stats"]
    return m.cpu, stats


def count_calls(d, kind):
    n = [0]

    def law(t, s):
        n[0] += 1
        return HOLD

    _, stats = simulate(d, kind, law)
    return n[0], stats


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    header(f"Python law's cost per call, pd_arm held at rest, {a.steps} steps")
    d = deck(a.steps)
    kinds = ["held", "differentiated", "explicit"]
    cpu = {k: [] for k in kinds}
    iters = {}
    for r in range(a.repeat):
        for k in kinds:
            c, stats = simulate(d, k)
            cpu[k].append(c)
            iters[k] = (stats["steps"], stats["newton_iterations"])
        print("  round", r + 1, ", ".join(f"{k} {cpu[k][-1]:.3f} s" for k in kinds))
    # The user's code alone: the constant lambda called from Python with its arguments.
    f = lambda t, s: HOLD  # noqa: E731
    user = min(timeit.repeat(lambda: f(0.5, None), number=200_000, repeat=5)) / 200_000
    base = min(cpu["held"])
    print(f"steps, Newton iterations: {iters}")
    print(f"held (no Python call)     min {base:.3f} s CPU")
    print(f"the lambda alone, from Python: {user * 1e9:.0f} ns per call")
    for k in ("differentiated", "explicit"):
        calls, stats = count_calls(d, k)
        extra = min(cpu[k]) - base
        per = extra / calls - user
        print(f"{k:15s} min {min(cpu[k]):.3f} s CPU, {calls} calls "
              f"({calls / stats['steps']:.2f} per step): {extra / calls * 1e6:.2f} µs per call, "
              f"{per * 1e6:.2f} µs on top of the user's code")
        if iters[k] != iters["held"]:
            # The subtraction holds only for the same solver path.
            print(f"  (not comparable: {k} took {iters[k]} steps and Newton iterations, "
                  f"held {iters['held']}; its whole run is "
                  f"{min(cpu[k]) / stats['steps'] * 1e6:.2f} µs CPU per step, law included)")
    (l1, l5, l15), n = load()
    print(f"# load average {l1:.2f} {l5:.2f} {l15:.2f} on {n} cores (after)")


if __name__ == "__main__":
    main()
