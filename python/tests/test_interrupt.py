"""Ctrl-C (issue 36 §7): SIGINT sent to this very process while a run computes stops it at
the end of a step and raises KeyboardInterrupt with the histories so far kept.

The signal is sent at a moment the test chooses, never after a wall-time delay that a
slow machine could outrun: from a progress callback's first call (a thread that waits
for it), from inside a law (os.kill raises at once in the calling thread), or to a run
whose length is thousands of times the poll interval (run_many)."""

import os
import signal
import threading

import numpy as np
import pytest

import mecano

from test_control import arm, torque


@pytest.fixture(autouse=True)
def default_sigint_handler():
    """pytest keeps Python's default SIGINT handler (KeyboardInterrupt); make sure."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


def long_pendulum(root, end=30.0):
    """decks/pendulum.dat run to `end` s: ~15 000 times the 50 ms poll of a run."""
    text = (root / "decks" / "pendulum.dat").read_text().replace("END 2.0", f"END {end}")
    return mecano.Deck(text, name="pendulum.dat")


def sigint_after(event):
    def go():
        if event.wait(60):
            os.kill(os.getpid(), signal.SIGINT)

    th = threading.Thread(target=go, daemon=True)
    th.start()
    return th


def whole_steps(run, end):
    """The histories of an interrupted run: incomplete, every file up to the same last
    step, short of the end."""
    assert not run.complete
    stop = run.summary["stop"]
    assert stop["reason"] == "interrupted" and stop["at_step_end"], stop
    t = run.node(12).t
    assert 0 < t[-1] < end
    assert run.energy.t[-1] == t[-1]
    for e in run.elements:
        assert run.element(e).t[-1] == t[-1]
    assert np.all(np.isfinite(run.node(12).array))
    return t[-1]


def test_ctrl_c_stops_run_at_a_step_and_keeps_the_histories(root):
    first = threading.Event()
    th = sigint_after(first)
    with pytest.raises(KeyboardInterrupt) as e:
        mecano.run(long_pendulum(root), progress=lambda t, end: first.set())
    th.join()
    run = e.value.run
    whole_steps(run, 30.0)
    assert run.summary.get("signal") == "SIGINT", run.summary


def test_ctrl_c_stops_every_run_of_run_many(root):
    decks = [long_pendulum(root), long_pendulum(root)]
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as e:
            mecano.run_many(decks, threads=2)
    finally:
        timer.cancel()
    runs = e.value.run
    assert isinstance(runs, list) and len(runs) == 2
    for run in runs:
        whole_steps(run, 30.0)


def interrupted_law(t, s, sent=[]):
    if t > 0.05 and not sent:
        sent.append(t)
        os.kill(os.getpid(), signal.SIGINT)  # raises KeyboardInterrupt here, in the law
    return torque(t, s.joint_angle(1), s.joint_rate(1))


def test_ctrl_c_in_a_law_stops_the_simulation_at_the_end_of_the_step(root):
    straight = mecano.Simulation(arm(root, 1e-3))
    straight.add_input(
        hinge=1,
        law=lambda t, s: torque(t, s.joint_angle(1), s.joint_rate(1)),
        sensors=[("angle", 1), ("rate", 1)],
    )
    straight.advance(0.2)

    sent = []
    sim = mecano.Simulation(arm(root, 1e-3))
    sim.add_input(
        hinge=1,
        law=lambda t, s: interrupted_law(t, s, sent),
        sensors=[("angle", 1), ("rate", 1)],
    )
    with pytest.raises(KeyboardInterrupt):
        sim.advance(0.2)
    assert len(sent) == 1
    # Stopped at the end of the step in which the law was interrupted, not failed.
    assert sim.failed is None
    assert sent[0] - 1e-3 < sim.t < sent[0] + 1e-3 + 1e-12
    assert sim.t == pytest.approx(round(sim.t / 1e-3) * 1e-3, abs=1e-12)
    run = sim.run()
    assert not run.complete and run.node(2).t[-1] == sim.t
    # It goes on, and computes what it would have without the interruption.
    sim.advance(0.2)
    assert sim.joint_angle(1) == straight.joint_angle(1)
    assert np.array_equal(sim.run().node(2).array, straight.run().node(2).array)


def test_ctrl_c_in_an_explicit_law_leaves_the_simulation_usable(root):
    sent = []

    def law(t, sim):
        if t > 0.02 and not sent:
            sent.append(t)
            os.kill(os.getpid(), signal.SIGINT)
        return 0.0

    sim = mecano.Simulation(arm(root, 1e-3))
    sim.add_input(hinge=1, law=law, tangent="explicit")
    with pytest.raises(KeyboardInterrupt):
        sim.advance(0.1)
    assert sim.failed is None
    stopped = sim.t
    assert 0.02 <= stopped < 0.022
    sim.advance(0.1)
    assert sim.t == pytest.approx(0.1)


def test_ctrl_c_while_a_simulation_advances(root):
    """No law: the signal arrives while Rust steps (the GIL released) and is seen at the
    next poll between steps; the simulation goes on afterwards."""
    sim = mecano.Simulation(long_pendulum(root))
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sim.advance(30.0)
    finally:
        timer.cancel()
    assert sim.failed is None
    stopped = sim.t
    assert 0 < stopped < 30.0
    run = sim.run()
    assert not run.complete and run.summary["stop"]["reason"] == "paused"
    assert run.energy.t[-1] <= stopped  # the deck's OUTPUT grid: rows up to the stop
    sim.step()
    assert sim.t > stopped
