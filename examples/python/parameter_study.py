"""A parameter study over every core: the pendulum's Young's modulus over a decade, four
runs at a time on a thread pool (the runs release the GIL), the largest |z| of node 12.

    python examples/python/parameter_study.py
"""
import pathlib
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import mecano

root = pathlib.Path(__file__).resolve().parents[2]
deck = mecano.Deck.read(root / "decks" / "pendulum_sweep.dat")
moduli = np.geomspace(2.1e10, 2.1e11, 8)
decks = [deck.with_parameters(E=e, T=0.5) for e in moduli]
with ThreadPoolExecutor() as pool:  # or: mecano.run_many(decks)
    runs = list(pool.map(mecano.run, decks))
for e, r in zip(moduli, runs):
    print(f"E = {e:.3e} Pa: max |z| of node 12 = {np.max(np.abs(r.node(12).z)):.4f} m")
