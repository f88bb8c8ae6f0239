#!/usr/bin/env python3
"""The converged decks of the benchmarks and their golden references (issue 37, item 2).

    python3 benches/peers/converged.py [--out out/peers] [--decks] [--golden] [--table] [--rounds R]

For each scene of CONVERGED, the configuration chosen from benches/peers/bench.py's ladder
(the cheapest run whose error plus the reference's own error meets the target; docs/benchmarks.md,
"The converged decks"):

--decks   writes decks/benchmarks/<name>_converged.dat: the scene's deck with that mesh,
          integrator, step and output interval (scenes.deck_text), under a header stating
          the claim (measured error, reference, what it is converged in);
--golden  writes tests/golden/converged/<scene>.csv: the reference's compared quantity at the
          deck's output instants (every `thin`-th), its first line `# target T
          reference_error E` (tests/validation/converged.rs asserts error + E <= T);
--table   runs each shipped deck with the release binary (best CPU of --rounds) and prints
          the docs' table: error against the reference, steps, Newton iterations,
          factorisations, CPU.

Needs OUT/<scene>/ref and OUT/<scene>/check from bench.py (`bench.py --codes mecano-rs
--scenes ...` computes them) and, for --table, target/release/mecano-rs.
"""
import argparse
import json
import os
import re
import subprocess
import sys

PEERS = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, PEERS)
import bench  # noqa: E402
from scenes import SCENES, deck_text, leg, mk, rod, bar4  # noqa: E402

ROOT = bench.ROOT

# scene -> (deck written, configuration, golden thinning, the claim's wording of the mesh)
CONVERGED = {
    "pendulum": dict(deck="decks/pendulum_converged.dat", cfg=None, thin=2),
    "pendulum_time": dict(deck="decks/pendulum_converged.dat", cfg=None, thin=2),
    "cantilever": dict(deck="decks/benchmarks/right_angle_cantilever_converged.dat",
                       cfg=leg(0.025, 1, 6, "ALPHA 0"), thin=1),
    "spinup": dict(deck="decks/benchmarks/spinup_converged.dat",
                   cfg=mk(None, 0.01, 1, 3, "ALPHA -0.05"), thin=1),
    "slider_crank": dict(deck="decks/benchmarks/slider_crank_flexible_converged.dat",
                         cfg=rod(1.6e-4, 1, 3, "ESDIRK5"), thin=1),
    "four_bar": dict(deck="decks/benchmarks/four_bar_bauchau_converged.dat",
                     cfg=bar4(0.02, 1, 2, "GENALPHA RHOINF 0"), thin=1),
    "slider_crank_ideal": dict(deck="decks/benchmarks/slider_crank_ideal_converged.dat",
                               cfg=mk(None, 4e-4, 1, 1, "ESDIRK5"), thin=1),
    "slider_crank_clearance": dict(deck="decks/benchmarks/slider_crank_clearance_converged.dat",
                                   cfg=mk(None, 4e-5, 1, 1, "ALPHA -0.05"), thin=1),
}

WHAT = {
    "pendulum": "nodes 12 and 23's positions",
    "pendulum_time": "nodes 12 and 23's positions, against the deck's own mesh at a tenth of its step",
    "cantilever": "the elbow's and the tip's positions (nodes 2 and 3)",
    "spinup": "the tip's deflection in the rotating frame, -x sin(theta) + y cos(theta) of node 3",
    "slider_crank": "the rod's mid-span deflection (node 12 from the chord of nodes 10 and 14, on its normal)",
    "four_bar": "the out-of-plane displacement (Z) of the mid-spans 11, 21 and 31",
    "slider_crank_clearance": "the slider's position (x of node 8)",
    "slider_crank_ideal": "the slider's acceleration (x of node 8)",
}


