#!/usr/bin/env python3
"""A structure-aware fuzzer of mecano-rs (issue 35 §6): decks and command lines built from
the deck grammar (every keyword of grammar.md), with extreme numbers, run through the
binary with a per-case time limit, each case in a sandbox beside a decoy tree.

Run by hand (a bench, not a test), niced, e.g. for an hour on 2 workers:

    cargo build --release
    python3 benches/fuzz/fuzz.py --bin target/release/mecano-rs --minutes 60 --jobs 2 \
        --out /tmp/mecano-fuzz --seed 1

Each case is reproducible from (seed, case number): `--replay SEED:CASE` writes it to a
directory and prints its command line. Findings are copied to OUT/found/<class>/<seed>_<case>/
(deck.dat, cmd.txt, output.txt) and summarised at the end. Classes:

- crash:     a signal (SIGABRT, SIGSEGV, …), a Rust panic (exit 101, "panicked"), or an
             exit code other than 0, 1, 2 and 130;
- hang:      the case outlived its time limit (default 60 s; every generated run is short)
             and then ignored SIGINT for 15 s; one that ended on SIGINT is reported as
             `slow` (a legitimate long run: tight tolerances, checkpoints every ms), not a
             failure;
- outside:   something outside the case's output directory changed — the decoy tree (files,
             links into it planted in the output directory), or the sandbox gained an entry
             other than the output directory and the deck;
- silent:    exit 0 on a deck the generator made invalid on purpose, a NaN or infinity in an
             output file, a summary that is not `complete`, or a run's energy balance error
             above 0.1 with exit 0 and no `coarse_balance` notice (the warning a run gives
             when its balance closes that coarsely; the energy guard's bound is issue 35
             §0's);
- unlocated: exit 2 on a deck error with no `file:line:col` (the command line unchanged, so
             the deck is at fault).

The oracle is also what `tests/cli_io/fuzz_regressions.rs` applies to the cases kept as
regression tests (tests/deck/fuzz/).
"""

import argparse
import concurrent.futures as cf
import hashlib
import json
import math
import os
import random
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time

# --------------------------------------------------------------------------- numbers

EXTREME = [
    "0", "-0", "1e-100", "-1e-100", "1e100", "-1e100", "1e-101", "1e101", "1e308", "-1e308",
    "1e-308", "5e-324", "1e-320", "2.2250738585072014e-308", "1.7976931348623157e308",
    "4294967295", "4294967296", "18446744073709551616", "1e15", "1e-15", "3.0e-16",
    "1e300", "-1e300", "1e-300", "0.0000001", "1e20", "-1e20", "1e-30", "123456789012",
    "9e99", "1.0000000000000002", "0.9999999999999999", "1e999", "-1e999", "nan", "inf",
    "1e", ".", "-", "+.5", "0x10", "1,5", "$undefined", "(1/0)", "sqrt(-1)", "log(0)",
    "exp(1000)", "2^1024", "(1e200*1e200)", "((((1))))", "-(-(-1))", "pi", "1e-5*pi",
]


def extreme(rng):
    return rng.choice(EXTREME)


def num(rng, lo, hi, log=True, extreme_p=0.004):
    """A number between lo and hi (log-uniform when log), or now and then an extreme one."""
    if rng.random() < extreme_p:
        return extreme(rng)
    if log and lo > 0:
        v = math.exp(rng.uniform(math.log(lo), math.log(hi)))
    else:
        v = rng.uniform(lo, hi)
    if rng.random() < 0.05:
        # As an expression.
        return f"({v:.6g}*1)"
    return f"{v:.6g}"


def val(rng, lo, hi):
    """A plain log-uniform number between lo > 0 and hi."""
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def vec(rng, scale=1.0, extreme_p=0.004):
    return " ".join(num(rng, -scale, scale, log=False, extreme_p=extreme_p) for _ in range(3))


def unit(rng):
    while True:
        v = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in v))
        if n > 1e-3:
            return [x / n for x in v]


def perp(rng, a):
    while True:
        b = unit(rng)
        d = sum(x * y for x, y in zip(a, b))
        c = [y - d * x for x, y in zip(a, b)]
        n = math.sqrt(sum(x * x for x in c))
        if n > 1e-3:
            return [x / n for x in c]


def fmt3(v):
    return " ".join(f"{x:.12g}" for x in v)


# --------------------------------------------------------------------------- decks


