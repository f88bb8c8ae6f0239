"""The scenes of the peer bench: mecano-rs's deck and its variants, the compared quantities,
the reference, and each code's ladder (benches/peers/README.md). Standard library only.

A mecano-rs configuration is made from the scene's deck by changing three cards, as
benches/converged_deck.sh does: the beams' mesh (DIVIDE d ORDER p on the scene's BEAM
cards), the ANALYSIS card (integrator, step, end) and the OUTPUT interval.
"""
import math
import os
import re

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def positions(nodes):
    return lambda t, pos: [pos[n] for n in nodes]


def spinup_angle(t, ws=4.0, T=15.0):
    """The hub's angle of decks/benchmarks/spinup.dat (omega_s = 4 rad/s)."""
    if t <= T:
        return ws / T * (t * t / 2 + (T / (2 * math.pi)) ** 2 * (math.cos(2 * math.pi * t / T) - 1))
    return ws * (t - T / 2)


def spinup_v(t, pos):
    """The tip's deflection in the rotating frame, -x sin(theta) + y cos(theta) of node 3."""
    th = spinup_angle(t)
    x, y, _ = pos[3]
    return [[-x * math.sin(th) + y * math.cos(th)]]


def midspan_w(t, pos):
    """The rod's mid-span deflection: node 12 minus the chord's midpoint (nodes 10, 14) on
    the normal z x chord (docs/benchmarks.md, "Flexible slider-crank")."""
    a, m, b = pos[10], pos[12], pos[14]
    cx, cy = b[0] - a[0], b[1] - a[1]
    ln = math.hypot(cx, cy)
    nx, ny = -cy / ln, cx / ln
    return [[(m[0] - 0.5 * (a[0] + b[0])) * nx + (m[1] - 0.5 * (a[1] + b[1])) * ny]]


def node_z(nodes):
    return lambda t, pos: [[pos[n][2]] for n in nodes]


def slider_x(t, pos):
    return [[pos[8][0]]]


def ideal_slider_a(t, r=0.05, l=0.12, w=5000 * 2 * 3.141592653589793 / 60):
    """The rigid slider-crank's slider acceleration at constant crank speed w, theta = w t
    (decks/benchmarks/slider_crank_ideal.dat): x = r cos(theta) + S, S = sqrt(l^2 - r^2
    sin^2(theta)), so x'' = w^2 (-r cos(theta) - r^2 cos(2 theta)/S - r^4 sin^2(theta)
    cos^2(theta)/S^3), which is -r w^2 (1 + r/l) at theta = 0."""
    th = w * t
    s, c = math.sin(th), math.cos(th)
    S = math.sqrt(l * l - (r * s) ** 2)
    return [[w * w * (-r * c - r * r * math.cos(2 * th) / S - r ** 4 * (s * c) ** 2 / S ** 3)]]


def mk(label, h, d, p, scheme, beams=1, per=""):
    """A mecano-rs configuration: every BEAM card of the scene divided into d beams of order p
    (`beams` BEAM cards per bar, leg or rod, named by `per`), scheme and step h."""
    n = d * beams
    mesh = (f"{n} x order {p}" if p > 1 else f"{n} two-node") + per if d * p > 1 or per else "rigid bodies"
    return dict(label=label or f"{mesh}, {scheme}, h = {h:g}", h=h, d=d, p=p, mesh=mesh, scheme=scheme)


def pend(h, d, p, scheme, label=None):
    return mk(label, h, d, p, scheme, 1, " per bar")


def leg(h, d, p, scheme, label=None):
    return mk(label, h, d, p, scheme, 1, " per leg")


def rod(h, d, p, scheme, label=None):
    return mk(label, h, d, p, scheme, 4, " in the rod")


def bar4(h, d, p, scheme, label=None):
    return mk(label, h, d, p, scheme, 2, " per bar")


def converged_deck(newton=""):
    """`decks/pendulum_converged.dat` as it is (a rung of both pendulum scenes), or with
    `newton` (e.g. a Newton tolerance) added to its integrator."""
    if newton:
        return pend(3.125e-4, 1, 8, "ESDIRK5" + newton)
    return pend(3.125e-4, 1, 8, "ESDIRK5", "decks/pendulum_converged.dat: 1 x order 8 per bar, ESDIRK5, h = 3.125e-4")


