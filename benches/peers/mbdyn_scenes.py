#!/usr/bin/env python3
"""The scenes of mecano-rs's benchmarks written for MBDyn (benches/peers/README.md).

    python3 mbdyn_scenes.py SCENE --h H --n N --out RUN.csv [--method "ms, 0.6"] [--mbdyn BIN]

SCENE is one of cantilever, spinup, slider_crank (the seed's pendulum is not modelled yet:
its floor, a Kelvin-Voigt point-on-plane contact, has no MBDyn element of its own;
docs/performance.md, "What is not here"). N is MBDyn's mesh (three-node `beam3` elements per leg, per beam or per rod), H its
fixed step. The run writes the MBDyn input file RUN.mbd beside RUN.csv, runs MBDyn on it,
and writes RUN.csv, the scene's compared quantities at the scene's sampling instants (the
columns of exudyn_scenes.py), and prints one line of JSON: code, scene, h, n, cpu (user +
system seconds of the whole MBDyn process: parsing, the initial assembly and the output
included, as for mecano-rs), steps, newton, ok. Standard library only.

Every scene is the deck's model (same data, loads, joints, start) with MBDyn's own elements:
`beam3`, the three-node finite-volume beam (internal forces at the two points
xi = -+1/sqrt(3); Ghiringhelli, Masarati & Mantegazza 2000), whose inertia MBDyn leaves to
`body` elements on its nodes: each node carries the mass and the section's rotary inertia
of the beam's piece it stands for, the end nodes (1 - 1/sqrt(3))/2 of the element's length
and the middle node 1/sqrt(3) of it (the finite volumes of the beam's formulation; MBDyn's
manual, "beam3"). MBDyn's multistep integrator `ms` (second order, A-stable, rho_inf
tunable: Masarati, Lanz & Mantegazza 2001; rho_inf = 0.9), full Newton, UMFPACK, one thread.
"""
import argparse
import json
import math
import os
import resource
import subprocess
import sys

PEERS = os.path.dirname(os.path.abspath(__file__))
DEFAULT_BIN = os.path.join(PEERS, ".mbdyn", "bin", "mbdyn")

# Sampling period (s), end time (s), the columns (the compared quantities) and Newton's
# tolerance on the residual's norm (N): the tightest that the residual's round-off floor lets
# Newton meet at the finest mesh of the ladder (spin-up: 1e-6 stalls at 20 beam3 at t = 2.1 s;
# 1e-5 and 1e-4 give the same error to 3 digits).
SCENES = {
    "cantilever": dict(period=0.1, tend=30.0, columns=["x2", "y2", "z2", "x3", "y3", "z3"], tol=1e-6),
    "spinup": dict(period=0.1, tend=20.0, columns=["v3"], tol=1e-4),
    "slider_crank": dict(period=1e-4, tend=0.06, columns=["w"], tol=1e-6),
}
END_SHARE = (1.0 - 1.0 / math.sqrt(3.0)) / 2.0   # an end node's share of a beam3's length
MID_SHARE = 1.0 / math.sqrt(3.0)                   # the middle node's share


