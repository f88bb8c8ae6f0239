"""Tables and figures of the peer bench from its records (bench.py; benches/peers/README.md).

    python3 benches/peers/tables.py [OUT]      # redraws OUT/tables.md and the figures from OUT/runs.jsonl
"""
import json
import os
import sys

from scenes import SCENES


def fmt(x, spec):
    return "–" if x is None else format(x, spec)


def cheapest(runs, bound):
    ok = [r for r in runs if r.get("ok") and r.get("error") is not None and r["error"] <= bound]
    return min(ok, key=lambda r: r["cpu"]) if ok else None


def scene_report(scene, recs):
    ref = next(r for r in recs if r["code"] == "reference")
    target = ref["target"]
    out = [f"### {scene}: {SCENES[scene]['title']}", "",
           f"Reference: {ref['label']}; {ref['check']} differs from it by {ref['check_error']:.2e} "
           f"(a bound of the reference's own error). Amplitude of the compared motion {ref['amplitude']:.4g}; "
           f"target 1e-3 of the motion: **{target:.2e}**.", "",
           "| code | configuration | steps | Newton | factorisations | CPU s | error | error / target |",
           "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in recs:
        if r["code"] == "reference":
            continue
        if not r.get("ok"):
            out.append(f"| {r['code']} | {r.get('label', '-')} | | | | | failed or missing: {r.get('why', '?')} | |")
            continue
        fac = r.get("factorisations")
        out.append(f"| {r['code']} | {r['label']} | {r['steps']:,} | {r['newton']:,} | {'–' if fac is None else f'{fac:,}'} "
                   f"| {r['cpu']:.3f} | {r['error']:.2e} | {r['error'] / target:.2f} |")
    out.append("")
    mec = [r for r in recs if r["code"] == "mecano-rs"]
    m = cheapest(mec, target)
    lines = []
    for code in sorted({r["code"] for r in recs} - {"reference", "mecano-rs"}):
        peer = [r for r in recs if r["code"] == code]
        usable = [r for r in peer if r.get("ok") and r.get("error") is not None]
        if not usable:
            why = next((r.get("why") for r in peer if r.get("why")), "no run")
            lines.append(f"- {code}: no result ({why}).")
            continue
        p = cheapest(usable, target)
        if p and m:
            lines.append(f"- {code} at the target: {p['label']}, {p['cpu']:.3f} s (error {p['error']:.2e}); mecano-rs: "
                         f"{m['label']}, {m['cpu']:.3f} s (error {m['error']:.2e}): **{p['cpu'] / m['cpu']:.0f}×**.")
            continue
        best = min(usable, key=lambda r: r["error"])
        mm = cheapest(mec, best["error"])
        tail = (f"; at that error mecano-rs needs {mm['cpu']:.3f} s ({mm['label']}, error {mm['error']:.2e}): "
                f"**{best['cpu'] / mm['cpu']:.0f}×** at equal accuracy there, a lower bound of the ratio at the target"
                if mm else "; mecano-rs has no run at that error")
        lines.append(f"- {code} does not reach the target on its ladder: its most accurate run, {best['label']}, "
                     f"is {best['error']:.2e} off ({best['error'] / target:.1f}× the target) in {best['cpu']:.3f} s{tail}.")
    if m is None:
        lines.append("- mecano-rs: no run of the ladder meets the target.")
    return out + lines + [""]


def figure(scene, recs, out):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    ref = next(r for r in recs if r["code"] == "reference")
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    marks = {"mecano-rs": "o", "exudyn": "s", "mbdyn": "^"}
    for code in sorted({r["code"] for r in recs} - {"reference"}):
        pts = sorted((r["cpu"], r["error"]) for r in recs if r["code"] == code and r.get("ok") and r.get("error"))
        if pts:
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], marks.get(code, "x"), label=code)
    ax.axhline(ref["target"], color="grey", ls="--", lw=1, label="1e-3 of the motion")
    ax.set_xlabel("CPU s (mecano-rs, MBDyn: the whole process; Exudyn: its solve)")
    ax.set_ylabel("largest error against the reference")
    ax.set_title(scene)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(os.path.join(out, f"{scene}.{ext}"))
    plt.close(fig)
    return True


def report(records, out):
    m = next((r for r in records if r["code"] == "machine"), None)
    text = [f"Machine: {m['cpu']}, {m['memory_gib']} GiB; mecano-rs {m['mecano_commit']}, Python {m['python']}; "
            f"load average at the start {' '.join(m['load'] or [])}.", ""] if m else []
    versions = sorted({f"{r['code']} {r['version']}" for r in records if r.get("version")})
    if versions:
        text += ["Peers: " + ", ".join(versions) + ".", ""]
    drawn = []
    for scene in SCENES:
        recs = [r for r in records if r["scene"] == scene]
        if not any(r["code"] == "reference" for r in recs):
            continue
        text += scene_report(scene, recs)
        if figure(scene, recs, out):
            drawn.append(scene)
    if not drawn:
        text.append("(no figures: matplotlib is not importable by this Python)")
    body = "\n".join(text)
    tmp = os.path.join(out, "tables.md.tmp")
    with open(tmp, "w") as f:
        f.write(body + "\n")
    os.replace(tmp, os.path.join(out, "tables.md"))
    print(body)


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..", "out", "peers")
    report([json.loads(line) for line in open(os.path.join(out, "runs.jsonl"))], out)