# The ladders. mecano-rs: (label, h, divisions, order, ANALYSIS scheme); Exudyn: (two-node
# beams per bar/leg/beam/rod, h); MBDyn: (three-node beam3 per leg/beam/rod, h). The first
# mecano-rs rung of each scene is the deck as shipped. PEER_SCENES: the scenes a peer models,
# the bench's default.
SCENES = {
    "pendulum": dict(
        title="seed's double pendulum striking the floor (flexible1), t <= 1.5 s, nodes 12 and 23",
        per="bar", deck="decks/pendulum_converged.dat", mesh_re=r"ORDER 8", tend=1.5, period=1e-3,
        nodes=[12, 23], widths=[3, 3], channels=positions([12, 23]), target=1e-3,
        ref=pend(3.90625e-5, 2, 8, "ESDIRK5", "reference: 2 x order 8 per bar, ESDIRK5, h = 3.90625e-5"),
        check=pend(7.8125e-5, 2, 8, "ESDIRK5", "check: 2 x order 8 per bar, ESDIRK5, h = 7.8125e-5"),
        mecano=[converged_deck(),
                pend(3.90625e-4, 1, 8, "ESDIRK5"),
                pend(7.8125e-4, 1, 8, "ESDIRK5"),
                pend(1.953125e-4, 1, 8, "ESDIRK5"),
                pend(3.90625e-4, 1, 10, "ESDIRK5"),
                pend(2.6041666666666666e-4, 1, 10, "ESDIRK5"),
                pend(1.953125e-4, 1, 10, "ESDIRK5"),
                pend(3.90625e-4, 2, 8, "ESDIRK5"),
                pend(1.5625e-5, 1, 8, "ALPHA -0.1"),
                # (h12, 2026-11-28: the deck at a Newton tolerance of 1e-4, 20 % cheaper for
                # 1.2e-6 m of Newton error; HHT gains as much, so the ratio of the two does not
                # move: pendulum_time below. newton_tol.py)
                converged_deck(" TOL 1e-4 TOLINC 1e-6")],
        exudyn=[(10, 1e-4), (20, 1e-4), (40, 5e-5), (80, 5e-5)],
    ),
    "cantilever": dict(
        title="right-angle cantilever (Simo & Vu-Quoc 1988), t <= 30 s, elbow and tip",
        per="leg", deck="decks/benchmarks/right_angle_cantilever.dat", mesh_re=r"DIVIDE \$n", tend=30.0, period=0.1,
        nodes=[2, 3], widths=[3, 3], channels=positions([2, 3]),
        ref=leg(0.0125, 4, 8, "ESDIRK5", "reference: 4 x order 8 per leg, ESDIRK5, h = 0.0125"),
        check=leg(0.025, 2, 8, "ESDIRK5", "check: 2 x order 8 per leg, ESDIRK5, h = 0.025"),
        mecano=[leg(0.05, 10, 1, "ALPHA 0", "the deck: 10 two-node per leg, HHT 0, h = 0.05"),
                leg(0.05, 40, 1, "ALPHA 0"),
                leg(0.025, 40, 1, "ALPHA 0"),
                leg(0.2, 2, 6, "ESDIRK5"),
                leg(0.125, 1, 6, "ESDIRK5"),
                leg(0.125, 1, 8, "ESDIRK5"),
                leg(0.1, 1, 6, "ESDIRK5"),
                leg(0.1, 1, 8, "ESDIRK5"),
                leg(0.1, 2, 6, "ESDIRK5"),
                leg(0.05, 2, 6, "ESDIRK5"),
                leg(0.025, 1, 6, "ALPHA 0"),
                leg(0.0375, 1, 6, "ALPHA 0"),
                leg(0.025, 1, 4, "ALPHA 0"),
                leg(0.025, 1, 5, "ALPHA 0"),
                # (h12, 2026-11-28: the rung above sits at 0.995 of the target. A slightly
                # smaller step costs no more — the kept matrix lasts longer: 576 against 709
                # factorisations — and leaves a margin, 0.84; a Newton tolerance of 1e-4 takes
                # 40 % of the iterations off for 3.4e-6 m of Newton error, 3e-4 of the target;
                # ESDIRK5 on the same mesh at the same tolerance as well. All three measured
                # interleaved with the rung above: benches/peers/newton_tol.py)
                leg(0.0225, 1, 5, "ALPHA 0"),
                leg(0.0225, 1, 5, "ALPHA 0 TOL 1e-4 TOLINC 1e-6"),
                leg(0.1, 1, 5, "ESDIRK5 TOL 1e-4 TOLINC 1e-6"),
                # (2026-11-28, sixth sitting: a Newton tolerance of 1e-3 takes 18 % of the
                # rung's iterations off for 7e-5 m of Newton error, 6e-3 of the target; Exudyn's
                # looser tolerances beside it: --ladder exudyn=40:0.025:1e-4, docs/performance.md)
                leg(0.0225, 1, 5, "ALPHA 0 TOL 1e-3 TOLINC 1e-5")],
        # (third field: Newton's relative tolerance instead of the bench's 1e-8; 1e-4 is the
        # loosest that converges here: 1e-3 and 1e-2 stop at t = 22.7 and 5.2 s. Sixth sitting.)
        exudyn=[(10, 0.05), (20, 0.05), (20, 0.025), (40, 0.05), (40, 0.025), (80, 0.0125),
                (40, 0.025, 1e-4)],
        mbdyn=[(5, 0.05), (10, 0.025), (10, 0.0125), (20, 0.025), (20, 0.0125), (40, 0.0125)],
    ),
    "spinup": dict(
        title="Kane's spin-up beam, omega_s = 4 rad/s, t <= 20 s, tip deflection in the rotating frame",
        per="beam", deck="decks/benchmarks/spinup.dat", mesh_re=r"DIVIDE \$n", tend=20.0, period=0.1,
        nodes=[3], widths=[1], channels=spinup_v,
        ref=mk("reference: 4 x order 8, ESDIRK5, h = 2.5e-3", 2.5e-3, 4, 8, "ESDIRK5"),
        check=mk("check: 2 x order 8, ESDIRK5, h = 5e-3", 5e-3, 2, 8, "ESDIRK5"),
        # (ESDIRK5 here: 7 factorisations a step at h = 0.02, 19 at 0.04, where the pendulum
        # needs 1.3: Newton leaves its region when the beam turns 0.16 rad a step, HHT too;
        # docs/performance.md, "The spin-up with ESDIRK5". 1 x order 6 at h = 0.02, which an
        # older note said stopped at t = 0, runs: 3.3e-4 in 0.66 s)
        mecano=[mk("the deck: 10 two-node, HHT -0.05, h = 0.01", 0.01, 10, 1, "ALPHA -0.05"),
                mk(None, 0.005, 10, 1, "ALPHA -0.05"),
                mk(None, 0.01, 20, 1, "ALPHA -0.05"),
                mk(None, 0.01, 1, 4, "ALPHA -0.05"),
                mk(None, 0.01, 1, 6, "ALPHA -0.05"),
                mk(None, 0.0125, 1, 6, "ALPHA -0.05"),
                mk(None, 0.01, 1, 6, "GENALPHA RHOINF 0.9"),
                mk(None, 0.04, 3, 6, "ESDIRK5"),
                mk(None, 0.02, 3, 6, "ESDIRK5"),
                mk(None, 0.04, 2, 8, "ESDIRK5"),
                mk(None, 0.02, 2, 8, "ESDIRK5"),
                mk(None, 0.0125, 1, 4, "ALPHA -0.05"),
                mk(None, 0.01, 1, 3, "ALPHA -0.05"),
                # (h12, 2026-11-28: the same mesh at a 25 % longer step is still 0.73 of the
                # target and about 15 % cheaper; a Newton tolerance of 1e-4 saves little more
                # here (0.9 factorisations a step, which it hardly changes), and it is unsafe
                # for HHT alpha = 0 on this scene: at h = 0.015 Newton failed, 7,916 steps for
                # 1,334, 13.8x the target, where the default tolerance gives 1.05x. newton_tol.py)
                mk(None, 0.0125, 1, 3, "ALPHA -0.05"),
                mk(None, 0.0125, 1, 3, "ALPHA -0.05 TOL 1e-4 TOLINC 1e-6"),
                mk(None, 0.0125, 1, 3, "ALPHA -0.05 TOL 1e-3 TOLINC 1e-5")],
        # (1e-3 runs as fast as 1e-4 here, 7.8e-4 off: sixth sitting)
        exudyn=[(10, 0.01), (20, 0.02), (20, 0.0125), (20, 0.01), (40, 0.005), (80, 0.0025),
                (20, 0.01, 1e-4)],
        mbdyn=[(5, 0.01), (10, 0.01), (10, 0.005), (20, 0.005), (40, 0.0025)],
    ),
    "slider_crank": dict(
        title="flexible slider-crank (Song & Haug 1980), t <= 0.06 s, the rod's mid-span deflection",
        per="rod", deck="decks/benchmarks/slider_crank_flexible.dat", mesh_re=r"ORDER 4", tend=0.06, period=1e-4,
        nodes=[10, 12, 14], widths=[1], channels=midspan_w,
        ref=rod(2.5e-6, 2, 8, "ESDIRK5", "reference: 8 x order 8 in the rod, ESDIRK5, h = 2.5e-6"),
        check=rod(5e-6, 1, 8, "ESDIRK5", "check: 4 x order 8 in the rod, ESDIRK5, h = 5e-6"),
        mecano=[rod(1e-5, 1, 4, "ALPHA 0", "the deck: 4 x order 4 in the rod, HHT 0, h = 1e-5"),
                rod(2e-5, 1, 4, "ALPHA 0"),
                rod(1.6e-4, 1, 4, "ESDIRK5"),
                rod(8e-5, 1, 4, "ESDIRK5"),
                rod(4e-5, 1, 4, "ESDIRK5"),
                rod(8e-5, 1, 2, "ESDIRK5"),
                rod(4e-5, 1, 6, "ESDIRK5"),
                rod(4e-5, 1, 4, "ALPHA 0"),
                rod(1.6e-4, 1, 3, "ESDIRK5"),
                rod(2.4e-4, 1, 4, "ESDIRK5"),
                # (h12, 2026-11-28: twice the step of 4 x order 3 at 1.6e-4 s above is 0.65 of the
                # target (the error is not monotone in the step here: 0.57, 0.55, 0.76, 0.65, 1.07
                # at 1.6, 2, 2.4, 3.2, 4e-4 s) and 27 % cheaper; a Newton tolerance of 1e-5 or
                # 1e-4 takes 30-40 % of the iterations off for 3e-9 / 1.7e-8 m of Newton error.
                # 1e-5 is the safer: at 3.6e-4 s, 1e-4 changed which steps are cut, 1.9e-6 m
                # away from the default tolerance's run, 0.4 of the target. newton_tol.py)
                rod(3.2e-4, 1, 3, "ESDIRK5"),
                rod(3.2e-4, 1, 3, "ESDIRK5 TOL 1e-5 TOLINC 1e-7"),
                rod(3.2e-4, 1, 3, "ESDIRK5 TOL 1e-4 TOLINC 1e-6"),
                rod(3.2e-4, 1, 3, "ESDIRK5 TOL 1e-3 TOLINC 1e-5")],
        exudyn=[(8, 1e-5), (16, 1e-5), (32, 1e-5), (64, 1e-5), (128, 1e-5), (128, 5e-6), (256, 5e-6),
                (128, 5e-6, 1e-4)],
        mbdyn=[(4, 1e-5), (8, 1e-5), (16, 1e-5), (32, 1e-5), (32, 5e-6)],
    ),
    "four_bar": dict(
        title="Bauchau's spatial four-bar, t <= 2.5 s (before the first flattened position), "
              "out-of-plane displacement of the three mid-spans",
        deck="decks/benchmarks/four_bar_bauchau.dat", mesh_re=r"ORDER \$p", tend=2.5, period=0.01,
        nodes=[11, 21, 31], widths=[1, 1, 1], channels=node_z([11, 21, 31]),
        ref=bar4(1.25e-3, 2, 8, "ESDIRK5", "reference: 4 x order 8 per bar, ESDIRK5, h = 1.25e-3"),
        check=bar4(2.5e-3, 1, 8, "ESDIRK5", "check: 2 x order 8 per bar, ESDIRK5, h = 2.5e-3"),
        mecano=[bar4(0.01, 1, 4, "GENALPHA RHOINF 0", "the deck: 2 x order 4 per bar, generalized-alpha 0, h = 0.01"),
                bar4(0.02, 1, 4, "GENALPHA RHOINF 0"),
                bar4(0.05, 1, 4, "GENALPHA RHOINF 0"),
                bar4(0.05, 1, 4, "ESDIRK5"),
                bar4(0.02, 1, 4, "ESDIRK5"),
                bar4(0.02, 1, 2, "GENALPHA RHOINF 0")],
    ),
    "slider_crank_ideal": dict(
        title="Flores & Ambrosio's slider-crank, ideal joints, 5000 rpm, two turns (0.024 s), the slider's "
              "acceleration (its position is exact at any step: one degree of freedom, driven)",
        deck="decks/benchmarks/slider_crank_ideal.dat", mesh_re=None, tend=0.024, period=1e-4,
        nodes=[8], widths=[1], channels=slider_x, exact=ideal_slider_a, acceleration=True,
        mecano=[mk("the deck: rigid, HHT -0.05, h = 1e-5", 1e-5, 1, 1, "ALPHA -0.05"),
                mk(None, 2e-5, 1, 1, "ALPHA -0.05"),
                mk(None, 5e-5, 1, 1, "ALPHA -0.05"),
                mk(None, 1e-4, 1, 1, "ALPHA -0.05"),
                mk(None, 1e-4, 1, 1, "ESDIRK5"),
                mk(None, 2e-4, 1, 1, "ESDIRK5"),
                mk(None, 4e-4, 1, 1, "ESDIRK5")],
    ),
    "slider_crank_clearance": dict(
        title="Flores & Ambrosio's slider-crank with a revolute clearance, 5000 rpm, t <= 4 ms (after it the "
              "impact sequence depends on the step: docs/benchmarks.md), the slider's position",
        deck="decks/benchmarks/slider_crank_clearance.dat", mesh_re=None, tend=0.004, period=1e-4,
        nodes=[8], widths=[1], channels=slider_x,
        ref=mk("reference: rigid, HHT -0.05, h = 1.25e-6", 1.25e-6, 1, 1, "ALPHA -0.05"),
        check=mk("check: rigid, HHT -0.05, h = 2.5e-6", 2.5e-6, 1, 1, "ALPHA -0.05"),
        mecano=[mk("the deck: rigid, HHT -0.05, h = 1e-5", 1e-5, 1, 1, "ALPHA -0.05"),
                mk(None, 2e-5, 1, 1, "ALPHA -0.05"),
                mk(None, 4e-5, 1, 1, "ALPHA -0.05"),
                mk(None, 5e-6, 1, 1, "ALPHA -0.05"),
                mk(None, 4e-5, 1, 1, "ESDIRK5"),
                mk(None, 2e-5, 1, 1, "ESDIRK5"),
                mk(None, 1e-5, 1, 1, "ESDIRK5")],
    ),
}


