#!/usr/bin/env python3
"""What the Newton tolerance is worth at the target: a scene's rungs run interleaved, best of R.

    python3 benches/peers/newton_tol.py SCENE [--out out/h12] [--rounds 3] [--tols 1e-8,1e-6,1e-5,1e-4]
                                        [--newton default,FULL] [--rung "h,d,p,SCHEME"]...

Each rung (a mecano-rs configuration of the peer bench: step h, d divisions of order p, the
ANALYSIS scheme) is run at each Newton tolerance TOL t TOLINC t/100 (the defaults' ratio,
1e-8 / 1e-10; t = 1e-8 writes no TOL, the deck's default), and with each NEWTON choice; all
runs of a round one after the other, R rounds, so that a load on the shared machine falls on
all alike. Per run: steps, Newton iterations, factorisations (deterministic), user CPU of
the child (getrusage, best of R; also user + system), the error against the scene's reference
(bench.py's; computed there on first use), error / target, and the largest distance of its
compared quantities from the same rung at the default tolerance and NEWTON: the Newton
error the looser tolerance adds. Records go to OUT/<scene>/newton_tol.jsonl; prints a table.
"""
import argparse
import json
import os
import resource
import sys

PEERS = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, PEERS)
from bench import Reference, dist, mecano_channels, run_mecano  # noqa: E402
from scenes import SCENES, deck_text, mk  # noqa: E402


def scheme_with(scheme, tol, newton):
    s = scheme
    if tol != 1e-8:
        s += f" TOL {tol:g} TOLINC {tol / 100:g}"
    if newton != "default":
        s += f" NEWTON {newton}"
    return s


def run(scene, cfg, d):
    """bench.py's run of a configuration, with the child's user CPU besides its user + system
    (run this script under `nice` on a shared machine)."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    rec = run_mecano(scene, cfg, d)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    rec["user"] = r1.ru_utime - r0.ru_utime
    return rec


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--out", default="out/h12")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--tols", default="1e-8,1e-6,1e-5,1e-4")
    ap.add_argument("--newton", default="default", help="comma list of default, FULL, MODIFIED")
    ap.add_argument("--rung", action="append", default=[], metavar="h,d,p,SCHEME")
    ap.add_argument("--also", default=None, metavar="SCENE",
                    help="also the error against this scene's reference (same deck: pendulum and pendulum_time)")
    a = ap.parse_args()
    sc = SCENES[a.scene]
    refd = os.path.join(a.out, a.scene, "ref")
    if not os.path.exists(os.path.join(refd, "summary.json")):
        sys.exit(f"no reference in {refd}: run bench.py --out {a.out} --scenes {a.scene} --codes none first")
    ref = Reference(a.scene, refd)
    also = Reference(a.also, os.path.join(a.out, a.also, "ref")) if a.also else None
    target = sc.get("target") or 1e-3 * ref.amplitude()
    tols = [float(t) for t in a.tols.split(",")]
    newtons = a.newton.split(",")
    rungs = []
    for spec in a.rung:
        h, d, p, scheme = spec.split(",", 3)
        rungs.append((float(h), int(d), int(p), scheme.strip()))
    per = {"leg": " per leg", "bar": " per bar", "rod": " in the rod"}.get(sc.get("per"), "")
    beams = 4 if a.scene == "slider_crank" else 1
    cfgs = []
    for (h, d, p, scheme) in rungs:
        for nw in newtons:
            for t in tols:
                c = mk(None, h, d, p, scheme_with(scheme, t, nw), beams, per)
                c.update(base=(h, d, p, scheme), tol=t, nw=nw)
                cfgs.append(c)
    best = {}
    for rnd in range(a.rounds):
        for i, c in enumerate(cfgs):
            d = os.path.join(a.out, a.scene, f"nt_{i}")
            r = run(a.scene, c, d)
            b = best.get(i)
            if b is None:
                best[i] = r
            elif b["ok"] and r["ok"]:
                b["user"] = min(b["user"], r["user"])
                b["cpu"] = min(b["cpu"], r["cpu"])
            print(f"round {rnd} {c['label']}: user {r['user']:.3f} s", file=sys.stderr, flush=True)
    chans = {}
    for i, c in enumerate(cfgs):
        r = best[i]
        if r["ok"]:
            chans[i] = mecano_channels(a.scene, os.path.join(a.out, a.scene, f"nt_{i}"))
            r["error"], _ = ref.error(chans[i])
            if also:
                r["error_" + a.also], _ = also.error(chans[i])
    # the Newton error: distance from the same rung at the default tolerance and NEWTON
    for i, c in enumerate(cfgs):
        j = next(k for k, o in enumerate(cfgs) if o["base"] == c["base"] and o["tol"] == 1e-8 and o["nw"] == "default") \
            if any(o["base"] == c["base"] and o["tol"] == 1e-8 and o["nw"] == "default" for o in cfgs) else None
        if j is not None and i in chans and j in chans and len(chans[i]) == len(chans[j]):
            best[i]["newton_err"] = max(max(dist(x, y) for x, y in zip(ci, cj))
                                        for (_, ci), (_, cj) in zip(chans[i], chans[j]))
    print(f"\n{a.scene}: target {target:.3g}; best of {a.rounds} interleaved rounds; load {open('/proc/loadavg').read().split()[:3]}")
    print("| configuration | steps | Newton | factorisations | user CPU s | user+sys s | error | error / target | vs default tol |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    with open(os.path.join(a.out, a.scene, "newton_tol.jsonl"), "a") as f:
        for i, c in enumerate(cfgs):
            r = best[i]
            f.write(json.dumps(dict(r, scene=a.scene, label=c["label"], h=c["h"], d=c["d"], p=c["p"],
                                    scheme=c["scheme"], target=target, rounds=a.rounds)) + "\n")
            if not r["ok"]:
                print(f"| {c['label']} | {r['steps']} | | | | | FAILED: {r['why']} | | |")
                continue
            ne = r.get("newton_err")
            print(f"| {c['label']} | {r['steps']:,} | {r['newton']:,} | {r['factorisations']:,} | {r['user']:.3f} "
                  f"| {r['cpu']:.3f} | {r['error']:.3e} | {r['error'] / target:.3f} | {'–' if ne is None else f'{ne:.1e}'} |"
                  + (f" {a.also}: {r['error_' + a.also]:.3e} |" if also else ""))


if __name__ == "__main__":
    main()
