#!/usr/bin/env python3
"""The FE model of decks/superelement/plate/: a flat aluminium plate, 0.5 m x 0.3 m x 5 mm,
in the xy plane (corner at the origin), meshed in NX x NY rectangles of a flat shell:

* membrane: the bilinear plane-stress quadrilateral (2 x 2 Gauss), dofs ux, uy;
* bending: the Adini-Clough-Melosh rectangle (ACM, 12 dofs: w, rx = dw/dy, ry = -dw/dx per
  node; Kirchhoff; Zienkiewicz & Taylor, The Finite Element Method, vol. 2, 6th ed., §4.4),
  consistent mass with the rotary inertia rho h^3/12 of the Kirchhoff plate;
* five dofs per node (ux uy uz rx ry: no drilling rotation), consistent mass.

It writes K.mtx, M.mtx (Matrix Market coordinate real symmetric, lower triangle, 17 digits),
nodes.csv and dofs.csv in the superelement's format (docs/superelements.md, "Input"), after
two checks that fail loudly:

* patch test: a linear membrane field and a quadratic (constant-curvature) bending field
  are reproduced exactly (no force at the interior nodes);
* the simply supported plate's lowest bending frequencies against Kirchhoff's closed form
  omega_mn = pi^2 (m^2/a^2 + n^2/b^2) sqrt(D / rho h), at the written mesh and at twice it:
  the error falls as h^2 (the ACM rectangle's order).

Node numbering: node j (NX+1) + i + 1 at (i a/NX, j b/NY), i = 0..NX, j = 0..NY; the edge
y = 0 (the hinge of plate_pendulum.dat) is nodes 1..NX+1.

    python3 decks/superelement/plate_mesh.py        (numpy only; e.g. benches/peers/.venv)
"""
import os
import sys

import numpy as np

A_X, B_Y, H = 0.5, 0.3, 0.005  # m
E, NU, RHO = 70e9, 0.33, 2700.0  # Pa, -, kg/m^3
NX, NY = 10, 6

G4 = np.polynomial.legendre.leggauss(4)
G2 = np.polynomial.legendre.leggauss(2)


def acm_basis(x, y):
    """The 12 monomials of the ACM rectangle and their first and second derivatives."""
    p = np.array([1, x, y, x * x, x * y, y * y, x**3, x * x * y, x * y * y, y**3, x**3 * y, x * y**3])
    px = np.array([0, 1, 0, 2 * x, y, 0, 3 * x * x, 2 * x * y, y * y, 0, 3 * x * x * y, y**3])
    py = np.array([0, 0, 1, 0, x, 2 * y, 0, x * x, 2 * x * y, 3 * y * y, x**3, 3 * x * y * y])
    pxx = np.array([0, 0, 0, 2, 0, 0, 6 * x, 2 * y, 0, 0, 6 * x * y, 0])
    pyy = np.array([0, 0, 0, 0, 0, 2, 0, 0, 2 * x, 6 * y, 0, 6 * x * y])
    pxy = np.array([0, 0, 0, 0, 1, 0, 0, 2 * x, 2 * y, 0, 3 * x * x, 3 * y * y])
    return p, px, py, pxx, pyy, pxy


