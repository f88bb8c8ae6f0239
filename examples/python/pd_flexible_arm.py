"""A PD-controlled flexible arm: a hinged beam (decks/rotating_cantilever.dat's blade,
on its hub's HINGE) whose hub torque tracks a smooth swing
theta_ref(t) = A (1 - cos(w t)) / 2 with T = kp (theta_ref - theta) + kd (rate_ref - rate),
the law evaluated inside each step with its derivative (tangent="differentiated").
Prints the tracking error at the hub and the tip's lag.

    python examples/python/pd_flexible_arm.py
"""
import math
import pathlib

import mecano

root = pathlib.Path(__file__).resolve().parents[2]
deck = mecano.Deck.read(root / "decks" / "pd_flexible_arm.dat")
A, w, kp, kd = 0.8, 2.0, 20.0, 2.0


def law(t, s):
    ref = A * (1 - math.cos(w * t)) / 2
    rate = A * w * math.sin(w * t) / 2
    return kp * (ref - s.joint_angle(1)) + kd * (rate - s.joint_rate(1))


sim = mecano.Simulation(deck)
sim.add_input(hinge=1, law=law, sensors=[("angle", 1), ("rate", 1)])
worst = 0.0
while sim.t < 3.0 - 1e-9:
    sim.advance(sim.t + 0.05)
    ref = A * (1 - math.cos(w * sim.t)) / 2
    worst = max(worst, abs(sim.joint_angle(1) - ref))
    tip = sim.position(12)
    print(f"t = {sim.t:4.2f} s  hub {sim.joint_angle(1):+.4f} rad  ref {ref:+.4f}  "
          f"tip angle {math.atan2(tip[1], tip[0]):+.4f} rad")
print(f"largest hub tracking error: {worst:.2e} rad")
