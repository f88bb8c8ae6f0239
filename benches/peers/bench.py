#!/usr/bin/env python3
"""Work-precision of mecano-rs and its peers on the same scenes (benches/peers/README.md).

    python3 benches/peers/bench.py [--out out/peers] [--scenes a,b] [--codes mecano-rs,exudyn,mbdyn]
                                   [--rounds R] [--quick] [--ladder PEER=N:H[:RTOL],...] [--append]

For each scene: a converged reference (mecano-rs on a mesh and step finer than any run, with
a second, coarser run that bounds its own error), then each code's ladder of meshes and
steps, run one after the other on this machine; every run's error is the largest distance of
the scene's compared quantities from the reference (interpolated at the run's output instants
by cubic Hermite on positions and velocities), its CPU: for mecano-rs and MBDyn the user +
system seconds of the whole process (parsing, the start and the output included: getrusage
of the child), for Exudyn the process seconds of its solve alone (time.process_time around
SolveSteps: Python's start, the imports and the model's building excluded), so that a ratio
of mecano-rs to Exudyn understates mecano-rs's lead; best of --rounds. Writes OUT/runs.jsonl
(one line per run, the machine's first), OUT/tables.md (the tables of docs/performance.md),
OUT/<scene>.png/.svg (error against CPU, log-log) and prints the tables. A code that is not
installed (OUT/status/<code>.fail, written by install.sh) or whose run fails is reported in
the table and the bench goes on. Standard library for the runs and tables; matplotlib for the
figures, if importable.
"""
import argparse
import bisect
import csv
import json
import math
import os
import resource
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
PEERS = os.path.join(ROOT, "benches", "peers")
BIN = os.path.join(ROOT, "target", "release", "mecano-rs")
VENV_PY = os.path.join(PEERS, ".venv", "bin", "python")
sys.path.insert(0, PEERS)
from scenes import PEER_SCENES, SCENES, deck_text  # noqa: E402


# ------------------------------------------------------------------------- reading runs
def load_nodes(d, nodes, acceleration=False):
    """{node: (t, x, v)} from a mecano-rs output directory (with acceleration: (t, a, None))."""
    out = {}
    for n in nodes:
        t, x, v = [], [], []
        with open(os.path.join(d, f"node_{n}.csv")) as f:
            for row in csv.DictReader(f):
                t.append(float(row["t"]))
                if acceleration:
                    x.append([float(row[k]) for k in ("ax", "ay", "az")])
                else:
                    x.append([float(row[k]) for k in ("x", "y", "z")])
                    v.append([float(row[k]) for k in ("vx", "vy", "vz")])
        out[n] = (t, x, v or None)
    return out


def hermite(ref, t):
    """Cubic Hermite interpolation of a node's positions (t, x, v) at time t."""
    ts, xs, vs = ref
    i = bisect.bisect_left(ts, t - 1e-12)
    if i < len(ts) and abs(ts[i] - t) <= 1e-12 * max(1.0, abs(t)):
        return xs[i]
    if i == 0 or i >= len(ts):
        return None
    t0, t1 = ts[i - 1], ts[i]
    h = t1 - t0
    s = (t - t0) / h
    h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
    h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
    return [h00 * a + h10 * h * va + h01 * b + h11 * h * vb
            for a, va, b, vb in zip(xs[i - 1], vs[i - 1], xs[i], vs[i])]


def mecano_channels(scene, d):
    """[(t, [channel vectors])] of a mecano-rs run."""
    sc = SCENES[scene]
    nodes = load_nodes(d, sc["nodes"], sc.get("acceleration", False))
    ts = nodes[sc["nodes"][0]][0]
    rows = []
    for i, t in enumerate(ts):
        if t > sc["tend"] + 1e-9:
            break
        pos = {n: nodes[n][1][i] for n in sc["nodes"]}
        rows.append((t, sc["channels"](t, pos)))
    return rows


def csv_channels(scene, path):
    """[(t, [channel vectors])] of a peer's CSV (t, then the scene's columns)."""
    sc = SCENES[scene]
    rows = []
    with open(path) as f:
        r = csv.reader(f)
        next(r)
        for row in r:
            v = [float(x) for x in row]
            t, vals, k, ch = v[0], v[1:], 0, []
            for w in sc["widths"]:
                ch.append(vals[k:k + w])
                k += w
            if t <= sc["tend"] + 1e-9:
                rows.append((t, ch))
    return rows


