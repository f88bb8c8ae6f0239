#!/usr/bin/env python3
"""Where a run's CPU goes, by phase (issue 37 item 4; docs/performance.md, "Where the CPU goes").

    python3 benches/profile.py DECK|SCENE:RUNG [...] [--samples 3000] [--set name=value] [--out DIR]

SCENE:RUNG names a configuration of the peer bench's mecano-rs ladder (benches/peers/scenes.py,
counted from 0; e.g. cantilever:13, the cheapest at the target in docs/performance.md), the
deck made as bench.py makes it.

Runs target/release/mecano-rs on each deck once plainly (to time it), then under Linux
`perf record` at the frequency that gives about --samples samples (500 to 20,000 Hz; call
stacks unwound with DWARF: the release profile keeps its debug info), then gives each
sample to the phase of the innermost function on its stack that names one (the table
PHASES below, first match from the leaf up): residual (the elements' and the loads' forces,
the assembly of the right-hand side), tangent (the elements' tangent matrices and their
assembly into the iteration matrix), factorisation (the sparse LU's numeric factorisation,
pivot search included), solves (forward and back substitution), Newton's own vector work
(predictors, updates, norms, stage and trial states: the integrator's code outside the
four), event control (step acceptance, error estimate, the energy guard, events and
restarts), output (histories, summary, checkpoints), start (reading the deck, building the
model and the system, the initial accelerations) and other. No instrumentation: the binary
measured is the release build as shipped, its hot loop unchanged. A sample whose stack
DWARF unwinding cut short before any phase's function is counted as "unattributed" (the
table gives its share: the phases' shares are of the attributed samples). Elements that
compute their forces and their tangent in one function (joints, rigid bodies, contacts) count
whole as residual; the beams' tangents (internal_tangent) and the assembly of the rotation
tangent maps count as tangent.

Needs `perf` (Debian: linux-perf) and the right to sample one's own processes
(/proc/sys/kernel/perf_event_paranoid <= 2). Not part of CI.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
BIN = os.path.join(ROOT, "target", "release", "mecano-rs")

# (phase, regular expression on a frame's symbol), tried on each frame from the leaf up;
# within a frame the first phase that matches wins.
PHASES = [
    ("output", r"mecano::output::|mecano::checkpoint::|solver::observe|Observer|safe_file"),
    ("factorisation", r"Factors::refactor|Factors::factor|SparseSystem::factor|pivoting::|faer::.*lu|faer::.*factor"),
    ("solves", r"Factors::solve|SparseSystem::solve|faer::.*solve"),
    ("tangent", r"tangent|apply_rotation_tangent|matrix\.clear|SparseMatrix::clear"),
    ("residual", r"internal_forces|residual|Element>::evaluate|::evaluate\b|System::assemble|force_scale|LoadTable"),
    ("event control", r"event_control|energy_guard|finish_step|error_estimate|Stepper::accept|restart|clip_step|events?::"),
    ("start", r"solver::prepare|System::new|mecano::deck::|model::.*build|start::|initial_acceleration|app::start_session"),
    ("Newton (vectors)", r"newton_solve|try_step|try_esdirk_step|stage_from_u|trial_from_u|multipliers::|Integrator"),
]
COMPILED = [(p, re.compile(r)) for p, r in PHASES]
ORDER = [p for p, _ in PHASES] + ["other", "unattributed"]


def classify(frames):
    """The phase of one sample: its frames, leaf first."""
    for sym in frames:
        for phase, rx in COMPILED:
            if rx.search(sym):
                return phase
    # a complete stack reaches main or the thread's start: the code outside every phase
    if any(s.endswith(" main") or s == "main" or "_start" in s or "lang_start" in s for s in frames):
        return "other"
    return "unattributed"


def samples(script_text):
    """Phases of the samples of `perf script -F comm,ip,sym` output."""
    out, frames = [], []
    for line in script_text.splitlines():
        if not line.strip():
            if frames:
                out.append(classify(frames))
            frames = []
            continue
        if line[0] in " \t":
            parts = line.strip().split(None, 1)
            if len(parts) == 2:
                frames.append(parts[1])
    if frames:
        out.append(classify(frames))
    return out


def resolve(arg, workdir):
    """A deck's path: the file, or the peer bench's configuration SCENE:RUNG written to workdir."""
    m = re.match(r"^(\w+):(\d+)$", arg)
    if not m or os.path.exists(arg):
        return os.path.abspath(arg), os.path.relpath(os.path.abspath(arg), ROOT)
    sys.path.insert(0, os.path.join(ROOT, "benches", "peers"))
    from scenes import SCENES, deck_text
    scene, rung = m.group(1), int(m.group(2))
    cfg = SCENES[scene]["mecano"][rung]
    path = os.path.join(workdir, "deck.dat")
    with open(path, "w") as f:
        f.write(deck_text(scene, cfg))
    return path, f"{scene}: {cfg['label']}"


def profile(arg, target, workdir, extra):
    deck, name = resolve(arg, workdir)
    data = os.path.join(workdir, "perf.data")
    outdir = os.path.join(workdir, "run")
    t0 = os.times()
    subprocess.run([BIN, deck, "-o", outdir, "--quiet", "--checkpoint", "0", "--force", *extra], capture_output=True)
    t1 = os.times()
    cpu = (t1.children_user - t0.children_user) + (t1.children_system - t0.children_system)
    freq = int(min(20000, max(500, target / max(cpu, 1e-3))))
    p = subprocess.run(["perf", "record", "-q", "-F", str(freq), "--call-graph", "dwarf,16384", "-o", data, BIN,
                        deck, "-o", outdir, "--quiet", "--checkpoint", "0", "--force", *extra],
                       capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"perf record / mecano-rs failed on {deck}: {(p.stderr or p.stdout).strip()[-300:]}")
    s = json.load(open(os.path.join(outdir, "summary.json")))
    text = subprocess.run(["perf", "script", "-i", data, "-F", "comm,ip,sym"], capture_output=True,
                          text=True).stdout
    phases = samples(text)
    n = len(phases)
    counts = {p: phases.count(p) for p in ORDER}
    attributed = n - counts["unattributed"]
    st = s["stats"]
    return dict(deck=name, samples=n, freq=freq, process_cpu=cpu, attributed=attributed, counts=counts,
                integration_seconds=st["cpu_seconds"], steps=st["steps"], newton=st["newton_iterations"],
                factorisations=st["factorizations"])


def markdown(results):
    head = "| phase | " + " | ".join(r["deck"] for r in results) + " |"
    lines = [head, "| --- |" + " --- |" * len(results)]
    for p in ORDER[:-1]:
        lines.append(f"| {p} | " + " | ".join(
            f"{100 * r['counts'][p] / max(r['attributed'], 1):.1f} %" for r in results) + " |")
    lines.append("| (unattributed samples, of all) | " + " | ".join(
        f"{100 * r['counts']['unattributed'] / max(r['samples'], 1):.1f} %" for r in results) + " |")
    lines.append("| samples | " + " | ".join(f"{r['samples']:,}" for r in results) + " |")
    lines.append("| steps / Newton / factorisations | " + " | ".join(
        f"{r['steps']:,} / {r['newton']:,} / {r['factorisations']:,}" for r in results) + " |")
    lines.append("| CPU s of the process, unprofiled | " + " | ".join(
        f"{r['process_cpu']:.3f}" for r in results) + " |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("decks", nargs="+")
    ap.add_argument("--samples", type=int, default=3000, help="about this many samples per deck")
    ap.add_argument("--set", action="append", default=[], help="passed to mecano-rs (--set name=value)")
    ap.add_argument("--out", help="keep the perf data and runs here (default: a temporary folder)")
    a = ap.parse_args()
    if not shutil.which("perf"):
        sys.exit("perf is not installed (Debian: apt-get install linux-perf)")
    if not os.access(BIN, os.X_OK):
        sys.exit(f"{BIN} missing: cargo build --release")
    extra = [x for s in a.set for x in ("--set", s)]
    results = []
    for deck in a.decks:
        wd = a.out and os.path.join(a.out, re.sub(r"[^\w.-]", "_", os.path.splitext(os.path.basename(deck))[0]))
        if wd:
            os.makedirs(wd, exist_ok=True)
            results.append(profile(deck, a.samples, wd, extra))
        else:
            with tempfile.TemporaryDirectory() as td:
                results.append(profile(deck, a.samples, td, extra))
        r = results[-1]
        print(f"{r['deck']}: " + ", ".join(f"{p} {100 * r['counts'][p] / max(r['attributed'], 1):.1f} %"
                                          for p in ORDER[:-1] if r["counts"][p])
              + f" (of {r['attributed']} attributed samples; {r['counts']['unattributed']} unattributed)",
              flush=True)
    print()
    print(markdown(results))


if __name__ == "__main__":
    main()
