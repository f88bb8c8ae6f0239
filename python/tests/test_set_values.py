"""A deck's own loads and drivers set between steps (Simulation.set_load, set_drive),
each against a solution computed here: a mass on a spring whose load is switched at a
known time (closed form), and a driven arm sent to a new angle (the quintic of six end
conditions solved here by numpy, and the torque it takes, J times its acceleration)."""

import json
import math

import numpy as np
import pytest

import mecano

M, K, F0, F1, TS = 1.0, 100.0, 1.0, 3.0, 0.3
OMEGA = math.sqrt(K / M)

SPRING = """TITLE mass on a spring, its load switched from Python
NODES
  1 0 0 0 FIX ALL
  2 1 0 0 FIX Y Z ROT
ELEMENTS
  1 SPRING 1 2 K {k}
  2 MASS 2 M {m}
LOADS
  FORCE 2 {f0} 0 0
ANALYSIS DYNAMIC ALPHA 0 STEP {h} END 1
OUTPUT NODES 2 EVERY 1
END
"""


def spring(h):
    return mecano.Deck(SPRING.format(k=K, m=M, f0=F0, h=h), name="spring.dat")


def closed_form(t):
    """m x'' + k x = F0 before TS, F1 after; from rest at x = 0."""
    if t <= TS:
        return F0 / K * (1 - math.cos(OMEGA * t))
    x_s = F0 / K * (1 - math.cos(OMEGA * TS))
    v_s = F0 / K * OMEGA * math.sin(OMEGA * TS)
    s = t - TS
    return F1 / K + (x_s - F1 / K) * math.cos(OMEGA * s) + v_s / OMEGA * math.sin(OMEGA * s)


def switched(h, end=1.0):
    sim = mecano.Simulation(spring(h))
    sim.advance(TS)
    sim.set_load(1, F1)  # the card's (1, 0, 0) times 3: 3 N from TS on
    sim.advance(end)
    return sim


def test_a_load_switched_between_steps_follows_the_closed_form():
    """The trapezoidal rule (HHT with alpha = 0) on an undamped oscillator has the phase
    error omega^3 h^2 t / 12 and no amplitude error, so |x - x_exact| is at most the
    amplitude (F0 + F1)/k times it; the accelerations restart at the switch, so the
    order stays 2 across it (a step straddling the jump would be first order)."""
    errors = []
    for h in (2e-3, 1e-3):
        sim = switched(h)
        run = sim.run()
        x = run.node(2)["ux"]
        t = run.node(2).t
        err = max(abs(xi - closed_form(ti)) for ti, xi in zip(t, x))
        bound = (F0 + F1) / K * OMEGA**3 * h**2 * 1.0 / 12
        assert err <= bound, (h, err, bound)
        errors.append(err)
    order = math.log2(errors[0] / errors[1])
    assert 1.9 < order < 2.1, (errors, order)


def test_a_load_given_back_its_function_and_bad_numbers():
    sim = mecano.Simulation(spring(1e-3))
    sim.set_load(1, 0.0)
    sim.advance(0.1)
    assert sim.position(2)[0] == pytest.approx(1.0, abs=1e-14)  # no load: at rest
    sim.set_load(1, None)  # the card's constant 1 N again
    sim.advance(0.2)
    assert sim.position(2)[0] > 1.0
    with pytest.raises(KeyError, match="no load 2"):
        sim.set_load(2, 1.0)
    with pytest.raises(KeyError):
        sim.set_load(0, 1.0)
    with pytest.raises(ValueError):
        sim.set_load(1, float("nan"))
    with pytest.raises(ValueError, match="without a driver"):
        sim.set_drive(1, 0.1, over=1.0)  # a SPRING


def test_a_load_set_before_the_first_step_is_the_first_rows_state():
    """Set at t = 0, the load's acceleration F/m is the first row's (issue 36 §5 and the
    held input's t = 0 row)."""
    sim = mecano.Simulation(spring(1e-3))
    sim.set_load(1, 2.0)
    sim.step()
    run = sim.run()
    assert run.node(2)["ax"][0] == pytest.approx(2.0 / M, rel=1e-12)
    held = mecano.Simulation(spring(1e-3))
    u = held.add_input(node=2, axis=0)
    held.set_input(u, 5.0)
    held.step()
    assert held.run().node(2)["ax"][0] == pytest.approx((F0 + 5.0) / M, rel=1e-12)


def test_save_and_load_carry_the_set_load(tmp_path):
    straight = switched(1e-3, end=0.5)
    straight.advance(0.8)
    first = switched(1e-3, end=0.5)
    first.save(tmp_path / "ck")
    record = json.loads((tmp_path / "ck" / "simulation.json").read_text())
    assert record["loads"] == {"1": F1}
    again = mecano.Simulation.load(tmp_path / "ck", deck=spring(1e-3))
    again.advance(0.8)
    assert np.array_equal(again.position(2), straight.position(2))
    # A record of another time than the checkpoint's is refused, never ignored.
    record["time"] = 0.25
    (tmp_path / "ck" / "simulation.json").write_text(json.dumps(record))
    with pytest.raises(mecano.SimulationError, match="not saved together"):
        mecano.Simulation.load(tmp_path / "ck", deck=spring(1e-3))