class Exact:
    """A closed-form reference: the scene's exact(t) gives its channels."""

    def __init__(self, scene):
        self.scene = scene

    def at(self, t):
        return SCENES[self.scene]["exact"](t)

    def amplitude(self):
        sc = SCENES[self.scene]
        n = int(round(sc["tend"] / sc["period"]))
        c0 = self.at(0.0)
        return max(dist(c, a) for k in range(n + 1) for c, a in zip(self.at(k * sc["period"]), c0))

    error = None


class Reference:
    def __init__(self, scene, d):
        self.scene = scene
        self.nodes = load_nodes(d, SCENES[scene]["nodes"])

    def at(self, t):
        pos = {}
        for n, ref in self.nodes.items():
            p = hermite(ref, t)
            if p is None:
                return None
            pos[n] = p
        return SCENES[self.scene]["channels"](t, pos)

    def amplitude(self):
        rows = [(t, self.at(t)) for t in self.nodes[next(iter(self.nodes))][0]
                if t <= SCENES[self.scene]["tend"] + 1e-9]
        c0 = rows[0][1]
        return max(dist(c, a) for _, ch in rows for c, a in zip(ch, c0))

    def error(self, rows):
        e, m = 0.0, 0
        for t, ch in rows:
            r = self.at(t)
            if r is None:
                continue
            m += 1
            e = max(e, max(dist(a, b) for a, b in zip(ch, r)))
        return e, m


def dist(a, b):
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)))


# --------------------------------------------------------------------------- the runs
def run_mecano(scene, cfg, out, dense=False):
    """Runs a mecano-rs configuration; returns its record (no error yet)."""
    os.makedirs(out, exist_ok=True)
    deck = os.path.join(out, "deck.dat")
    with open(deck, "w") as f:
        f.write(deck_text(scene, cfg, dense))
    cpu0 = children_cpu()
    p = subprocess.run([BIN, deck, "-o", out, "--quiet", "--checkpoint", "0", "--force"],
                       capture_output=True, text=True)
    cpu = children_cpu() - cpu0
    rec = dict(code="mecano-rs", scene=scene, label=cfg["label"], h=cfg["h"], mesh=cfg["mesh"], scheme=cfg["scheme"])
    try:
        s = json.load(open(os.path.join(out, "summary.json")))
        st = s["stats"]
        rec.update(ok=bool(s["complete"]) and p.returncode == 0, cpu=cpu, wall=st["cpu_seconds"], steps=st["steps"],
                   newton=st["newton_iterations"], factorisations=st["factorizations"])
    except (OSError, KeyError, ValueError):
        rec.update(ok=False, cpu=None, steps=None, newton=None)
    if not rec["ok"]:
        rec["why"] = (p.stderr.strip().splitlines() or ["no summary"])[-1][:200]
    return rec


