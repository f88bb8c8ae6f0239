"""The Simulation you drive, and inputs that close a loop: the PD-controlled rigid arm
against an independent solution of its ODE, computed here by RK4 at a fine step."""

import math
import threading

import numpy as np
import pytest

import mecano

KP, KD, A, W, G = 50.0, 10.0, 0.5, 2.0, 9.81
END = 1.0


def ref(t):
    return A * math.sin(W * t), A * W * math.cos(W * t)


def torque(t, theta, rate):
    r, rd = ref(t)
    return KP * (r - theta) + KD * (rd - rate)


def rk4_reference(end=END, h=2e-5):
    """theta'' = -g cos(theta) + T: the arm of decks/pd_arm.dat (J = m L^2 = 1 kg m^2).
    RK4's error at h = 2e-5 s is ~h^4 * C ~ 1e-17 rad: far below what is checked."""

    def f(t, y):
        return np.array([y[1], -G * math.cos(y[0]) + torque(t, y[0], y[1])])

    y, t, out = np.zeros(2), 0.0, {}
    n = int(round(end / h))
    for k in range(n):
        k1 = f(t, y)
        k2 = f(t + h / 2, y + h / 2 * k1)
        k3 = f(t + h / 2, y + h / 2 * k2)
        k4 = f(t + h, y + h * k3)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        t = (k + 1) * h
    return y[0]


REFERENCE = None


def reference():
    global REFERENCE
    if REFERENCE is None:
        REFERENCE = rk4_reference()
    return REFERENCE


def arm(root, h, scheme=""):
    text = (root / "decks" / "pd_arm.dat").read_text()
    # The arm without its deck PID: the input comes from Python.
    text = text.replace("  3  PID 1 KP $KP KD $KD TARGET 1 AMPLITUDE $A\n", "")
    text = text.replace("ELEMENTS 1 3", "ELEMENTS 1")
    if scheme:
        text = text.replace("ALPHA 0", scheme)
    return mecano.Deck(text, name="pd_arm.dat").with_parameters(H=h)


def differentiated(root, h, scheme=""):
    sim = mecano.Simulation(arm(root, h, scheme))
    sim.add_input(
        hinge=1,
        law=lambda t, s: torque(t, s.joint_angle(1), s.joint_rate(1)),
        sensors=[("angle", 1), ("rate", 1)],
    )
    sim.advance(END)
    return sim.joint_angle(1)


def explicit(root, h):
    sim = mecano.Simulation(arm(root, h))
    sim.add_input(
        hinge=1,
        law=lambda t, sim: torque(t, sim.joint_angle(1), sim.joint_rate(1)),
        tangent="explicit",
    )
    sim.advance(END)
    return sim.joint_angle(1)


def test_differentiated_input_matches_the_ode_to_1e_8_rad(root):
    """ESDIRK5 at h = 1e-3 s: its error O(h^5) is far below 1e-8 rad; HHT (trapezoidal,
    alpha = 0) converges at order 2 with the input inside the step."""
    theta = reference()
    err5 = abs(differentiated(root, 1e-3, "ESDIRK5") - theta)
    assert err5 < 1e-8, err5
    e1 = abs(differentiated(root, 2e-3) - theta)
    e2 = abs(differentiated(root, 1e-3) - theta)
    order = math.log2(e1 / e2)
    assert 1.8 < order < 2.2, (e1, e2, order)


def test_explicit_input_is_first_order(root):
    """The zero-order hold (value held over each step from the step's start state) costs
    one order: the error halves with the step (measured order 1 +- 0.15)."""
    theta = reference()
    errors = [abs(explicit(root, h) - theta) for h in (2e-3, 1e-3, 5e-4)]
    orders = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    for o in orders:
        assert 0.85 < o < 1.15, (errors, orders)


@pytest.mark.parametrize("name", ["pd_arm.dat", "pd_arm_law.dat"])
def test_deck_pid_is_the_python_pd(root, name):
    """decks/pd_arm.dat's PID card, and decks/pd_arm_law.dat's CONTROL law of sensors,
    against the same law from Python: the same history."""
    deck = mecano.Deck.read(root / "decks" / name)
    run = mecano.run(deck)
    sim = mecano.Simulation(arm(root, 1e-3))
    sim.add_input(
        hinge=1,
        law=lambda t, s: torque(t, s.joint_angle(1), s.joint_rate(1)),
        sensors=[("angle", 1), ("rate", 1)],
    )
    sim.advance(END)
    a = run.element(1)["angle"]
    b = sim.run().element(1)["angle"]
    assert a.shape == b.shape
    # Same equations and scheme; the Python law's tangent is a forward difference (1e-7
    # relative), so Newton stops at slightly different iterates: within its tolerance.
    assert np.max(np.abs(a - b)) < 1e-9
    # HHT alpha = 0 at h = 1e-3 s: 5.7e-8 rad from the ODE at 1 s (docs/python.md).
    assert abs(run.element(3)["s1"][-1] - reference()) < 2e-5