class Model:
    """An MBDyn model being written: nodes, elements, and the nodes whose motion is output."""

    def __init__(self):
        self.nodes, self.elements, self.out = [], [], set()
        self.counts = dict(structural=0, bodies=0, beams=0, joints=0, forces=0)
        self.nl = 0
        self.el = 0

    def node(self, x, vel=(0.0, 0.0, 0.0), omega=(0.0, 0.0, 0.0), output=False):
        self.nl += 1
        self.counts["structural"] += 1
        self.nodes.append(f"structural: {self.nl}, dynamic, {vec(x)}, eye, {vec(vel)}, {vec(omega)}, "
                          f"output, {'yes' if output else 'no'};")
        return self.nl

    def element(self, kind, text):
        self.el += 1
        self.counts[kind] += 1
        key = dict(bodies="body", beams="beam3", joints="joint", forces="force")[kind]
        self.elements.append(f"{key}: {self.el}, {text};")
        return self.el

    def beam_line(self, p0, p1, n, section_orientation, law, mass_per_length, rho_inertia, first=None, last=None,
                  vel=None, omega=(0.0, 0.0, 0.0)):
        """n beam3 elements from p0 to p1 on 2n + 1 nodes (first/last: existing nodes to reuse),
        with the lumped bodies; rho_inertia: the section's rotary inertia per length in the global
        frame at t = 0 (diagonal). vel(s): the initial velocity at the abscissa s. Returns the nodes."""
        p0, p1 = [float(c) for c in p0], [float(c) for c in p1]
        length = math.dist(p0, p1)
        nodes = []
        for i in range(2 * n + 1):
            s = length * i / (2 * n)
            x = [a + (b - a) * i / (2 * n) for a, b in zip(p0, p1)]
            if i == 0 and first is not None:
                nodes.append(first)
            elif i == 2 * n and last is not None:
                nodes.append(last)
            else:
                nodes.append(self.node(x, vel(s) if vel else (0.0, 0.0, 0.0), omega))
        le = length / n
        for e in range(n):
            a, b, c = nodes[2 * e:2 * e + 3]
            for nd, share in ((a, END_SHARE), (b, MID_SHARE), (c, END_SHARE)):
                ell = share * le
                m = mass_per_length * ell
                inertia = [rho_inertia[k] * ell for k in range(3)]
                self.element("bodies", f"{nd}, {m!r}, null, diag, {inertia[0]!r}, {inertia[1]!r}, {inertia[2]!r}")
            self.element("beams", f"{a}, null, {b}, null, {c}, null, {section_orientation}, {law}, same, same")
        return nodes

    def text(self, h, tend, method, tol, extra_control=""):
        c = self.counts
        control = [f"structural nodes: {c['structural']};"]
        for k, key in (("bodies", "rigid bodies"), ("beams", "beams"), ("joints", "joints"), ("forces", "forces")):
            if c[k]:
                control.append(f"{key}: {c[k]};")
        return "\n".join([
            "# written by benches/peers/mbdyn_scenes.py",
            "begin: data;", "  problem: initial value;", "end: data;", "",
            "begin: initial value;",
            "  initial time: 0.;", f"  final time: {tend!r};", f"  time step: {h!r};",
            f"  method: {method};",
            f"  tolerance: {tol!r};", "  max iterations: 30;",
            f"  derivatives tolerance: {tol!r};", "  derivatives max iterations: 30;",
            "  derivatives coefficient: auto;",
            "  linear solver: umfpack;",
            "  threads: disable;",
            "end: initial value;", "",
            "begin: control data;", "  default output: none, structural nodes;", "  output precision: 16;",
            *["  " + line for line in control], extra_control,
            "end: control data;", "",
            "begin: nodes;", *["  " + line for line in self.nodes], "end: nodes;", "",
            "begin: elements;", *["  " + line for line in self.elements], "end: elements;", ""])


def vec(v):
    return ", ".join(repr(float(c)) for c in v)


def law6(EA, GA2, GA3, GJ, EI2, EI3):
    return f"linear elastic generic, diag, {EA!r}, {GA2!r}, {GA3!r}, {GJ!r}, {EI2!r}, {EI3!r}"


# --------------------------------------------------------------- right-angle cantilever
def cantilever(n):
    """decks/benchmarks/right_angle_cantilever.dat: two legs of 10 m, n beam3 each, sharing
    the elbow node (MBDyn's beams are joined by their nodes: a weld is the shared node); the
    root clamped; the force along Z at the elbow 50 f(t), f the triangle 0 -> 1 at 1 s -> 0 at 2 s."""
    m = Model()
    law = law6(1e6, 1e6, 1e6, 1e3, 1e3, 1e3)
    root = m.node((0, 0, 0))
    elbow = m.node((10, 0, 0), output=True)
    tip = m.node((10, 10, 0), output=True)
    # leg 1 along X (section axis 1 = X, axis 2 = Y: the deck's AXIS2 0 1 0); leg 2 along Y
    # (axis 1 = Y, axis 2 = -X: AXIS2 -1 0 0); rho*J = 20 about the leg, rho*I = 10 across
    m.beam_line((0, 0, 0), (10, 0, 0), n, "eye", law, 1.0, (20.0, 10.0, 10.0), first=root, last=elbow)
    m.beam_line((10, 0, 0), (10, 10, 0), n, "1, 0., 1., 0., 2, -1., 0., 0.", law, 1.0, (10.0, 20.0, 10.0),
                first=elbow, last=tip)
    m.element("joints", f"clamp, {root}, node, node")
    m.element("forces", f"absolute, {elbow}, position, null, single, 0., 0., 1., "
                        "piecewise linear, 4, 0., 0., 1., 50., 2., 0., 30., 0.")

    def columns(mov, times):
        return [[t] + mov[elbow][k][:3] + mov[tip][k][:3] for k, t in times]

    return m, columns


# ------------------------------------------------------------------- Kane's spin-up beam
def spinup_angle(t, ws=4.0, T=15.0):
    if t <= T:
        return ws / T * (t * t / 2 + (T / (2 * math.pi)) ** 2 * (math.cos(2 * math.pi * t / T) - 1))
    return ws * (t - T / 2)


