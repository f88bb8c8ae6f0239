#!/usr/bin/env python3
"""What a run costs before it steps, against a peer's budget (issue 37; docs/performance.md,
"What ≥ 100× would take").

    python3 benches/floor.py SCENE:RUNG [...] [--runs out/pc6/runs.jsonl] [--lead 100] [--rounds 21]

For each configuration of the peer bench's mecano-rs ladder (benches/peers/scenes.py,
SCENE:RUNG counted from 0, the deck made as bench.py makes it) it runs
target/release/mecano-rs on the deck as it is and on the same deck ended after its first
step (`END` set to its `STEP`: reading the deck, building the model and the system, the
summary's modes, the initial accelerations, one step, the output files), interleaved,
`--rounds` times each, and keeps the least user + system CPU of each. The difference is
what the steps after the first cost; divided by the steps (summary.json) it is the cost of
a step. With `--runs` (a bench's runs.jsonl) it also prints the peer's cheapest run that
meets the scene's target there, and the budget a lead of `--lead` leaves mecano-rs: a
one-step run above it means no faster stepping can reach that lead.

Not part of CI.
"""
import argparse
import json
import os
import re
import resource
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
BIN = os.path.join(ROOT, "target", "release", "mecano-rs")
sys.path.insert(0, os.path.join(ROOT, "benches", "peers"))
from scenes import SCENES, deck_text  # noqa: E402


def one_step(text):
    """The deck ended after its first step: the ANALYSIS line's END set to its STEP."""
    out = []
    for line in text.splitlines():
        if line.startswith("ANALYSIS DYNAMIC"):
            step = re.search(r"\bSTEP\s+(\S+)", line)
            if not step or not re.search(r"\bEND\s+\S+", line):
                raise ValueError(f"no STEP and END on the ANALYSIS line: {line}")
            line = re.sub(r"\bEND\s+\S+", f"END {step.group(1)}", line)
        out.append(line)
    return "\n".join(out) + "\n"


def cpu_of(deck, outdir):
    """User + system CPU seconds of one run, and its summary."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([BIN, deck, "-o", outdir, "--quiet", "--checkpoint", "0", "--force"],
                       capture_output=True, text=True)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise RuntimeError(f"mecano-rs failed on {deck}: {p.stderr.strip()[-300:]}")
    s = json.load(open(os.path.join(outdir, "summary.json")))
    return (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime), s["stats"]


def peer_at_target(runs, scene, code):
    """The peer's cheapest run at the scene's target in a bench's runs.jsonl, or None."""
    target, best = None, None
    for r in runs:
        if r.get("scene") == scene and r.get("code") == "reference":
            target = r["target"]
    for r in runs:
        if (r.get("scene") == scene and r.get("code") == code and r.get("ok") and target
                and r.get("error") is not None and r["error"] <= target
                and (best is None or r["cpu"] < best["cpu"])):
            best = r
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("rungs", nargs="+", help="SCENE:RUNG of the peer bench's mecano-rs ladder")
    ap.add_argument("--runs", help="a bench's runs.jsonl: the peer's cheapest run at the target")
    ap.add_argument("--peer", default="exudyn")
    ap.add_argument("--lead", type=float, default=100.0)
    ap.add_argument("--rounds", type=int, default=21)
    a = ap.parse_args()
    if not os.access(BIN, os.X_OK):
        sys.exit(f"{BIN} missing: cargo build --release")
    if a.rounds < 1 or not a.lead > 0:
        sys.exit("--rounds must be at least 1 and --lead above 0")
    try:
        runs = [json.loads(line) for line in open(a.runs) if line.strip()] if a.runs else []
    except (OSError, ValueError) as e:
        sys.exit(f"--runs {a.runs}: {e}")
    rows = []
    with tempfile.TemporaryDirectory() as td:
        for arg in a.rungs:
            m = re.match(r"^(\w+):(\d+)$", arg)
            if not m or m.group(1) not in SCENES or int(m.group(2)) >= len(SCENES[m.group(1)]["mecano"]):
                sys.exit(f"{arg}: not SCENE:RUNG of benches/peers/scenes.py")
            scene, cfg = m.group(1), SCENES[m.group(1)]["mecano"][int(m.group(2))]
            whole, first = os.path.join(td, "whole.dat"), os.path.join(td, "first.dat")
            text = deck_text(scene, cfg)
            open(whole, "w").write(text)
            open(first, "w").write(one_step(text))
            cw, c1 = [], []
            for _ in range(a.rounds):
                t, stats = cpu_of(whole, os.path.join(td, "w"))
                cw.append(t)
                c1.append(cpu_of(first, os.path.join(td, "f"))[0])
            rows.append(dict(scene=scene, label=cfg["label"], whole=min(cw), first=min(c1),
                             steps=stats["steps"], peer=peer_at_target(runs, scene, a.peer)))
            print(f"{arg}: whole {min(cw):.4f} s, one step {min(c1):.4f} s", flush=True)
    print()
    print(f"| scene, rung | whole run (s) | one-step run (s) | the other steps (s) | steps | per step (µs) "
          f"| {a.peer} at the target (s, steps, per step) | {a.lead:g}× budget (s) | one-step run / budget |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        rest = r["whole"] - r["first"]
        per = 1e6 * rest / max(r["steps"] - 1, 1)
        p = r["peer"]
        if p:
            budget = p["cpu"] / a.lead
            peer = f"{p['cpu']:.3f}, {p['steps']:,}, {1e6 * p['cpu'] / p['steps']:.0f} µs ({p['label']})"
            b, ratio = f"{budget:.4f}", f"{r['first'] / budget:.2f}"
        else:
            peer, b, ratio = "–", "–", "–"
        print(f"| {r['scene']}: {r['label']} | {r['whole']:.4f} | {r['first']:.4f} | {rest:.4f} | "
              f"{r['steps']:,} | {per:.1f} | {peer} | {b} | {ratio} |")


if __name__ == "__main__":
    main()