def test_simulation_state_queries_and_held_input(root):
    sim = mecano.Simulation(arm(root, 1e-3))
    # 9.81 N m holds the arm up against gravity from the start: it stays at rest.
    u = sim.add_input(hinge=1, value=9.81)
    assert sim.t == 0.0
    for _ in range(10):
        sim.step()
    assert sim.t == pytest.approx(0.01)
    assert abs(sim.joint_angle(1)) < 1e-12
    assert np.allclose(sim.position(2), [1, 0, 0], atol=1e-12)
    assert sim.rotation(2).shape == (3, 3)
    f, m = sim.reaction(1)
    assert f.shape == (3,) and m.shape == (3,)
    assert "torque" in sim.element(u)
    with pytest.raises(mecano.SimulationError):
        sim.add_input(hinge=1)  # after the start
    with pytest.raises(ValueError):
        sim.set_input(u, float("nan"))
    with pytest.raises(KeyError):
        sim.position(77)


def test_save_and_load_go_on_bit_for_bit(root, tmp_path):
    deck = arm(root, 1e-3)
    straight = mecano.Simulation(deck)
    straight.advance(0.2)  # the same landing on 0.2 s as the saved one
    straight.advance(0.4)
    first = mecano.Simulation(deck)
    first.advance(0.2)
    first.save(tmp_path / "ck")
    again = mecano.Simulation.load(tmp_path / "ck", deck=deck)
    assert isinstance(again, mecano.Simulation)
    again.advance(0.4)
    assert again.joint_angle(1) == straight.joint_angle(1)
    assert np.array_equal(again.position(2), straight.position(2))


def test_a_law_that_raises_stops_the_run_and_keeps_the_histories(root):
    sim = mecano.Simulation(arm(root, 1e-3))

    def law(t, s):
        if t > 0.05:
            raise ZeroDivisionError("controller bug")
        return 0.0

    sim.add_input(hinge=1, law=law, sensors=[("angle", 1)])
    with pytest.raises(ZeroDivisionError, match="controller bug"):
        sim.advance(0.2)
    run = sim.run()
    assert not run.complete
    assert 0.04 < run.node(2).t[-1] <= 0.05 + 1e-12
    assert sim.failed
    with pytest.raises(mecano.SimulationError, match="failed"):
        sim.step()


@pytest.mark.parametrize(
    "value, error",
    [(float("nan"), ValueError), ("abc", TypeError), ([1.0, 2.0], TypeError)],
)
def test_a_law_returning_nan_or_a_wrong_type_is_an_exception(root, value, error):
    sim = mecano.Simulation(arm(root, 1e-3))
    sim.add_input(hinge=1, law=lambda t, s: value, sensors=[("angle", 1)])
    with pytest.raises(error):
        sim.advance(0.01)
    sim2 = mecano.Simulation(arm(root, 1e-3))
    sim2.add_input(hinge=1, law=lambda t, sim: value, tangent="explicit")
    with pytest.raises(error):
        sim2.step()


def test_undeclared_sensor_and_bad_arguments(root):
    sim = mecano.Simulation(arm(root, 1e-3))
    sim.add_input(hinge=1, law=lambda t, s: s.joint_rate(1), sensors=[("angle", 1)])
    with pytest.raises(ValueError, match="not among its sensors"):
        sim.step()
    sim = mecano.Simulation(arm(root, 1e-3))
    with pytest.raises(ValueError):
        sim.add_input(hinge=1, law=lambda t, s: 0.0)  # no sensors
    with pytest.raises(ValueError):
        sim.add_input(node=2)  # no axis
    with pytest.raises(TypeError):
        sim.add_input(hinge=1, sensors=[("speed", 1)], law=lambda t, s: 0.0)
    with pytest.raises(ValueError):
        sim.add_input(hinge=2)  # a MASS, not a HINGE
    with pytest.raises(TypeError):
        sim.add_input(hinge=1, law=3.0)
    with pytest.raises(ValueError):
        sim.advance(float("inf"))


