#!/usr/bin/env python3
"""Why mecano-rs's third-order integrator is not a Richardson extrapolation of HHT or
generalized-alpha (docs/accuracy.md, "A third-order integrator"): on the linear oscillator
q'' = -w^2 q, local extrapolation of one step of H against two of H/2,

    y_R = y_B + (y_B - y_A)/3,

of the Newmark-type schemes in the state (q, v, a) of Arnold & Bruls (2007) (equilibrium at
t_{n+1}, (1 - am) a_{n+1} + am a_n = (1 - af) qdd_{n+1} + af qdd_n).

  variant "a combined": a extrapolated like q and v: the observed order falls to 1 (the
      pseudo-acceleration a ~ qdd(t + (am - af) h) means something else at H and H/2);
  variant "a per chain": q, v extrapolated, each chain (H and H/2) keeps its own a: order 3,
      but the largest spectral radius of the extrapolated step exceeds 1 for every base
      (HHT alpha in [-1/3, 0], generalized-alpha rho_inf in [0, 1)): mid frequencies grow.

Prints, per base and variant, the largest spectral radius over w H in [1e-2, 1e4], where it
is, its value at w H = 1e4, and the observed order of q at t = 2 (w = 3). numpy only.
"""
import numpy as np


def ga(rho):
    am = (2 * rho - 1) / (rho + 1)
    af = rho / (rho + 1)
    g = 0.5 + af - am
    return am, af, 0.25 * (g + 0.5) ** 2, g


def hht(alpha):
    return 0.0, -alpha, (1 - alpha) ** 2 / 4, 0.5 - alpha


def step(y, h, w, p):
    am, af, be, ga_ = p
    q, v, a, qdd = y
    k = (1 - am) / ((1 - af) * be * h * h)
    rhs = -w * w * q + ((1 - am) * (v / h + a * (0.5 - be)) / be - am * a + af * qdd) / (1 - af)
    u = rhs / (k + w * w)
    a1 = (u / (h * h) - v / h - a * (0.5 - be)) / be
    return np.array([q + u, v + h * ((1 - ga_) * a + ga_ * a1), a1,
                     ((1 - am) * a1 + am * a - af * qdd) / (1 - af)])


def extrapolated(s, H, w, p, per_chain):
    q, v, a_h, a_h2, qdd = s
    if not per_chain:
        a_h2 = a_h
    A = step(np.array([q, v, a_h, qdd]), H, w, p)
    B = step(step(np.array([q, v, a_h2, qdd]), H / 2, w, p), H / 2, w, p)
    R = (4 * B - A) / 3
    if per_chain:
        return np.array([R[0], R[1], A[2], B[2], R[3]])
    return np.array([R[0], R[1], R[2], R[2], R[3]])


def radius(H, p, per_chain):
    m = np.column_stack([extrapolated(e, H, 1.0, p, per_chain) for e in np.eye(5)])
    if not per_chain:
        m = np.delete(np.delete(m, 3, 0), 3, 1)
    return max(abs(np.linalg.eigvals(m)))


def error(n, p, per_chain, w=3.0, t=2.0):
    s = np.array([1.0, 0.0, -w * w, -w * w, -w * w])
    for _ in range(n):
        s = extrapolated(s, t / n, w, p, per_chain)
    return abs(s[0] - np.cos(w * t))


xs = np.logspace(-2, 4, 241)
print("base\tvariant\tmax radius\tat wH\tradius at wH=1e4\tobserved orders (n = 50..800)")
for name, p in [("HHT a=-0.1", hht(-0.1)), ("HHT a=-1/3", hht(-1 / 3)),
                ("gen-a rho=0", ga(0.0)), ("gen-a rho=0.25", ga(0.25)),
                ("gen-a rho=0.5", ga(0.5)), ("gen-a rho=0.8", ga(0.8))]:
    for per_chain in (False, True):
        r = np.array([radius(x, p, per_chain) for x in xs])
        e = [error(n, p, per_chain) for n in (50, 100, 200, 400, 800)]
        orders = ", ".join(f"{np.log2(e[i] / e[i + 1]):.2f}" for i in range(4))
        print(f"{name}\t{'a per chain' if per_chain else 'a combined'}\t{r.max():.4f}\t"
              f"{xs[r.argmax()]:.3g}\t{r[-1]:.4f}\t{orders}")