class Deck:
    """A coherent model: a ground node, a chain of nodes and elements on it, functions,
    loads, an analysis and the output. Extreme values come in at a low rate; invalid
    tokens only through `mutate`."""

    def __init__(self, rng):
        self.rng = rng
        self.lines = []
        self.params = []
        self.functions = []  # (id, smooth)
        self.hinges = []
        self.nodes = []      # (id, position)
        self.elements = []
        self.next_el = 1

    def el(self):
        e = self.next_el
        self.next_el += 1
        self.elements.append(e)
        return e

    def build(self):
        r = self.rng
        out = []
        out.append(f"TITLE fuzz {r.randrange(10**6)}")
        if r.random() < 0.4:
            out.append("PARAMETERS")
            for k in range(r.randrange(1, 4)):
                name = f"p{k}"
                if k and r.random() < 0.5:
                    out.append(f"  {name} 2*$p{k-1}+{num(r, 0.1, 10)}")
                else:
                    out.append(f"  {name} {num(r, 1e-3, 1e3)}")
                self.params.append(name)
        # Materials and sections.
        out.append("MATERIALS")
        E = num(r, 1e6, 1e12)
        rho = num(r, 10, 1e4)
        nu_or_g = f"NU {num(r, 0.0, 0.49, log=False)}" if r.random() < 0.8 else f"G {num(r, 1e5, 1e11)}"
        damp = f" DAMPING {num(r, 1e-6, 1e-2)}" if r.random() < 0.2 else ""
        out.append(f"  1 E {E} {nu_or_g} RHO {rho}{damp}")
        out.append("SECTIONS")
        out.append(f"  1 A {num(r, 1e-6, 1e-2)} I2 {num(r, 1e-12, 1e-5)} I3 {num(r, 1e-12, 1e-5)} J {num(r, 1e-12, 1e-5)}"
                   + (f" K {num(r, 0.5, 1.0, log=False)}" if r.random() < 0.3 else ""))
        out.append(f"  2 RIGID A {num(r, 1e-4, 1e-2)}")
        out.append(
            f"  3 PROPERTIES EA {num(r, 1e3, 1e9)} GA2 {num(r, 1e3, 1e8)} GA3 {num(r, 1e3, 1e8)} GJ {num(r, 1e-1, 1e4)} &\n"
            f"     EI2 {num(r, 1e-1, 1e4)} EI3 {num(r, 1e-1, 1e4)} RHOA {num(r, 0.1, 10)} RHOJ {num(r, 1e-6, 1e-2)} "
            f"RHOI2 {num(r, 1e-6, 1e-2)} RHOI3 {num(r, 1e-6, 1e-2)}")
        out.append(f"  4 RIGID PROPERTIES RHOA {num(r, 0.1, 10)}")
        # Functions: every kind; some smooth (drivers need derivatives).
        out.append("FUNCTIONS")
        out.append("  1 TABLE 0 0 0.01 1 0.02 0")
        self.functions.append((1, False))
        out.append(f"  2 CONSTANT {num(r, 0.1, 10)}")
        out.append(f"  3 HAVERSINE {num(r, 0.0, 0.01, log=False)} {num(r, 1e-3, 1e-1)}")
        out.append(f"  4 SINE {num(r, 0.1, 2)} FREQ {num(r, 0.1, 50)}" + (f" PHASE {num(r, -3, 3, log=False)}" if r.random() < 0.3 else "")
                   + (f" START {num(r, 0, 0.01, log=False)}" if r.random() < 0.2 else ""))
        out.append(f"  5 COSINE {num(r, 0.1, 2)} OMEGA {num(r, 0.1, 300)}")
        out.append(f"  6 RAMP 0 0 {num(r, 1e-3, 0.05)} {num(r, 0.1, 2)}")
        out.append(f"  7 SPLINE 0 0 0.01 {num(r, 0.1, 1)} 0.02 0 0.03 {num(r, 0.1, 1)}")
        expr = r.choice(["sin(10*t)", "t^2", "0.5*t^2-sin(t)", "exp(-t)*cos(3*t)", "abs(t-0.01)", "1/(t-0.0123457)",
                         "sqrt(t+1)", "log(t+2)", "$p0*t" if self.params else "2*t", "t*1e100", "(t)"])
        out.append(f"  8 EXPR {expr}")
        for i in range(2, 9):
            self.functions.append((i, i != 1))
        # Nodes: the ground, a chain, a few free ones.
        out.append("NODES")
        out.append("  1 0 0 0 FIX ALL")
        self.nodes.append((1, [0, 0, 0]))
        n = r.randrange(2, 7)
        d = unit(r)
        L = val(r, 0.05, 3)
        for i in range(n):
            p = [x * L * (i + 1) for x in d]
            fix = ""
            if r.random() < 0.1:
                fix = " FIX " + " ".join(r.sample(["X", "Y", "Z", "RX", "RY", "RZ", "TRANS", "ROT"], r.randrange(1, 3)))
            out.append(f"  {i+2} {fmt3(p)}{fix}")
            self.nodes.append((i + 2, p))
        if r.random() < 0.3:
            last = n + 2
            out.append(f"  {last+1} TO {last+3} LINE {fmt3([0, 1, 0])} {fmt3([1, 1, 0])}")
            self.nodes += [(last + 1, [0, 1, 0]), (last + 2, [0.5, 1, 0]), (last + 3, [1, 1, 0])]
        if r.random() < 0.05:
            out.append(f"  FIX {r.choice(self.nodes)[0]} {r.choice(['X', 'RZ', 'ALL'])}")
        # A superelement (issue 38): the project's exported bar (decks/superelement/beam/,
        # FE nodes 1 at 0 and 2 at 1 m along x), copied into the case as fe/, hung from the
        # chain's tip; its interface nodes must sit as the FE nodes do.
        self.se = r.random() < 0.12
        if self.se:
            p = self.nodes[n][1]
            out.append(f"  90 {fmt3(p)}")
            out.append(f"  91 {fmt3([p[0] + 1.0, p[1], p[2]])}")
        # Elements.
        out.append("ELEMENTS")
        chain = [nid for nid, _ in self.nodes[: n + 1]]
        first = self.el()
        # Joint at the ground.
        kind = r.choice(["HINGE", "SPHERICAL", "UJOINT", "CLAMP", "PRISMATIC", "BEAM", "SPRING", "BUSHING", "CLEARANCE"])
        a = fmt3(unit(r))
        smooth = [f for f, s in self.functions if s]
        drive = f" DRIVE {r.choice(smooth)}" + (f" AMPLITUDE {num(r, 0.1, 10)}" if r.random() < 0.3 else "") if r.random() < 0.3 else ""
        if kind == "HINGE":
            out.append(f"  {first} HINGE 1 2 AXIS {a}{drive}")
            self.hinges.append(first)
        elif kind == "UJOINT":
            u = unit(r)
            out.append(f"  {first} UJOINT 1 2 AXIS1 {fmt3(u)} AXIS2 {fmt3(perp(r, u))}")
        elif kind == "PRISMATIC":
            out.append(f"  {first} PRISMATIC 1 2 AXIS {a}{drive}")
        elif kind == "BEAM":
            out.append(f"  {first} BEAM 1 2 MAT 1 SEC 1")
        elif kind == "SPRING":
            out.append(f"  {first} SPRING 1 2 K {num(r, 1, 1e7)} C {num(r, 0.0, 10, log=False)}")
        elif kind == "BUSHING":
            ks = " ".join(num(r, 1, 1e6) for _ in range(6))
            out.append(f"  {first} BUSHING 1 2 K {ks}" + (f" C {' '.join(num(r, 0.0, 10, log=False) for _ in range(6))}" if r.random() < 0.5 else ""))
        elif kind == "CLEARANCE":
            rad = val(r, 0.01, 0.1)
            out.append(f"  {first} CLEARANCE 1 2 AXIS {a} RADIUS {rad:.6g} CLEARANCE {num(r, 1e-5, 1e-3)} "
                       f"LAW {r.choice(['KV', 'LN'])} {num(r, 1e5, 1e10)} {num(r, 0.0, 1, log=False)}"
                       + (f" EXPONENT {num(r, 1, 2, log=False)}" if r.random() < 0.3 else "")
                       + (f" MU {num(r, 0, 0.5, log=False)}" if r.random() < 0.3 else ""))
        else:
            out.append(f"  {first} {kind} 1 2")
        # Beams along the chain.
        for i in range(1, len(chain) - 1):
            e = self.el()
            sec = r.choice(["MAT 1 SEC 1", "MAT 1 SEC 1", "SEC 3", "MAT 1 SEC 2", "SEC 4"])
            extra = ""
            if r.random() < 0.2:
                extra += f" DIVIDE {r.choice(['2', '3', '5', str(r.randrange(1, 40))])}"
            if r.random() < 0.15:
                extra += f" ORDER {r.randrange(1, 6)}"
            if r.random() < 0.2:
                extra += f" AXIS2 {fmt3(perp(r, d))}"
            if r.random() < 0.05:
                pa, pb = self.nodes[i][1], self.nodes[i + 1][1]
                mid = [(x + y) / 2 for x, y in zip(pa, pb)]
                off = perp(r, d)
                extra += f" ARC {fmt3([m + o * L for m, o in zip(mid, off)])}"
            out.append(f"  {e} BEAM {chain[i]} {chain[i+1]} {sec}{extra}")
        tip = chain[-1]
        e = self.el()
        out.append(f"  {e} MASS {tip} M {num(r, 0.01, 100)}" + (f" INERTIA {num(r, 1e-4, 1)} {num(r, 1e-4, 1)} {num(r, 1e-4, 1)}" if r.random() < 0.5 else ""))
        if self.se:
            e = self.el()
            joint = r.choice(["HINGE", "SPHERICAL", "CLAMP"])
            axis = f" AXIS {fmt3(unit(r))}" if joint == "HINGE" else ""
            out.append(f"  {e} {joint} {tip} 90{axis}")
            e = self.el()
            modes = r.choice(["0", "2", "4", "6", "8", "42", "43", str(r.randrange(0, 60)), "-1"])
            out.append(f"  {e} SUPERELEMENT FILES {r.choice(['fe', 'fe', 'fe', 'nowhere'])} MODES {modes} INTERFACE 1 90 2 91"
                       + (f" CACHE {r.choice(['ON', 'OFF'])}" if r.random() < 0.3 else ""))
        extras = r.randrange(0, 3)
        for _ in range(extras):
            k = r.choice(["RSPRING", "CAME", "RIGID", "PRESCRIBED", "SPRING", "MASS", "SPHERICAL", "BUSHING", "CONTROL"])
            e = self.el()
            if k == "RSPRING" and self.hinges:
                out.append(f"  {e} RSPRING {self.hinges[0]} K {num(r, 0.1, 1e4)} C {num(r, 0.0, 1, log=False)}"
                           + (f" FRICTION {num(r, 0.0, 1, log=False)} WREG {num(r, 1e-3, 1)}" if r.random() < 0.3 else ""))
            elif k == "CAME":
                ground = len(self.nodes) + 1
                out.append(f"  {e} CAME 1 {tip} CAM LINE FOLLOWER POINT K {num(r, 1e3, 1e9)} C {num(r, 0, 100, log=False)}"
                           + (f" MU {num(r, 0, 0.5, log=False)}" if r.random() < 0.3 else "")
                           + (f" CLIP {r.choice(['ON', 'OFF'])}" if r.random() < 0.3 else "")
                           + (f" IMPACT_STEPS {r.randrange(1, 50)}" if r.random() < 0.2 else ""))
            elif k == "RIGID" and len(chain) >= 3:
                out.append(f"  {e} RIGID {chain[-2]} {chain[-1]}")
            elif k == "PRESCRIBED":
                what = r.choice(["X", "Y", "Z", f"ROTATION AXIS {fmt3(unit(r))}"])
                out.append(f"  {e} PRESCRIBED {tip} {what} FUNCTION {r.choice([3, 4, 6])}" + (f" AMPLITUDE {num(r, 1e-3, 1)}" if r.random() < 0.5 else ""))
            elif k == "CONTROL":
                # A law of sensors (issue 36 §6): a PD on a hinge, or a spring-damper force.
                if self.hinges and r.random() < 0.5:
                    h = self.hinges[0]
                    out.append(f"  {e} CONTROL TORQUE {h} LAW ({num(r, 0.1, 1e4)}*(sin(t)-angle({h}))-{num(r, 0.0, 100, log=False)}*rate({h}))")
                else:
                    ax = r.choice(["x", "y", "z"])
                    out.append(f"  {e} CONTROL FORCE {tip} {ax.upper()} LAW (-{num(r, 0.1, 1e6)}*{ax}({tip})-{num(r, 0.0, 100, log=False)}*v{ax}({tip}))")
            elif k == "SPRING":
                out.append(f"  {e} SPRING 1 {tip} K {num(r, 1, 1e6)}" + (f" L0 {num(r, 0.1, 5)}" if r.random() < 0.3 else "")
                           + (" CURVE 7" if r.random() < 0.1 else ""))
            elif k == "BUSHING":
                out.append(f"  {e} BUSHING 1 {tip} K {' '.join(num(r, 1, 1e6) for _ in range(6))} AXES {fmt3(d)} {fmt3(perp(r, d))}")
            elif k == "SPHERICAL" and len(chain) >= 3:
                out.append(f"  {e} SPHERICAL {chain[-2]} {chain[-1]}")
            else:
                out.append(f"  {e} MASS {r.choice(chain[1:])} M {num(r, 0.01, 10)}")
        # Loads, initial velocities.
        out.append("LOADS")
        if r.random() < 0.6:
            out.append(f"  GRAVITY {vec(r, 10)}")
        if r.random() < 0.6:
            out.append(f"  {r.choice(['FORCE', 'MOMENT'])} {tip} {vec(r, 100)} FUNCTION {r.choice([f for f, _ in self.functions])}")
        if r.random() < 0.3:
            out.append("INITIAL")
            out.append(f"  {tip} V {vec(r, 1)}" + (f" W {vec(r, 1)}" if r.random() < 0.5 else ""))
        # Analysis: short runs.
        kind = r.choices(["DYNAMIC", "STATIC", "MODES"], [0.7, 0.15, 0.15])[0]
        if kind == "DYNAMIC":
            h = val(r, 1e-5, 1e-2)
            steps = r.randrange(3, 150)
            scheme = r.choice(["", "ALPHA -0.1", "ALPHA 0", "GENALPHA", "GENALPHA RHOINF 0.5", "ESDIRK3", "ESDIRK5", "ALPHA -0.3333"])
            extra = ""
            if r.random() < 0.25:
                extra += f" ADAPTIVE TOLPOS {num(r, 1e-6, 1e-3)} TOLROT {num(r, 1e-6, 1e-3)}" + (f" GROWTH {num(r, 1, 4, log=False)}" if r.random() < 0.3 else "")
            if r.random() < 0.2:
                extra += f" MINSTEP {h / r.choice([2, 16, 1024, 1e6]):.6g}"
            if r.random() < 0.1:
                extra += f" MAXSTEP {h * r.choice([1, 2, 10]):.6g}"
            if r.random() < 0.2:
                extra += f" TOL {num(r, 1e-12, 1e-4)} TOLINC {num(r, 1e-12, 1e-4)}"
            if r.random() < 0.1:
                extra += f" MAXIT {r.randrange(1, 60)}"
            if r.random() < 0.1:
                extra += f" NEWTON {r.choice(['FULL', 'MODIFIED'])}"
            out.append(f"ANALYSIS DYNAMIC {scheme} STEP {h:.6g} END {h * steps:.6g}{extra}")
        elif kind == "STATIC":
            out.append(f"ANALYSIS STATIC STEPS {r.randrange(1, 20)}" + (f" MAXIT {r.randrange(1, 50)}" if r.random() < 0.2 else ""))
        else:
            out.append(f"ANALYSIS MODES {r.choice(['1', '3', '10', '4294967295', str(r.randrange(1, 100))])}" + (" ROTATING" if r.random() < 0.3 else ""))
        sel = r.choice(["", "NODES ALL", f"NODES {tip}", "NODES NONE ELEMENTS ALL", f"NODES {tip} ELEMENTS {first}"])
        extra = ""
        if r.random() < 0.2:
            extra += f" EVERY {r.randrange(1, 5)}"
        if r.random() < 0.1:
            extra += " VTK"
        if r.random() < 0.1:
            extra += " FORMAT NETCDF"
        if sel or extra:
            out.append(f"OUTPUT {sel}{extra}".rstrip())
        if r.random() < 0.3:
            out.append("END")
        return "\n".join(out) + "\n"