ARM = """TITLE driven arm set from Python
NODES
  1 0 0 0 FIX ALL
  2 1 0 0
FUNCTIONS
  1 SINE 1 OMEGA 2
ELEMENTS
  1 HINGE 1 2 AXIS 0 0 1 DRIVE 1 AMPLITUDE 0.5
  2 MASS 2 M 1
ANALYSIS DYNAMIC ALPHA -0.1 STEP {h} END 1
OUTPUT NODES 2 ELEMENTS 1 EVERY 1
END
"""


def quintic(t0, t1, start, target):
    """The polynomial p of degree 5 with p, p', p'' = start at t0 and (target, 0, 0) at
    t1, by solving its 6 x 6 system (independent of the solver's closed form)."""
    rows, rhs = [], []
    for t, (p, v, a) in ((t0, start), (t1, (target, 0.0, 0.0))):
        rows.append([t**k for k in range(6)])
        rows.append([k * t ** (k - 1) if k else 0.0 for k in range(6)])
        rows.append([k * (k - 1) * t ** (k - 2) if k > 1 else 0.0 for k in range(6)])
        rhs += [p, v, a]
    c = np.linalg.solve(np.array(rows), np.array(rhs))
    value = lambda t: sum(c[k] * t**k for k in range(6))
    acc = lambda t: sum(k * (k - 1) * c[k] * t ** (k - 2) for k in range(2, 6))
    jerk = lambda t: sum(k * (k - 1) * (k - 2) * c[k] * t ** (k - 3) for k in range(3, 6))
    return value, acc, jerk


def test_a_drive_set_between_steps_follows_its_quintic_and_torque():
    """The hinge's angle follows the C² quintic from the law's state at 0.25 s to 0.2 rad
    at 0.75 s (to Newton's tolerance: the driver's equation holds at each step), then
    stays; the driving torque is J p'' (J = m L^2 = 1 kg m^2, no gravity), which HHT
    (alpha = -0.1: the index-3 multipliers of alpha = 0 oscillate undamped) gives to
    O(h^2) once the transient of the jerk's jump at 0.25 s (order h J |jump|, decaying
    like rho_inf^n, rho_inf = 0.82) is gone: measured 1.9e-4 and 4.7e-5 N m at h = 1e-3
    and 5e-4 s over [0.35, 0.65] s, ratio 4.00."""
    t0, t1, target = 0.25, 0.75, 0.2
    start = (0.5 * math.sin(2 * t0), math.cos(2 * t0), -2 * math.sin(2 * t0))
    p, acc, jerk = quintic(t0, t1, start, target)
    # The trapezoidal rule's velocity defect for a prescribed motion is h^2/6 times its
    # third derivative per step, alternating in sign: the rate is within twice that.
    jerk_max = max(max(abs(jerk(x)) for x in np.linspace(t0, t1, 200)), 0.5 * 8)
    errors = []
    for h in (1e-3, 5e-4):
        sim = mecano.Simulation(mecano.Deck(ARM.format(h=h), name="arm.dat"))
        sim.advance(t0)
        with pytest.raises(ValueError, match="jump"):
            sim.set_drive(1, target)
        sim.set_drive(1, target, over=t1 - t0)
        sim.advance(1.0)
        assert sim.joint_angle(1) == pytest.approx(target, abs=1e-10)
        assert abs(sim.joint_rate(1)) <= h**2 / 3 * jerk_max, (h, jerk_max)
        e = sim.run().element(1)
        t = e.t
        for ti, ai in zip(t, e["angle"]):
            want = p(ti) if t0 <= ti <= t1 else (target if ti > t1 else 0.5 * math.sin(2 * ti))
            assert abs(ai - want) < 1e-9, (ti, ai, want)
        inside = (t > t0 + 0.1) & (t < t1 - 0.1)
        errors.append(max(abs(e["torque"][inside] - [acc(x) for x in t[inside]])))
    order = math.log2(errors[0] / errors[1])
    assert 1.85 < order < 2.15, (errors, order)


def test_save_and_restore_carry_a_set_drive_and_a_held_input(tmp_path):
    """The driver's quintic and a held input's value set by hand go to simulation.json and
    come back: the restored run goes on bit for bit; without the input it is refused."""
    deck = mecano.Deck(ARM.format(h=1e-3), name="arm.dat")

    def started():
        sim = mecano.Simulation(deck)
        u = sim.add_input(node=2, axis=2)  # a force along z, which the hinge carries
        sim.advance(0.25)
        sim.set_drive(1, 0.2, over=0.5)
        sim.set_input(u, 7.0)
        sim.advance(0.4)
        return sim, u

    straight, _ = started()
    straight.advance(0.9)
    first, _ = started()
    first.save(tmp_path / "ck")
    record = json.loads((tmp_path / "ck" / "simulation.json").read_text())
    assert list(record["drives"]) == ["1"] and list(record["inputs"].values()) == [7.0]
    again = mecano.Simulation(deck)
    u = again.add_input(node=2, axis=2)
    again.restore(tmp_path / "ck")
    again.advance(0.9)
    assert again.joint_angle(1) == straight.joint_angle(1)
    assert np.array_equal(again.position(2), straight.position(2))
    assert again.element(u)["force"] == 7.0
    with pytest.raises(mecano.MecanoError):
        mecano.Simulation.load(tmp_path / "ck", deck=deck)  # saved with an input