def element(a, b):
    """Stiffness and mass of one a x b rectangle, 20 dofs: per node (ux uy uz rx ry), nodes
    counter-clockwise from (0, 0)."""
    corners = [(0, 0), (a, 0), (a, b), (0, b)]
    # ACM: w = P c, nodal values [w, dw/dy, -dw/dx] = C c.
    cmat = np.zeros((12, 12))
    for i, (x, y) in enumerate(corners):
        p, px, py, *_ = acm_basis(x, y)
        cmat[3 * i], cmat[3 * i + 1], cmat[3 * i + 2] = p, py, -px
    cinv = np.linalg.inv(cmat)
    d = E * H**3 / (12 * (1 - NU**2))
    db = d * np.array([[1, NU, 0], [NU, 1, 0], [0, 0, (1 - NU) / 2]])
    kb, mb = np.zeros((12, 12)), np.zeros((12, 12))
    for xi, wx in zip(*G4):
        for eta, wy in zip(*G4):
            x, y = a * (xi + 1) / 2, b * (eta + 1) / 2
            w = wx * wy * a * b / 4
            p, px, py, pxx, pyy, pxy = (v @ cinv for v in acm_basis(x, y))
            bm = np.vstack([pxx, pyy, 2 * pxy])
            kb += w * bm.T @ db @ bm
            mb += w * (RHO * H * np.outer(p, p) + RHO * H**3 / 12 * (np.outer(px, px) + np.outer(py, py)))
    # Membrane: bilinear plane stress.
    dm = E * H / (1 - NU**2) * np.array([[1, NU, 0], [NU, 1, 0], [0, 0, (1 - NU) / 2]])
    km, mm = np.zeros((8, 8)), np.zeros((8, 8))
    sgn = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    for xi, wx in zip(*G2):
        for eta, wy in zip(*G2):
            n = np.array([(1 + s * xi) * (1 + t * eta) / 4 for s, t in sgn])
            nx = np.array([s * (1 + t * eta) / 4 for s, t in sgn]) * 2 / a
            ny = np.array([t * (1 + s * xi) / 4 for s, t in sgn]) * 2 / b
            bmat = np.zeros((3, 8))
            bmat[0, 0::2], bmat[1, 1::2] = nx, ny
            bmat[2, 0::2], bmat[2, 1::2] = ny, nx
            w = wx * wy * a * b / 4
            km += w * bmat.T @ dm @ bmat
            nn = np.zeros((2, 8))
            nn[0, 0::2], nn[1, 1::2] = n, n
            mm += w * RHO * H * nn.T @ nn
    # Gauss 4 x 4 for the mass of 2 x 2-integrated bilinear terms: both exact.
    k, m = np.zeros((20, 20)), np.zeros((20, 20))
    memb = [5 * i + c for i in range(4) for c in (0, 1)]
    bend = [5 * i + c for i in range(4) for c in (2, 3, 4)]
    k[np.ix_(memb, memb)], m[np.ix_(memb, memb)] = km, mm
    k[np.ix_(bend, bend)], m[np.ix_(bend, bend)] = kb, mb
    return k, m


def assemble(nx, ny):
    a, b = A_X / nx, B_Y / ny
    ke, me = element(a, b)
    nn = (nx + 1) * (ny + 1)
    k, m = np.zeros((5 * nn, 5 * nn)), np.zeros((5 * nn, 5 * nn))
    for j in range(ny):
        for i in range(nx):
            ids = [j * (nx + 1) + i, j * (nx + 1) + i + 1, (j + 1) * (nx + 1) + i + 1, (j + 1) * (nx + 1) + i]
            dofs = [5 * n + c for n in ids for c in range(5)]
            k[np.ix_(dofs, dofs)] += ke
            m[np.ix_(dofs, dofs)] += me
    xy = np.array([(i * a, j * b) for j in range(ny + 1) for i in range(nx + 1)])
    return k, m, xy


def patch_test(k, xy, nx, ny):
    """Linear membrane and constant-curvature bending fields: zero force at interior nodes."""
    n = len(xy)
    x, y = xy[:, 0], xy[:, 1]
    u = np.zeros(5 * n)
    u[0::5], u[1::5] = 1e-3 * x + 2e-3 * y, -1e-3 * x + 3e-3 * y
    # w = c1 x^2 + c2 x y + c3 y^2: rx = dw/dy, ry = -dw/dx.
    c1, c2, c3 = 0.7, -0.4, 0.3
    u[2::5] = c1 * x * x + c2 * x * y + c3 * y * y
    u[3::5] = c2 * x + 2 * c3 * y
    u[4::5] = -(2 * c1 * x + c2 * y)
    f = k @ u
    interior = [j * (nx + 1) + i for j in range(1, ny) for i in range(1, nx)]
    rows = [5 * p + c for p in interior for c in range(5)]
    rel = np.abs(f[rows]).max() / np.abs(f).max()
    assert rel < 1e-10, f"patch test: interior force {rel:.2e} of the largest"
    return rel