HOSTILE = EXTREME + ["TO", "END", "ALL", "&", "!", "#", "$", "()", "\u00e9", "\u0000", "\ufeff", "\r",
                     "BEAM", "CAME", "RIGID", "SPLINE 2", "FIX", "DRIVE 1", "MODES", "ROTATING",
                     "(" * 101 + "1" + ")" * 101, "(" * 100 + "1" + ")" * 100, "9" * 2000, "x" * 1100]


def mutate(rng, text):
    """Token-level mutations; returns (text, surely_invalid)."""
    lines = text.split("\n")
    invalid = False
    for _ in range(rng.randrange(1, 4)):
        if not lines:
            break
        i = rng.randrange(len(lines))
        toks = lines[i].split(" ")
        op = rng.randrange(8)
        edits_tokens = op in (0, 1, 2, 3, 6)
        if op <= 2 and toks:
            j = rng.randrange(len(toks))
            t = rng.choice(HOSTILE)
            toks[j] = t
        elif op == 3 and toks:
            del toks[rng.randrange(len(toks))]
        elif op == 4:
            lines.insert(i, lines[i])
        elif op == 5:
            j = rng.randrange(len(lines))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == 6:
            # A number in range swapped for an extreme one.
            nums = [k for k, t in enumerate(toks) if t[:1].isdigit() or t[:1] == "-"]
            if nums:
                toks[rng.choice(nums)] = extreme(rng)
        else:
            # A card no section accepts: surely invalid.
            lines.insert(0, f"ZZZ{rng.randrange(1000)} 1 2")
            invalid = True
        if edits_tokens:
            lines[i] = " ".join(toks)
    return "\n".join(lines), invalid


