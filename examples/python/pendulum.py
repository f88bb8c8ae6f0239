"""The reference pendulum (decks/pendulum.dat): run it into memory and plot node 12's
trajectory and the energy balance with matplotlib (pip install matplotlib).

    python examples/python/pendulum.py        # writes pendulum.png
"""
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import mecano

root = pathlib.Path(__file__).resolve().parents[2]
run = mecano.run(root / "decks" / "pendulum.dat")
print(run, f"{run.summary['stats']['steps']} steps, {run.summary['stats']['cpu_seconds']:.2f} s CPU")
node = run.node(12)
energy = run.energy
fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
a.plot(node.x, node.z)
a.set_xlabel("x (m)")
a.set_ylabel("z (m)")
a.set_title("node 12")
b.plot(energy.t, energy.total, label="total")
b.plot(energy.t, energy.kinetic, label="kinetic")
b.set_xlabel("t (s)")
b.set_ylabel("J")
b.legend()
fig.tight_layout()
fig.savefig("pendulum.png", dpi=120)