def ssss_frequencies(nx, ny, count=4):
    """Lowest bending frequencies (Hz) of the simply supported plate: w = 0 on the edges, and
    the rotation about the edge's normal (the tangential slope) held."""
    k, m, xy = assemble(nx, ny)
    fixed = set()
    for p, (x, y) in enumerate(xy):
        fixed.update(5 * p + c for c in (0, 1))  # membrane held: bending alone
        on_x = abs(x) < 1e-12 or abs(x - A_X) < 1e-12
        on_y = abs(y) < 1e-12 or abs(y - B_Y) < 1e-12
        if on_x or on_y:
            fixed.add(5 * p + 2)
        if on_y:
            fixed.add(5 * p + 4)  # edge along x: dw/dx = 0, ry = -dw/dx
        if on_x:
            fixed.add(5 * p + 3)  # edge along y: dw/dy = 0, rx
    free = [i for i in range(len(k)) if i not in fixed]
    kk, mm = k[np.ix_(free, free)], m[np.ix_(free, free)]
    lc = np.linalg.cholesky(mm)
    li = np.linalg.inv(lc)
    w2 = np.linalg.eigvalsh(li @ kk @ li.T)
    return np.sqrt(np.sort(w2)[:count]) / (2 * np.pi)


def kirchhoff_ssss(count=4):
    d = E * H**3 / (12 * (1 - NU**2))
    w = sorted(
        np.pi**2 * (mx**2 / A_X**2 + ny**2 / B_Y**2) * np.sqrt(d / (RHO * H))
        for mx in range(1, 6)
        for ny in range(1, 6)
    )
    return np.array(w[:count]) / (2 * np.pi)


def write_mtx(path, a, what):
    n = len(a)
    rows = [(i, j, a[i, j]) for j in range(n) for i in range(j, n) if a[i, j] != 0.0]
    with open(path, "w") as f:
        f.write("%%MatrixMarket matrix coordinate real symmetric\n")
        f.write(f"% {what}. decks/superelement/plate_mesh.py: flat shell (bilinear membrane + ACM plate), "
                f"{NX} x {NY} rectangles, {A_X} x {B_Y} x {H} m aluminium; rows: dofs.csv\n")
        f.write(f"{n} {n} {len(rows)}\n")
        for i, j, v in rows:
            f.write(f"{i + 1} {j + 1} {float(v)!r}\n")


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "plate")
    k, m, xy = assemble(NX, NY)
    rel = patch_test(k, xy, NX, NY)
    print(f"patch test: largest interior force {rel:.1e} of the largest nodal force")
    exact = kirchhoff_ssss()
    errs = []
    for f in (1, 2):
        fe = ssss_frequencies(NX * f, NY * f)
        e = np.abs(fe - exact) / exact
        errs.append(e.max())
        print(f"simply supported, {NX * f} x {NY * f}: f = {np.round(fe, 3)} Hz, Kirchhoff "
              f"{np.round(exact, 3)}; largest relative error {e.max():.2e}")
    ratio = errs[0] / errs[1]
    print(f"error ratio for half the element size: {ratio:.2f} (h^2: 4)")
    assert errs[0] < 0.05 and 3.0 < ratio < 5.0, "the plate's frequencies do not converge as h^2"
    os.makedirs(out, exist_ok=True)
    write_mtx(os.path.join(out, "K.mtx"), k, "stiffness K, N/m, N, N·m")
    write_mtx(os.path.join(out, "M.mtx"), m, "mass M, kg, kg·m, kg·m²")
    with open(os.path.join(out, "nodes.csv"), "w") as f:
        f.write("node,x,y,z\n")
        for p, (x, y) in enumerate(xy):
            f.write(f"{p + 1},{float(x)!r},{float(y)!r},0.0\n")
    with open(os.path.join(out, "dofs.csv"), "w") as f:
        f.write("dof,node,component\n")
        for p in range(len(xy)):
            for c in range(5):
                f.write(f"{5 * p + c + 1},{p + 1},{c + 1}\n")
    print(f"wrote {out}: {len(k)} dofs, mass {m[0::5, 0::5].sum():.6f} kg "
          f"(rho a b h = {RHO * A_X * B_Y * H:.6f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