def spinup(n):
    """decks/benchmarks/spinup.dat (omega_s = 4 rad/s): a 10 m beam of n beam3 elements
    clamped to the hub node, whose position is held and whose orientation is imposed, a
    rotation theta(t) about Z (a total pin joint; theta the deck's expression as a string
    drive, min(t, T) written (t + T - |t - T|)/2 as in the deck)."""
    m = Model()
    EA, GA, GJ, EI = 2.8e7, 1e7, 1e4, 1.4e4
    hub = m.node((0, 0, 0))
    tip = m.node((10, 0, 0), output=True)
    m.beam_line((0, 0, 0), (10, 0, 0), n, "eye", law6(EA, GA, GA, GJ, EI, EI), 1.2, (1.2e-3, 6e-4, 6e-4),
                first=hub, last=tip)
    mt = "((Time+15.-abs(Time-15.))/2.)"
    theta = (f"4./15.*({mt}^2/2.+(15./(2.*pi))^2*(cos(2.*pi*{mt}/15.)-1.))+4.*(Time-{mt})")
    m.element("joints", f"total pin joint, {hub}, position, null, rotation orientation, eye, "
                        f"position, null, rotation orientation, eye, "
                        f"position constraint, active, active, active, null, "
                        f"orientation constraint, active, active, active, "
                        f"single, 0., 0., 1., string, \"{theta}\"")

    def columns(mov, times):
        rows = []
        for k, t in times:
            x, y = mov[tip][k][0], mov[tip][k][1]
            th = spinup_angle(t)
            rows.append([t, -x * math.sin(th) + y * math.cos(th)])
        return rows

    return m, columns


# -------------------------------------------------------------- flexible slider-crank
def slider_crank(n):
    """decks/benchmarks/slider_crank_flexible.dat: the crank pin's path imposed on the rod's
    first node (r = 0.15 m, 150 rad/s: a total pin joint imposing its position
    (r cos wt, r sin wt, 0) and leaving its rotation about Z free), the rod of n beam3
    elements (d = 6 mm steel), its end node held on the X axis (y, z and the rotations about
    X and Y) and carrying the slider's mass; every node starts with the rigid mechanism's
    velocity. Output: the mid-span deflection on the normal to the chord."""
    r, l, w, d, rho, E, nu = 0.15, 0.3, 150.0, 6e-3, 7870.0, 200e9, 0.3
    A, I = math.pi * d * d / 4, math.pi * d ** 4 / 64
    G = E / (2 * (1 + nu))
    m = Model()
    wr = -r * w / l

    def vel(s):
        return (0.0, r * w + wr * s, 0.0)

    # the deck's section: no shear factor given, so mecano-rs's default 5/6 (K of SECTIONS)
    law = law6(E * A, 5 / 6 * G * A, 5 / 6 * G * A, G * 2 * I, E * I, E * I)
    a = m.node((r, 0, 0), vel(0.0), (0, 0, wr), output=True)
    b = m.node((r + l, 0, 0), vel(l), (0, 0, wr), output=True)
    nodes = m.beam_line((r, 0, 0), (r + l, 0, 0), n, "eye", law, rho * A, (rho * 2 * I, rho * I, rho * I),
                        first=a, last=b, vel=vel, omega=(0, 0, wr))
    mid = nodes[n]
    m.nodes[mid - 1] = m.nodes[mid - 1].replace("output, no", "output, yes")
    m.element("bodies", f"{b}, {0.5 * rho * A * l!r}, null, null")
    m.element("joints", f"total pin joint, {a}, position, null, rotation orientation, eye, "
                        f"position, {r!r}, 0., 0., rotation orientation, eye, "
                        f"position constraint, active, active, active, "
                        f"component, string, \"{r!r}*(cos({w!r}*Time)-1.)\", string, \"{r!r}*sin({w!r}*Time)\", 0., "
                        f"orientation constraint, active, active, inactive, null")
    m.element("joints", f"total pin joint, {b}, position, null, rotation orientation, eye, "
                        f"position, {r + l!r}, 0., 0., rotation orientation, eye, "
                        f"position constraint, inactive, active, active, null, "
                        f"orientation constraint, active, active, inactive, null")

    def columns(mov, times):
        rows = []
        for k, t in times:
            pa, pm, pb = mov[a][k], mov[mid][k], mov[b][k]
            cx, cy = pb[0] - pa[0], pb[1] - pa[1]
            ln = math.hypot(cx, cy)
            nx, ny = -cy / ln, cx / ln
            rows.append([t, (pm[0] - 0.5 * (pa[0] + pb[0])) * nx + (pm[1] - 0.5 * (pa[1] + pb[1])) * ny])
        return rows

    return m, columns