# --------------------------------------------------------------------------- command lines


def command(rng, deck_text):
    """The argument list (the deck is `deck.dat`, the output directory `out`)."""
    mode = rng.choices(["run", "check", "modes", "resume"], [0.55, 0.25, 0.17, 0.03])[0]
    extra = []
    if rng.random() < 0.08:
        extra += ["--refine", rng.choice(["1", "2", "3", "2", "1000000", "0", "4294967296"])]
    if rng.random() < 0.05:
        extra += ["--max-memory", rng.choice(["1G", "100M", "1k", "0", "lots"])]
    if rng.random() < 0.08:
        name = rng.choice(["p0", "p1", "E", "nope", "1x", ""])
        value = rng.choice(["1", "2*3", "1e308", "(" * 100 + "1" + ")" * 100, "(" * 60000 + "1" + ")" * 60000, "1/0", "x", "-1e-100"])
        extra += ["--set", f"{name}={value}"]
    if mode == "run":
        args = ["deck.dat", "-q", "--checkpoint", rng.choices(["0", "0.001", "-1", "nan"], [0.7, 0.25, 0.025, 0.025])[0]]
        if rng.random() < 0.9:
            args += ["-o", "out"]
        if rng.random() < 0.2:
            args += ["--force"]
        return args + extra, mode
    if mode == "check":
        return ["--check", "deck.dat"] + extra, mode
    if mode == "modes":
        args = ["modes", "deck.dat", "-q", "-o", "out"]
        opt = rng.choice([[], ["--count", rng.choice(["1", "5", "4294967295", "0"])], ["--static"], ["--at", rng.choice(["0", "0.001", "1e308", "-1", "nan"])],
                          ["--rotating"], ["--solver", rng.choice(["dense", "sparse"])], ["--order", rng.choice(["1", "2", "17", "0"])], ["--force"]])
        return args + opt + extra, mode
    return ["resume", "out"], mode