def children_cpu():
    """User + system CPU seconds of this process's finished children."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


PEERS_RUN = {
    # code: (the Python that runs its script, the script, the mesh's words, the scheme)
    "exudyn": (VENV_PY, "exudyn_scenes.py", "two-node", lambda scene: "HHT -0.1" if scene == "pendulum"
               else "generalized-alpha"),
    "mbdyn": (sys.executable, "mbdyn_scenes.py", "beam3", lambda scene: "ms 0.9"),
}


def run_peer(code, scene, n, h, out, reltol=None):
    """Runs a peer's configuration (n elements per bar/leg/beam/rod, step h, and for Exudyn
    optionally Newton's relative tolerance instead of the bench's 1e-8) through its script;
    returns its record (no error yet)."""
    py, script, words, scheme = PEERS_RUN[code]
    os.makedirs(out, exist_ok=True)
    csvp = os.path.join(out, "run.csv")
    if os.path.exists(csvp):
        os.remove(csvp)
    extra = ["--reltol", repr(reltol)] if reltol is not None else []
    p = subprocess.run([py, os.path.join(PEERS, script), scene, "--h", repr(h), "--n", str(n), "--out", csvp]
                       + extra, capture_output=True, text=True)
    tol = f", Newton rel. tol. {reltol:g}" if reltol is not None else ""
    rec = dict(code=code, scene=scene,
               label=f"{n} {words} per {SCENES[scene]['per']}, {scheme(scene)}, h = {h:g}{tol}",
               h=h, mesh=f"{n} {words}", scheme=scheme(scene))
    j = {}
    try:
        j = json.loads(p.stdout.strip().splitlines()[-1])
        rec.update(ok=j["ok"], cpu=j["cpu"], steps=j["steps"], newton=j["newton"],
                   factorisations=j.get("jacobians"), version=j.get("version"))
    except (IndexError, ValueError, KeyError):
        rec.update(ok=False, cpu=None, steps=None, newton=None)
    if not rec["ok"]:
        if j.get("why"):
            rec["why"] = j["why"]
        elif rec.get("steps") is not None and j.get("t_reached") is not None:
            rec["why"] = f"stopped at t = {j['t_reached']:.4g} s (Newton did not converge; fixed step)"
        else:
            rec["why"] = ((p.stderr or p.stdout).strip().splitlines() or ["failed"])[-1][:200]
    rec["csv"] = csvp
    return rec


def machine():
    """The machine and the codes' versions, for the tables' header."""
    def sh(*cmd):
        try:
            return subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT).stdout
        except OSError:
            return ""
    cpu = {}
    for line in sh("lscpu").splitlines():
        k, _, v = line.partition(":")
        cpu[k.strip()] = v.strip()
    mem = next((line.split()[1] for line in open("/proc/meminfo") if line.startswith("MemTotal")), "?") \
        if os.path.exists("/proc/meminfo") else "?"
    return dict(code="machine", scene="*",
                cpu=f"{cpu.get('Model name', '?')}, {cpu.get('CPU(s)', '?')} CPUs "
                    f"({cpu.get('Thread(s) per core', '?')} thread per core), L2 {cpu.get('L2 cache', '?')}, "
                    f"L3 {cpu.get('L3 cache', '?')}, {cpu.get('Hypervisor vendor', 'no')} hypervisor",
                memory_gib=round(int(mem) / 2**20, 1) if mem != "?" else None,
                mecano_commit=sh("git", "rev-parse", "--short", "HEAD").strip(),
                python=sys.version.split()[0],
                load=open("/proc/loadavg").read().split()[:3] if os.path.exists("/proc/loadavg") else None)


def peer_status(out):
    """{code: None if usable, else why not} from the install step's status files."""
    st = {"mecano-rs": None if os.access(BIN, os.X_OK) else "target/release/mecano-rs missing (cargo build --release)"}
    for code in ("exudyn", "mbdyn"):
        f = os.path.join(out, "status", code)
        if os.path.exists(f + ".ok"):
            st[code] = None
        elif os.path.exists(f + ".fail"):
            st[code] = open(f + ".fail").read().strip() or "install failed"
        else:
            st[code] = "not installed (run benches/peers/install.sh)"
    return st


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "peers"))
    ap.add_argument("--scenes", default=",".join(PEER_SCENES),
                    help=f"default: the scenes the peers model; also: {', '.join(s for s in SCENES if s not in PEER_SCENES)}")
    ap.add_argument("--codes", default="mecano-rs,exudyn,mbdyn")
    ap.add_argument("--rounds", type=int, default=1, help="timed runs per configuration (best of)")
    ap.add_argument("--quick", action="store_true", help="only each code's cheapest two configurations")
    ap.add_argument("--ladder", action="append", default=[], metavar="PEER=N:H[:RTOL],...",
                    help="a peer's rungs instead of the scene's ladder (e.g. exudyn=80:2.5e-5,160:1e-5; for Exudyn "
                         "a third field sets Newton's relative tolerance, e.g. exudyn=40:0.025:1e-4), run in "
                         "OUT/<scene>/<peer>_n<N>_h<H>[_rtol<RTOL>]")
    ap.add_argument("--append", action="store_true",
                    help="add this sitting's records to OUT/runs.jsonl (a scene's reference once) instead of replacing it")
    a = ap.parse_args()
    ladders = {}
    for spec in a.ladder:
        code, _, rungs = spec.partition("=")
        if code not in PEERS_RUN:
            sys.exit(f"--ladder {spec}: {code!r} is not a peer ({', '.join(PEERS_RUN)})")
        try:
            ladders[code] = [tuple(int(v) if i == 0 else float(v) for i, v in enumerate(r.split(":")))
                             for r in rungs.split(",")]
            if any(len(c) not in (2, 3) or (len(c) == 3 and code != "exudyn") for c in ladders[code]):
                raise ValueError
        except ValueError:
            sys.exit(f"--ladder {spec}: expected PEER=N:H,N:H (elements per bar, step in s; Exudyn: N:H:RTOL too)")
    os.makedirs(a.out, exist_ok=True)
    status = peer_status(a.out)
    codes = a.codes.split(",")
    records = [machine()]
    for scene in a.scenes.split(","):
        sc = SCENES[scene]
        sd = os.path.join(a.out, scene)
        # the reference and its check, dense output, computed once (delete OUT/<scene>/ref* to redo)
        refs = {}
        for key in ([] if "exact" in sc else ["ref", "check"]):
            d = os.path.join(sd, key)
            if not os.path.exists(os.path.join(d, "summary.json")):
                print(f"[{scene}] {key}: {sc[key]['label']} ...", flush=True)
                r = run_mecano(scene, sc[key], d, dense=True)
                if not r["ok"]:
                    sys.exit(f"[{scene}] the {key} run failed: {r.get('why')}")
            refs[key] = d
        if "exact" in sc:
            ref, check_err = Exact(scene), 0.0
            Exact.error = Reference.error
        else:
            ref = Reference(scene, refs["ref"])
            check_err, _ = ref.error(mecano_channels(scene, refs["check"]))
        amp = ref.amplitude()
        target = sc.get("target") or 1e-3 * amp
        records.append(dict(code="reference", scene=scene, label=sc["ref"]["label"] if "ref" in sc else "closed form",
                            check=sc["check"]["label"] if "check" in sc else "(exact)",
                            check_error=check_err, amplitude=amp, target=target))
        print(f"[{scene}] amplitude {amp:.4g}, target {target:.3g}; reference vs check {check_err:.2e}", flush=True)
        for code in codes:
            if code not in status:
                continue
            if status[code] is not None:
                records.append(dict(code=code, scene=scene, ok=False, why=status[code], label="-"))
                print(f"[{scene}] {code}: {status[code]}", flush=True)
                continue
            ladder = ladders.get(code) or sc.get(code.replace("-rs", ""), [])
            if not ladder and code != "mecano-rs":
                records.append(dict(code=code, scene=scene, ok=False, label="-", why="scene not modelled for this code"))
                continue
            if a.quick:
                ladder = ladder[:2]
            for i, cfg in enumerate(ladder):
                d = os.path.join(sd, f"{code}_n{cfg[0]}_h{cfg[1]:g}" + "".join(f"_rtol{t:g}" for t in cfg[2:])
                                 if code in ladders else f"{code}_{i}")
                best = None
                for _ in range(a.rounds):
                    if code == "mecano-rs":
                        r = run_mecano(scene, cfg, d)
                    else:
                        r = run_peer(code, scene, cfg[0], cfg[1], d, *cfg[2:])
                    if best is None or (r["ok"] and best["ok"] and r["cpu"] < best["cpu"]):
                        best = r if best is None or r["ok"] else best
                    if not r["ok"]:
                        break
                r = best
                if r["ok"]:
                    rows = mecano_channels(scene, d) if code == "mecano-rs" else csv_channels(scene, r["csv"])
                    r["error"], r["samples"] = ref.error(rows)
                r.pop("csv", None)
                records.append(r)
                msg = (f"error {r['error']:.2e}, cpu {r['cpu']:.3f} s, {r['steps']} steps, {r['newton']} Newton"
                       if r["ok"] else f"FAILED: {r.get('why')}")
                print(f"[{scene}] {code} {r['label']}: {msg}", flush=True)
    runs = os.path.join(a.out, "runs.jsonl")
    if a.append and os.path.exists(runs):
        old = [json.loads(line) for line in open(runs)]
        have = {json.dumps(r, sort_keys=True) for r in old if r["code"] == "reference"}
        records = old + [r for r in records if json.dumps(r, sort_keys=True) not in have]
    tmp = os.path.join(a.out, f"runs.jsonl.tmp{os.getpid()}")
    with open(tmp, "w") as f:
        for r in records:
            f.write(json.dumps(r) + "\n")
    os.replace(tmp, runs)   # nothing half-written
    import tables
    tables.report(records, a.out)


if __name__ == "__main__":
    main()