def reference(scene, out):
    if "exact" in SCENES[scene]:
        bench.Exact.error = bench.Reference.error
        ref = bench.Exact(scene)
        amp = ref.amplitude()
        return ref, 0.0, amp, 1e-3 * amp
    sd = os.path.join(out, scene)
    ref = bench.Reference(scene, os.path.join(sd, "ref"))
    check_err, _ = ref.error(bench.mecano_channels(scene, os.path.join(sd, "check")))
    amp = ref.amplitude()
    target = SCENES[scene].get("target") or 1e-3 * amp
    return ref, check_err, amp, target


def run_deck(deck, out):
    """Runs a shipped deck; (record, rows of its compared quantity)."""
    os.makedirs(out, exist_ok=True)
    cpu0 = bench.children_cpu()
    p = subprocess.run([bench.BIN, os.path.join(ROOT, deck), "-o", out, "--quiet", "--checkpoint", "0", "--force"],
                       capture_output=True, text=True)
    cpu = bench.children_cpu() - cpu0
    s = json.load(open(os.path.join(out, "summary.json")))
    assert s["complete"] and p.returncode == 0, (deck, p.stderr[-400:])
    st = s["stats"]
    return dict(cpu=cpu, steps=st["steps"], newton=st["newton_iterations"], factorisations=st["factorizations"])


def instants(scene, deck):
    """The deck's output instants: k * EVERY * STEP up to the end."""
    text = open(os.path.join(ROOT, deck)).read()
    a = re.search(r"^ANALYSIS DYNAMIC .*STEP\s+(\S+)\s+END\s+(\S+)", text, re.M)
    h, end = float(a.group(1)), float(a.group(2))
    o = re.search(r"^OUTPUT .*EVERY\s+(\d+)", text, re.M)
    every = int(o.group(1)) if o else 1
    n = int(round(end / (h * every)))
    return [k * every * h for k in range(n + 1)]