# The seed's scene in time alone: the converged deck's own mesh (one element of order 8 per
# bar) integrated at a ten times finer step, so that the deck's distance to it is the error of
# its step alone (issue 37: "its error <= 1e-3 m both against the space-time reference and
# with the time error alone"); its own error bounded by the same mesh at twice that step.
SCENES["pendulum_time"] = dict(
    SCENES["pendulum"],
    title="seed's double pendulum (flexible1) in time alone: the deck's mesh, 1 x order 8 per bar, t <= 1.5 s, nodes 12 and 23",
    ref=pend(3.125e-5, 1, 8, "ESDIRK5", "time reference: 1 x order 8 per bar, ESDIRK5, h = 3.125e-5"),
    check=pend(6.25e-5, 1, 8, "ESDIRK5", "check: 1 x order 8 per bar, ESDIRK5, h = 6.25e-5"),
    mecano=[converged_deck(),
            pend(3.90625e-4, 1, 8, "ESDIRK5"),
            # (h12, 2026-11-28: the issue's "<= 1/5 of HHT's CPU on the same mesh at equal
            # step error": HHT at 1.4423e-5 s is 0.95 of the target against this reference
            # (docs/accuracy.md); both at the default Newton tolerance and at 1e-4, which
            # takes about 20 % off each, so the ratio stays 0.38-0.39. newton_tol.py)
            converged_deck(" TOL 1e-4 TOLINC 1e-6"),
            pend(1.4423e-5, 1, 8, "ALPHA -0.1"),
            pend(1.4423e-5, 1, 8, "ALPHA -0.1 TOL 1e-4 TOLINC 1e-6")],
)