# --------------------------------------------------------------------------- sandbox


def plant(rng, sandbox):
    """Output-directory plants: links into the decoy (dangling or not), foreign files, a
    subdirectory, a hostile manifest, a lock that is a link. Returns their description."""
    out = os.path.join(sandbox, "out")
    decoy = os.path.join(sandbox, "decoy")
    what = []
    if rng.random() < 0.7:
        return what
    os.makedirs(out, exist_ok=True)
    names = ["node_2.csv", "node_3.csv", "energy.csv", "summary.json", "summary.json.tmp", "checkpoint.bin",
             "checkpoint.bin.tmp", ".mecano-manifest", ".mecano-manifest.tmp", ".mecano-lock", "element_1.csv",
             "modes.csv", "histories.nc", "model.pvd", "vtk", "sub"]
    for _ in range(rng.randrange(1, 4)):
        name = rng.choice(names)
        p = os.path.join(out, name)
        if os.path.lexists(p):
            continue
        k = rng.randrange(6)
        if k == 0:
            os.symlink(os.path.join(decoy, "victim.txt"), p)
        elif k == 1:
            os.symlink(os.path.join(decoy, "nowhere_" + name), p)
        elif k == 2:
            os.symlink(os.path.join(decoy, "inner"), p)
        elif k == 3:
            with open(p, "w") as f:
                f.write("foreign\n")
        elif k == 4:
            os.makedirs(os.path.join(p, "deep"), exist_ok=True)
            with open(os.path.join(p, "deep", "x.txt"), "w") as f:
                f.write("x")
        else:
            os.mkfifo(p)
        what.append(f"{name}:{k}")
    if rng.random() < 0.3 and not os.path.lexists(os.path.join(out, ".mecano-manifest")):
        with open(os.path.join(out, ".mecano-manifest"), "w") as f:
            f.write("# mecano-rs output manifest v1\n")
            for e in ["sub/victim.txt", "../decoy/victim.txt", os.path.join(decoy, "victim.txt"), "node_2.csv",
                      "vtk/", "inner/deep.txt", "sub", ".mecano-lock", "."]:
                if rng.random() < 0.6:
                    f.write(e + "\n")
        what.append("manifest")
    return what