def header(scene, c, err, check_err, amp, target):
    sc = SCENES[scene]
    cfg = c["cfg"]
    base = sc["deck"]
    tend = sc["tend"]
    every = int(max(1, (sc["period"] / cfg["h"] + 1e-9) // 1))
    lines = [
        f"{c['deck']}: {sc['title'].split(',')[0]},",
        f"converged to 1e-3 of its motion for t <= {tend:g} s at the least cost measured",
        "(docs/benchmarks.md, \"The converged decks\").",
        f"Configuration: {cfg['mesh']}, {re.sub(r'^ALPHA', 'HHT alpha =', cfg['scheme'])}, fixed step",
        f"h = {cfg['h']:g} s, output every {every} step{'s' if every > 1 else ''}.",
        f"Claim: {WHAT[scene]}: largest distance {err:.3e}",
    ] + ([
        "at the output instants from the closed form of the rigid slider-crank at constant",
        "crank speed (the reference has no error of its own);",
    ] if "exact" in sc else [
        "at the output instants from the space-time-converged reference",
        f"({sc['ref']['label'].split(': ', 1)[1]}), whose own error is bounded by {check_err:.2e}",
        f"(its largest difference to {sc['check']['label'].split(': ', 1)[1]});",
    ]) + [
        f"target: 1e-3 of the motion's amplitude {amp:.4g}, {target:.3e}. Converged in "
        + ("the step (rigid bodies: no mesh):" if cfg["p"] * cfg["d"] == 1 else "the step and the mesh together:"),
        "the cheapest run of benches/peers/bench.py's ladder (docs/performance.md, docs/benchmarks.md)",
        "whose error plus the reference's own error meets the target.",
        "Asserted by tests/validation/converged.rs against " + (
            "the closed form." if "exact" in sc else f"tests/golden/converged/{scene}.csv."),
        f"The scene is {base}'s (its header gives the source and the data); only the",
        "mesh, the integrator, the step and the output interval differ",
        "(written by benches/peers/converged.py --decks).",
    ]
    return "".join(f"! {l}\n" for l in lines)


def write_deck(scene, c, err, check_err, amp, target):
    text = deck_text(scene, c["cfg"])
    lines = text.splitlines()
    while lines and (lines[0].startswith("!") or not lines[0].strip()):
        lines.pop(0)
    body = "\n".join(lines) + "\n"
    # parameters no longer used (the mesh and the step are now literal) are dropped
    out, in_params = [], False
    for line in body.splitlines():
        if re.match(r"^[A-Z]", line):
            in_params = line.startswith("PARAMETERS")
        m = re.match(r"^\s+([A-Za-z_]\w*)\s+\S", line)
        if in_params and m and not re.search(r"\$" + m.group(1) + r"\b", body):
            continue
        out.append(line)
    body = "\n".join(out) + "\n"
    body = re.sub(r"^PARAMETERS\n\n+(?=[A-Z])", "", body, flags=re.M)   # none left
    # a BEAM card's trailing comment about the old mesh goes with it
    body = re.sub(r"^(\s*\d+(?:\s+TO\s+\d+)?\s+BEAM\b[^!\n]*?)\s*!.*$", r"\1", body, flags=re.M)
    with open(os.path.join(ROOT, c["deck"]), "w") as f:
        f.write(header(scene, c, err, check_err, amp, target) + "\n" + body)


def write_golden(scene, c, ref, check_err, target):
    ts = instants(scene, c["deck"])[::c["thin"]]
    sc = SCENES[scene]
    path = os.path.join(ROOT, "tests", "golden", "converged", f"{scene}.csv")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    names = []
    for i, w in enumerate(sc["widths"]):
        names += [f"c{i}_{k}" for k in range(w)]
    with open(path, "w") as f:
        f.write(f"# target {target:.6e} reference_error {check_err:.6e}\n")
        f.write("t," + ",".join(names) + "\n")
        for t in ts:
            r = ref.at(t)
            assert r is not None, (scene, t)
            f.write(repr(round(t, 12)) + "," + ",".join(f"{v:.12e}" for ch in r for v in ch) + "\n")
    return len(ts)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "peers"))
    ap.add_argument("--scenes", default=",".join(CONVERGED))
    ap.add_argument("--decks", action="store_true")
    ap.add_argument("--golden", action="store_true")
    ap.add_argument("--table", action="store_true")
    ap.add_argument("--rounds", type=int, default=3)
    a = ap.parse_args()
    rows = []
    for scene in a.scenes.split(","):
        c = CONVERGED[scene]
        ref, check_err, amp, target = reference(scene, a.out)
        d = os.path.join(a.out, scene, "converged")
        rec = None
        for _ in range(a.rounds if a.table else 1):
            r = run_deck(c["deck"], d) if os.path.exists(os.path.join(ROOT, c["deck"])) else None
            if r and (rec is None or r["cpu"] < rec["cpu"]):
                rec = r
        if a.decks and c["cfg"] is not None:
            # the error of the configuration, measured on a run of the written deck
            write_deck(scene, c, float("nan"), check_err, amp, target)
            rec = run_deck(c["deck"], d)
            err, _ = ref.error(bench.mecano_channels(scene, d))
            write_deck(scene, c, err, check_err, amp, target)
        err, m = ref.error(bench.mecano_channels(scene, d))
        n = write_golden(scene, c, ref, check_err, target) if a.golden and "exact" not in SCENES[scene] else None
        rows.append((scene, c["deck"], err, check_err, target, rec, m, n))
        print(f"[{scene}] {c['deck']}: error {err:.3e} + reference {check_err:.2e} = {err + check_err:.3e} "
              f"<= target {target:.3e}? {err + check_err <= target}; {rec['steps']} steps, {rec['newton']} Newton, "
              f"{rec['factorisations']} factorisations, {rec['cpu']:.3f} s CPU; {m} instants"
              + (f"; golden {n} rows" if n else ""), flush=True)
    if a.table:
        print("\n| deck | error | reference's own error | target | steps | Newton | factorisations | CPU s |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
        for scene, deck, err, ce, target, rec, m, n in rows:
            print(f"| `{deck}` | {err:.2e} | {ce:.2e} | {target:.2e} | {rec['steps']:,} | {rec['newton']:,} | "
                  f"{rec['factorisations']:,} | {rec['cpu']:.3f} |")


if __name__ == "__main__":
    main()