BUILDERS = dict(cantilever=cantilever, spinup=spinup, slider_crank=slider_crank)


def read_mov(path):
    """{node: [[x, y, z, ...] per output block]} from MBDyn's .mov file."""
    out = {}
    with open(path) as f:
        for line in f:
            v = line.split()
            if v:
                out.setdefault(int(v[0]), []).append([float(c) for c in v[1:]])
    return out


def read_out(path):
    """[(time, Newton iterations)] of the converged steps, from MBDyn's .out file
    ('Step <n> <time> <dt> <iterations> <error> ...')."""
    steps = []
    with open(path) as f:
        for line in f:
            v = line.split()
            if len(v) >= 5 and v[0] == "Step":
                steps.append((int(v[1]), float(v[2]), int(v[4])))
    return steps


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", choices=sorted(SCENES))
    ap.add_argument("--h", type=float, required=True)
    ap.add_argument("--n", type=int, required=True)
    ap.add_argument("--tend", type=float, help="end time (default: the scene's)")
    ap.add_argument("--method", default="ms, 0.9",
                    help="MBDyn's integrator card (default: ms, 0.9, more accurate here than the manual's "
                         "compromise 0.6: 1.43e-2 against 1.60e-2 on the cantilever, 20 beam3 per leg, h = 0.025)")
    ap.add_argument("--tol", type=float,
                    help="Newton's tolerance on the residual's norm, N (default: the scene's; 1e-8 is below "
                         "the round-off floor of the cantilever's residual and Newton stalls at t = 3.5 s)")
    ap.add_argument("--mbdyn", default=DEFAULT_BIN)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    sc = SCENES[a.scene]
    tend = a.tend or sc["tend"]
    steps = int(round(tend / a.h))
    per = sc["period"] / a.h
    if abs(per - round(per)) > 1e-9 or abs(steps * a.h - tend) > 1e-9 * tend:
        sys.exit(f"h = {a.h} must divide the sampling period {sc['period']} and the end time {tend}")
    model, columns = BUILDERS[a.scene](a.n)
    base = os.path.splitext(os.path.abspath(a.out))[0]
    with open(base + ".mbd", "w") as f:
        f.write(model.text(a.h, tend, a.method, a.tol or sc["tol"]))
    for ext in (".mov", ".out", ".log"):
        if os.path.exists(base + ext):
            os.remove(base + ext)
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([a.mbdyn, "-f", base + ".mbd", "-o", base], capture_output=True, text=True)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    v = subprocess.run([a.mbdyn, "--version"], capture_output=True, text=True).stdout.split()
    version = v[v.index("Dynamics") + 1] if "Dynamics" in v[:-1] else "?"
    rec = dict(code="mbdyn", version=version, scene=a.scene, h=a.h, n=a.n, method=a.method, cpu=round(cpu, 4),
               ok=False)
    try:
        done = read_out(base + ".out")
        mov = read_mov(base + ".mov")
    except OSError as e:
        rec.update(why=f"no output ({e}); mbdyn: {(p.stderr or p.stdout).strip().splitlines()[-1:]}")
        print(json.dumps(rec))
        return 1
    blocks = len(next(iter(mov.values())))
    # one .mov block per converged step, after one for the initial state at t = 0
    times = [(0, 0.0)] + [(k + 1, s[1]) for k, s in enumerate(done)] if blocks == len(done) + 1 else \
        [(k, s[1]) for k, s in enumerate(done)]
    t_reached = done[-1][1] if done else 0.0
    rec.update(steps=sum(1 for s in done if s[0] > 0 and s[1] <= tend + 0.5 * a.h),
               newton=sum(s[2] for s in done if s[1] <= tend + 0.5 * a.h), t_reached=t_reached,
               ok=p.returncode == 0 and t_reached >= tend - 1e-9 * max(1.0, tend))
    # (MBDyn sums its steps and may take one past the final time: its rows after tend are dropped)
    keep = [(k, round(t / sc["period"]) * sc["period"]) for k, t in times
            if abs(t - round(t / sc["period"]) * sc["period"]) < 0.25 * a.h and t <= tend + 0.25 * a.h]
    rows = columns(mov, keep)
    if rec["ok"]:
        with open(a.out, "w") as f:
            f.write("t," + ",".join(sc["columns"]) + "\n")
            for row in rows:
                f.write(",".join(repr(float(v)) for v in row) + "\n")
    else:
        rec["why"] = ((p.stderr or p.stdout).strip().splitlines() or [f"stopped at t = {t_reached}"])[-1][:200]
    print(json.dumps(rec))
    return 0 if rec["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