def make_decoy(sandbox):
    decoy = os.path.join(sandbox, "decoy")
    os.makedirs(os.path.join(decoy, "inner"))
    with open(os.path.join(decoy, "victim.txt"), "w") as f:
        f.write("precious\n")
    with open(os.path.join(decoy, "inner", "deep.txt"), "w") as f:
        f.write("deep\n")


def tree(root):
    """Every entry under `root`, not following links: kind and content hash or target."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for n in dirnames + filenames:
            p = os.path.join(dirpath, n)
            rel = os.path.relpath(p, root)
            if os.path.islink(p):
                out[rel] = "link " + os.readlink(p)
            elif os.path.isdir(p):
                out[rel] = "dir"
            elif os.path.isfile(p):
                with open(p, "rb") as f:
                    out[rel] = "file " + hashlib.sha256(f.read()).hexdigest()
            else:
                out[rel] = "other"
    return out


# --------------------------------------------------------------------------- oracle


LOCATED_OK = [  # exit-2 messages that are about the command line or the output directory
    "--set", "--refine", "--max-memory", "--count", "--at", "--static", "--rotating", "--order", "--checkpoint",
    "--solver", "invalid value", "unexpected argument", "output directory", "output path", "in use", "resume",
    "checkpoint", "cannot set parameter", "not UTF-8", "nothing to vibrate", "outside the deck's time span",
    "--at needs", "no such", "is not a regular file", "symbolic link", "the model refined", "ANALYSIS MODES",
    "usage:", "Usage:", "required", "a FIFO", "is a directory", "not a directory",
]


def judge(case):
    """The classes of a finished case (a list; empty when it passed)."""
    found = []
    rc, out = case["rc"], case["output"]
    if case["timeout"]:
        return ["hang"]
    if case.get("slow"):
        found.append("slow")
        rc = 130 if rc in (130, -2) else rc
    if rc is None or rc < 0 or rc not in (0, 1, 2, 130) or "panicked" in out or "RUST_BACKTRACE" in out:
        found.append("crash")
    if case["decoy_before"] != case["decoy_after"] or case["outside"]:
        found.append("outside")
    if rc == 0 and case["invalid"] and case["mode"] in ("run", "check", "modes"):
        found.append("silent")
    if rc == 0 and case["mode"] == "run":
        bad = case.get("nonfinite")
        s = case.get("summary")
        if bad:
            found.append("silent")
        elif s is not None and s.get("complete") is not True and "modes" not in s:
            found.append("silent")
        elif s is not None:
            e = (s.get("energy") or {}).get("max_balance_error")
            scale = case.get("energy_scale") or 0.0
            # Judged only where the energies are physical (> 1 µJ): at round-off scale
            # (1e-20 J, a load on a fixed node) the relative balance is noise.
            # A run that says so (the `coarse_balance` notice of summary.json, printed as
            # a warning) is not silent: it is a coarse step the user is told about.
            warned = any(n.get("kind") == "coarse_balance" for n in s.get("notices") or [])
            if isinstance(e, (int, float)) and e > 0.1 and scale > 1e-6 and not warned:
                case["note"] = f"max_balance_error {e:.3g}, energy scale {scale:.3g} J"
                found.append("silent")
    if rc == 2 and case["plain"]:
        located = "deck.dat:" in out or "╭─[" in out
        if not located and not any(k in out for k in LOCATED_OK):
            found.append("unlocated")
    return found


def scan_outputs(out_dir):
    """NaN/inf in any text output (CSV, JSON), and the summary."""
    nonfinite = []
    summary = None
    if not os.path.isdir(out_dir) or os.path.islink(out_dir):
        return nonfinite, summary
    for dirpath, _, files in os.walk(out_dir):
        for n in files:
            p = os.path.join(dirpath, n)
            if os.path.islink(p) or not os.path.isfile(p) or not (n.endswith(".csv") or n.endswith(".json")):
                continue
            with open(p, "rb") as f:
                b = f.read(50 << 20)
            low = b.lower()
            if b"nan" in low or b"inf" in low:
                # "inf" in JSON text (e.g. "infinity" words in a note) is allowed only as a word
                if n.endswith(".csv") or b"NaN" in b or b": inf" in low:
                    nonfinite.append(os.path.relpath(p, out_dir))
            if n == "summary.json" and dirpath == out_dir:
                try:
                    summary = json.loads(b)
                except Exception:
                    nonfinite.append("summary.json (not JSON)")
    return nonfinite, summary


# --------------------------------------------------------------------------- one case


def generate(seed, k):
    """The case (seed, k): deck text, arguments, whether the deck is invalid on purpose,
    whether the command line is plain, plants rng seed."""
    rng = random.Random(seed * 1_000_003 + k)
    text = Deck(rng).build()
    invalid = False
    if rng.random() < 0.3:
        text, invalid = mutate(rng, text)
    args, mode = command(rng, text)
    plain = mode in ("run", "check") and not any(a.startswith("--") and a not in ("--check", "--checkpoint") for a in args[1:])
    return text, args, mode, invalid, plain, rng.randrange(1 << 30)


def run_case(binary, root, seed, k, limit):
    text, args, mode, invalid, plain, plant_seed = generate(seed, k)
    slow_note = [""]
    sandbox = tempfile.mkdtemp(prefix=f"c{seed}_{k}_", dir=root)
    with open(os.path.join(sandbox, "deck.dat"), "w", encoding="utf-8", errors="surrogatepass") as f:
        f.write(text)
    if "SUPERELEMENT FILES fe " in text:
        repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        shutil.copytree(os.path.join(repo, "decks", "superelement", "beam"), os.path.join(sandbox, "fe"))
    make_decoy(sandbox)
    plants = plant(random.Random(plant_seed), sandbox)
    decoy_before = tree(os.path.join(sandbox, "decoy"))
    before = set(os.listdir(sandbox))
    parent_before = set(os.listdir(root))
    t0 = time.time()
    timeout = False
    # No case may take the shared machine's memory: the model estimate is capped by
    # --max-memory (unless the case gives its own), the address space by RLIMIT_AS (an
    # allocation beyond it must be an error, not an abort).
    if "--max-memory" not in args and mode != "resume":
        args = args + ["--max-memory", "2G"]

    def limits():
        resource.setrlimit(resource.RLIMIT_AS, (6 << 30, 6 << 30))

    p = subprocess.Popen(["nice", "-n", "19", binary] + args, cwd=sandbox, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, preexec_fn=limits,
                         env={**os.environ, "MECANO_FAILPOINT": "", "RUST_BACKTRACE": "0"})
    try:
        so, se = p.communicate(timeout=limit)
        rc = p.returncode
    except subprocess.TimeoutExpired:
        # Slow or hung? A bounded loop hears SIGINT: the run ends at its next step (130),
        # --check and modes at once. Only a process that ignores it is a hang.
        p.send_signal(signal.SIGINT)
        t_int = time.time()
        try:
            so, se = p.communicate(timeout=15)
            rc = p.returncode
            case_note = f"slow: ended {rc} {time.time() - t_int:.1f} s after SIGINT at {limit:.0f} s"
        except subprocess.TimeoutExpired:
            p.kill()
            so, se = p.communicate()
            rc = None
            timeout = True
            case_note = "ignored SIGINT for 15 s"
        slow_note[0] = case_note
    output = (so + se).decode("utf-8", "replace")
    dt = time.time() - t0
    after = set(os.listdir(sandbox))
    new = sorted(after - before - {"out", "deck.dat", "decoy"})
    # A deck's own OUTPUT DIR (none generated) or the default out/deck when -o is absent.
    new = [n for n in new if n not in ("out",)]
    outside = new if new != [] else []
    parent_after = set(os.listdir(root))
    foreign = sorted(parent_after - parent_before - {os.path.basename(sandbox)})
    # Other workers' sandboxes appear in the parent: only entries not named like a case.
    foreign = [f for f in foreign if not f.startswith("c")]
    # The run's directory: -o out, else the default out/<deck name> (modes: …/modes).
    run_dir = os.path.join(sandbox, "out")
    if "-o" not in args:
        run_dir = os.path.join(run_dir, "deck", "modes" if mode == "modes" else "")
    nonfinite, summary = scan_outputs(run_dir)
    energy_scale = 0.0
    ecsv = os.path.join(run_dir, "energy.csv")
    if os.path.isfile(ecsv) and not os.path.islink(ecsv):
        try:
            with open(ecsv) as f:
                head = f.readline().strip().split(",")
                cols = [head.index(c) for c in ("kinetic", "strain", "gravity", "external_work")]
                for line in f:
                    v = line.split(",")
                    energy_scale = max(energy_scale, sum(abs(float(v[c])) for c in cols))
        except (ValueError, IndexError):
            pass
    case = {
        "seed": seed, "case": k, "args": args, "mode": mode, "invalid": invalid, "plain": plain,
        "plants": plants, "rc": rc, "timeout": timeout, "seconds": dt, "output": output[-20000:],
        "decoy_before": decoy_before, "decoy_after": tree(os.path.join(sandbox, "decoy")),
        "outside": outside + foreign, "nonfinite": nonfinite, "summary": summary,
        "energy_scale": energy_scale,
    }
    if slow_note[0]:
        case["note"] = slow_note[0]
        case["slow"] = not timeout
    case["classes"] = judge(case)
    if case["classes"]:
        case["sandbox_deck"] = text
    shutil.rmtree(sandbox, ignore_errors=True)
    return case


def save(out_root, case):
    for c in case["classes"]:
        d = os.path.join(out_root, "found", c, f"{case['seed']}_{case['case']}")
        os.makedirs(d, exist_ok=True)
        with open(os.path.join(d, "deck.dat"), "w", encoding="utf-8", errors="surrogatepass") as f:
            f.write(case["sandbox_deck"])
        with open(os.path.join(d, "cmd.txt"), "w") as f:
            f.write(" ".join(case["args"]) + "\n")
            f.write(f"plants: {case['plants']}\nrc: {case['rc']} timeout: {case['timeout']} seconds: {case['seconds']:.1f}\n")
            f.write(f"note: {case.get('note', '')}\noutside: {case['outside']}\nnonfinite: {case['nonfinite']}\n")
        with open(os.path.join(d, "output.txt"), "w") as f:
            f.write(case["output"])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="target/release/mecano-rs")
    ap.add_argument("--minutes", type=float, default=10)
    ap.add_argument("--cases", type=int, default=0, help="stop after this many cases (0: by time)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--limit", type=float, default=60, help="seconds per case")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="/tmp/mecano-fuzz")
    ap.add_argument("--replay", help="SEED:CASE: write that case to OUT/replay and print its command")
    a = ap.parse_args()
    binary = os.path.abspath(a.bin)
    os.makedirs(a.out, exist_ok=True)
    if a.replay:
        seed, k = map(int, a.replay.split(":"))
        text, args, mode, invalid, plain, plant_seed = generate(seed, k)
        d = os.path.join(a.out, "replay", f"{seed}_{k}")
        shutil.rmtree(d, ignore_errors=True)
        os.makedirs(d)
        with open(os.path.join(d, "deck.dat"), "w") as f:
            f.write(text)
        make_decoy(d)
        print("plants:", plant(random.Random(plant_seed), d))
        print(f"cd {d} && {binary} {' '.join(args)}")
        return
    root = tempfile.mkdtemp(prefix="cases_", dir=a.out)
    deadline = time.time() + 60 * a.minutes
    counts, classes, findings = {}, {}, []
    slowest = []
    t0 = time.time()
    k = 0
    with cf.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        running = set()
        while True:
            while len(running) < a.jobs and time.time() < deadline and (a.cases == 0 or k < a.cases):
                running.add(pool.submit(run_case, binary, root, a.seed, k, a.limit))
                k += 1
            if not running:
                break
            done, running = cf.wait(running, return_when=cf.FIRST_COMPLETED)
            for f in done:
                c = f.result()
                key = f"{c['mode']}:{c['rc']}"
                counts[key] = counts.get(key, 0) + 1
                slowest.append((c["seconds"], c["case"]))
                for cl in c["classes"]:
                    classes[cl] = classes.get(cl, 0) + 1
                if c["classes"]:
                    findings.append(c)
                    save(a.out, c)
                    print(f"case {c['seed']}:{c['case']} {c['classes']} rc={c['rc']} {' '.join(c['args'])[:120]} {c.get('note', '')}",
                          flush=True)
    n = sum(counts.values())
    slowest.sort(reverse=True)
    report = {
        "cases": n, "seconds": time.time() - t0, "seed": a.seed, "jobs": a.jobs, "limit": a.limit,
        "outcomes": dict(sorted(counts.items())), "classes": classes,
        "slowest": slowest[:5],
        "findings": [{"case": f"{c['seed']}:{c['case']}", "classes": c["classes"], "rc": c["rc"], "args": c["args"], "note": c.get("note", "")} for c in findings],
    }
    with open(os.path.join(a.out, f"report_{a.seed}.json"), "w") as f:
        json.dump(report, f, indent=1)
    print(json.dumps({k: v for k, v in report.items() if k != "findings"}, indent=1))
    shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