def test_two_threads_on_one_simulation_get_an_exception(root):
    sim = mecano.Simulation(arm(root, 1e-4))
    errors = []

    def go():
        try:
            sim.advance(0.5)
        except mecano.SimulationError as e:
            errors.append(e)

    threads = [threading.Thread(target=go) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sim.t == pytest.approx(0.5)
    # Whichever came second while the first stepped was refused (or found t reached).
    for e in errors:
        assert "another thread" in str(e)


def test_a_law_error_carries_its_python_traceback(root):
    """The error is the law's own exception: its traceback reaches into the law."""
    sim = mecano.Simulation(arm(root, 1e-3))

    def faulty_controller(t, s):
        return {}["gain"]  # KeyError inside the user's code

    sim.add_input(hinge=1, law=faulty_controller, sensors=[("angle", 1)])
    with pytest.raises(KeyError) as e:
        sim.step()
    assert any(entry.name == "faulty_controller" for entry in e.traceback)


def test_an_explicit_law_that_raises_stops_the_simulation(root):
    sim = mecano.Simulation(arm(root, 1e-3))

    def law(t, sim):
        if t > 0.01:
            raise RuntimeError("explicit controller bug")
        return 9.81

    sim.add_input(hinge=1, law=law, tangent="explicit")
    with pytest.raises(RuntimeError, match="explicit controller bug"):
        sim.advance(0.1)
    assert sim.failed and "raised" in sim.failed
    run = sim.run()
    assert not run.complete and 0.01 <= run.node(2).t[-1] < 0.012
    with pytest.raises(mecano.SimulationError, match="failed"):
        sim.advance(0.2)


@pytest.mark.parametrize(
    "call, error",
    [
        (lambda sim: sim.add_input(hinge=1, value=float("nan")), ValueError),
        (lambda sim: sim.add_input(hinge=1, value="big"), TypeError),
        (lambda sim: sim.add_input(node=2, axis=3), ValueError),
        (lambda sim: sim.add_input(hinge=1, tangent="exact", law=lambda t, s: 0.0), ValueError),
        (lambda sim: sim.advance("1.0"), TypeError),
        (lambda sim: sim.position("2"), TypeError),
        (lambda sim: sim.velocity(2, axis=5), ValueError),
        (lambda sim: sim.joint_angle(2), KeyError),  # a MASS, not a HINGE
        (lambda sim: sim.reaction(2), ValueError),  # a MASS has no reaction
        (lambda sim: sim.set_input(99, 1.0), KeyError),
    ],
)
def test_bad_arguments_raise_python_exceptions(root, call, error):
    sim = mecano.Simulation(arm(root, 1e-3))
    with pytest.raises(error):
        call(sim)


def test_pd_law_on_the_flexible_arm_starts_and_steps(root):
    """examples/python/pd_flexible_arm.py's set-up: starting it used to hang in the
    run summary's modal block (a dense eigensolve that did not return, with the GIL
    held). Run in a child process so that a regression fails instead of hanging."""
    import subprocess
    import sys

    code = f"""
import math, mecano
sim = mecano.Simulation(mecano.Deck.read({str(root / 'decks' / 'pd_flexible_arm.dat')!r}))
sim.add_input(hinge=1, law=lambda t, s: 20.0 * (0.1 - s.joint_angle(1)) - 2.0 * s.joint_rate(1),
              sensors=[("angle", 1), ("rate", 1)])
sim.advance(0.05)
run = sim.run()
assert run.summary["step_resolution"]["computed"] is False
print(sim.t, sim.joint_angle(1))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    t, angle = map(float, out.stdout.split())
    assert t == pytest.approx(0.05) and 0 < angle < 0.1


def test_an_explicit_law_sets_the_initial_accelerations(root):
    """The explicit law's value at t = 0 (not the input's default `value` = 0) is what the
    start's accelerations balance: a law that holds the arm up against gravity (9.81 N m)
    keeps it at rest from the first step, as the held input does."""
    sim = mecano.Simulation(arm(root, 1e-3))
    sim.add_input(hinge=1, law=lambda t, sim: 9.81, tangent="explicit")
    sim.advance(0.1)
    assert abs(sim.joint_angle(1)) < 1e-12
    # The first row, recorded again once the law's value set the start: at rest, no
    # acceleration (it showed the free fall's -9.81 m/s^2 before).
    assert np.max(np.abs(sim.run().node(2)["ay"])) < 1e-12