PEER_SCENES = ["pendulum", "cantilever", "spinup", "slider_crank"]


def deck_text(scene, cfg, dense=False):
    """The scene's deck with cfg's mesh, integrator, step and output interval."""
    sc = SCENES[scene]
    text = open(os.path.join(ROOT, sc["deck"])).read()
    mesh = (f"DIVIDE {cfg['d']} " if cfg["d"] > 1 else "") + (f"ORDER {cfg['p']}" if cfg["p"] > 1 else "")
    lines = []
    for line in text.splitlines():
        if sc["mesh_re"] and re.match(r"^\s*\d+(\s+TO\s+\d+)?\s+BEAM\b", line) and re.search(sc["mesh_re"], line):
            line = re.sub(sc["mesh_re"], mesh.strip() or "DIVIDE 1", line)
        if line.startswith("ANALYSIS DYNAMIC"):
            line = f"ANALYSIS DYNAMIC {cfg['scheme']} STEP {cfg['h']!r} END {sc['tend']!r}"
        if line.startswith("OUTPUT"):
            every = 1 if dense else max(1, int(math.floor(sc["period"] / cfg["h"] + 1e-9)))
            line = re.sub(r"\s+EVERY\s+\d+", "", line) + f" EVERY {every}"
        lines.append(line)
    return "\n".join(lines) + "\n"
