#!/usr/bin/env python3
"""The Campbell diagram of the rotating cantilever as one SVG (standard library only).

Usage: scripts/campbell.py out/campbell/sweep.csv docs/figures/campbell.svg

Reads the sweep of sweeps/rotating_cantilever.toml (columns OMEGA, f1..f4 in Hz, the
dimensionless deck: 2 pi f is omega sqrt(m L^4/EI)) and draws the four lowest frequencies
seen in the hub's frame against nu, with the Euler-Bernoulli flapwise table of issue 24
(circles) and sqrt(flap^2 - nu^2) for lead-lag (squares) as references.
"""
import csv
import math
import sys

FLAP = [
    [3.5160, 3.6816, 4.1373, 4.7973, 5.5850, 6.4495, 7.3604, 8.2996, 9.2568, 10.2257,
     11.2023, 12.1843, 13.1702],
    [22.0345, 22.1810, 22.6149, 23.3203, 24.2733, 25.4461, 26.8091, 28.3341, 29.9954,
     31.7705, 33.6404, 35.5890, 37.6031],
]


def main(src, dst):
    rows = [r for r in csv.DictReader(open(src)) if r["status"] == "ok"]
    nu = [float(r["OMEGA"]) for r in rows]
    curves = {q: [2 * math.pi * float(r[q]) for r in rows] for q in ("f1", "f2", "f3", "f4")}
    W, H, L, B, T, R = 640, 480, 60, 50, 30, 20
    xmax, ymax = 12.0, 40.0
    X = lambda x: L + (W - L - R) * x / xmax
    Y = lambda y: H - B - (H - B - T) * y / ymax
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" '
           f'font-family="sans-serif" font-size="12">',
           f'<rect width="{W}" height="{H}" fill="white"/>']
    for i in range(0, 13, 2):
        out.append(f'<line x1="{X(i)}" y1="{Y(0)}" x2="{X(i)}" y2="{Y(ymax)}" stroke="#ddd"/>')
        out.append(f'<text x="{X(i)}" y="{Y(0) + 16}" text-anchor="middle">{i}</text>')
    for j in range(0, 41, 5):
        out.append(f'<line x1="{X(0)}" y1="{Y(j)}" x2="{X(xmax)}" y2="{Y(j)}" stroke="#ddd"/>')
        out.append(f'<text x="{X(0) - 6}" y="{Y(j) + 4}" text-anchor="end">{j}</text>')
    # The speed itself (1 per revolution): where a mode crosses it, resonance in the inertial frame.
    out.append(f'<line x1="{X(0)}" y1="{Y(0)}" x2="{X(12)}" y2="{Y(12)}" stroke="#999" '
               f'stroke-dasharray="4 3"/>')
    colours = {"f1": "#1f77b4", "f2": "#d62728", "f3": "#1f77b4", "f4": "#d62728"}
    for q, ys in curves.items():
        pts = " ".join(f"{X(x):.1f},{Y(y):.1f}" for x, y in zip(nu, ys))
        out.append(f'<polyline points="{pts}" fill="none" stroke="{colours[q]}" stroke-width="1.5"/>')
    for k in range(2):
        for i, f in enumerate(FLAP[k]):
            out.append(f'<circle cx="{X(i):.1f}" cy="{Y(f):.1f}" r="3.5" fill="none" stroke="black"/>')
            g = math.sqrt(f * f - i * i)
            out.append(f'<rect x="{X(i) - 3:.1f}" y="{Y(g) - 3:.1f}" width="6" height="6" '
                       f'fill="none" stroke="black"/>')
    out.append(f'<text x="{(L + W - R) / 2}" y="{H - 12}" text-anchor="middle">'
               'hub speed ν = Ω √(mL⁴/EI)</text>')
    out.append(f'<text x="16" y="{(T + H - B) / 2}" text-anchor="middle" '
               f'transform="rotate(-90 16 {(T + H - B) / 2})">ω √(mL⁴/EI), rotating frame</text>')
    legend = [("#d62728", "flapwise (mecano-rs)"), ("#1f77b4", "lead-lag (mecano-rs)")]
    for i, (c, t) in enumerate(legend):
        y = T + 14 + 16 * i
        out.append(f'<line x1="{L + 12}" y1="{y}" x2="{L + 36}" y2="{y}" stroke="{c}" stroke-width="1.5"/>')
        out.append(f'<text x="{L + 42}" y="{y + 4}">{t}</text>')
    y = T + 14 + 32
    out.append(f'<circle cx="{L + 24}" cy="{y}" r="3.5" fill="none" stroke="black"/>')
    out.append(f'<text x="{L + 42}" y="{y + 4}">Euler–Bernoulli flapwise (issue 24)</text>')
    y += 16
    out.append(f'<rect x="{L + 21}" y="{y - 3}" width="6" height="6" fill="none" stroke="black"/>')
    out.append(f'<text x="{L + 42}" y="{y + 4}">√(flap² − ν²), lead-lag</text>')
    y += 16
    out.append(f'<line x1="{L + 12}" y1="{y}" x2="{L + 36}" y2="{y}" stroke="#999" stroke-dasharray="4 3"/>')
    out.append(f'<text x="{L + 42}" y="{y + 4}">ω = ν</text>')
    out.append("</svg>")
    open(dst, "w").write("\n".join(out) + "\n")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
