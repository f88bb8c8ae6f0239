#!/usr/bin/env python3
"""The solid FE model of decks/superelement/plate_solid/: the plate of plate_mesh.py (aluminium,
0.5 m x 0.3 m x 5 mm, in the xy plane, corner at the origin, mid-plane z = 0) meshed in
NX x NY x NZ rectangular bricks, three translational dofs per node (ux uy uz) — the mesh
Exudyn's ObjectFFRFreducedOrder takes (benches/peers/plate_exudyn.py), and mecano-rs's
SUPERELEMENT too (decks/superelement/plate_solid_pendulum.dat).

* element: the 8-node brick with incompatible modes (Wilson, Taylor, Beresford & Wilson,
  IJNME 10, 1976: "A non-conforming element for stress analysis"; Zienkiewicz & Taylor vol. 1,
  6th ed., §11.3): trilinear displacements plus the nine bubbles (1 - xi^2), (1 - eta^2),
  (1 - zeta^2) per component, condensed statically, 2 x 2 x 2 Gauss. A trilinear brick
  locks in bending (its shear strain is spurious in pure bending: a 5 mm plate in 25 mm
  bricks is 5x too stiff); the incompatible modes represent pure bending exactly in a
  rectangular brick, so one brick through the thickness bends like the plate. Bricks of a
  regular mesh are parallelepipeds: the patch test holds (checked below).
* consistent mass of the trilinear field (the bubbles carry no mass: they are condensed).

It writes K.mtx, M.mtx (Matrix Market coordinate real symmetric, lower triangle, 17 digits),
nodes.csv and dofs.csv in the superelement's format (docs/superelements.md, "Input"), after
two checks that fail loudly:

* patch test: a linear field of plane stress (exx, eyy, gxy, and ezz = -nu/(1-nu)(exx+eyy)
  so that the faces z = +-h/2 are free) gives no force at the nodes off the lateral edges;
* the simply supported plate's lowest bending frequencies (uz = 0 on the four edges'
  nodes) against Kirchhoff's omega_mn = pi^2 (m^2/a^2 + n^2/b^2) sqrt(D / rho h), at the
  written mesh and at twice it in the plane: the error falls at least as the element size
  squared. The written mesh is coarse (the files stay small): 10 x 6 x 1 is 12.7 % stiff
  in the first frequency and 34 % in the fourth, 20 x 12 x 1 1.2 % and 3.9 % (ratio 8.9,
  not yet the asymptotic 4). Both codes of the side by side read these very matrices, so
  the mesh's error is the same for both and does not enter their comparison.

Node numbering: node k (NX+1)(NY+1) + j (NX+1) + i + 1 at (i a/NX, j b/NY, -h/2 + k h/NZ);
the edge y = 0 (the hinge) is nodes with j = 0 (NZ + 1 rows of NX + 1).

    benches/peers/.venv/bin/python decks/superelement/plate_solid_mesh.py   (numpy only)
"""
import os
import sys

import numpy as np

A_X, B_Y, H = 0.5, 0.3, 0.005  # m
E, NU, RHO = 70e9, 0.33, 2700.0  # Pa, -, kg/m^3
NX, NY, NZ = 10, 6, 1

CORNERS = np.array([(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
                    (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)], float)


def dmat():
    lam = E * NU / ((1 + NU) * (1 - 2 * NU))
    mu = E / (2 * (1 + NU))
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[np.arange(3), np.arange(3)] += 2 * mu
    d[np.arange(3, 6), np.arange(3, 6)] = mu
    return d


def bmat(dndx):
    """Strain (exx eyy ezz gxy gyz gzx) of nodal displacements, ux uy uz per node."""
    n = dndx.shape[0]
    b = np.zeros((6, 3 * n))
    b[0, 0::3], b[1, 1::3], b[2, 2::3] = dndx[:, 0], dndx[:, 1], dndx[:, 2]
    b[3, 0::3], b[3, 1::3] = dndx[:, 1], dndx[:, 0]
    b[4, 1::3], b[4, 2::3] = dndx[:, 2], dndx[:, 1]
    b[5, 0::3], b[5, 2::3] = dndx[:, 2], dndx[:, 0]
    return b


def element(a, b, c):
    """Stiffness and mass of one a x b x c brick, 24 dofs (ux uy uz per node, CORNERS order)."""
    half = np.array([a, b, c]) / 2
    det = half.prod()
    d = dmat()
    g = np.polynomial.legendre.leggauss(2)
    kuu, kua, kaa, m = np.zeros((24, 24)), np.zeros((24, 9)), np.zeros((9, 9)), np.zeros((24, 24))
    for xi, wx in zip(*g):
        for eta, wy in zip(*g):
            for zeta, wz in zip(*g):
                s = np.array([xi, eta, zeta])
                w = wx * wy * wz * det
                n = np.prod(1 + CORNERS * s, axis=1) / 8
                dn = np.empty((8, 3))
                for k in range(3):
                    others = [o for o in range(3) if o != k]
                    dn[:, k] = CORNERS[:, k] * np.prod(1 + CORNERS[:, others] * s[others], axis=1) / 8 / half[k]
                # incompatible modes: (1 - s_k^2) for each component; d/dx_k = -2 s_k / half_k
                dbub = np.zeros((3, 3))  # dbub[k] = gradient of bubble k
                for k in range(3):
                    dbub[k, k] = -2 * s[k] / half[k]
                bu, ba = bmat(dn), bmat(dbub)
                kuu += w * bu.T @ d @ bu
                kua += w * bu.T @ d @ ba
                kaa += w * ba.T @ d @ ba
                nn = np.zeros((3, 24))
                for k in range(3):
                    nn[k, k::3] = n
                m += w * RHO * nn.T @ nn
    k = kuu - kua @ np.linalg.solve(kaa, kua.T)
    return (k + k.T) / 2, m


def assemble(nx, ny, nz):
    a, b, c = A_X / nx, B_Y / ny, H / nz
    ke, me = element(a, b, c)
    nid = lambda i, j, k: k * (nx + 1) * (ny + 1) + j * (nx + 1) + i
    nn = (nx + 1) * (ny + 1) * (nz + 1)
    kg, mg = np.zeros((3 * nn, 3 * nn)), np.zeros((3 * nn, 3 * nn))
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                ids = [nid(i + (cx > 0), j + (cy > 0), k + (cz > 0)) for cx, cy, cz in CORNERS]
                dofs = [3 * p + q for p in ids for q in range(3)]
                kg[np.ix_(dofs, dofs)] += ke
                mg[np.ix_(dofs, dofs)] += me
    xyz = np.array([(i * a, j * b, -H / 2 + k * c)
                    for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)])
    return kg, mg, xyz


def on_lateral_edge(x, y):
    return abs(x) < 1e-12 or abs(x - A_X) < 1e-12 or abs(y) < 1e-12 or abs(y - B_Y) < 1e-12


def patch_test(k, xyz):
    exx, eyy, gxy = 1e-3, -2e-3, 3e-3
    ezz = -NU / (1 - NU) * (exx + eyy)
    x, y, z = xyz.T
    u = np.zeros(k.shape[0])
    u[0::3], u[1::3], u[2::3] = exx * x + gxy / 2 * y, gxy / 2 * x + eyy * y, ezz * z
    f = k @ u
    inner = [p for p, (x, y, _) in enumerate(xyz) if not on_lateral_edge(x, y)]
    rows = [3 * p + q for p in inner for q in range(3)]
    rel = np.abs(f[rows]).max() / np.abs(f).max()
    assert rel < 1e-10, f"patch test: force {rel:.2e} of the largest off the lateral edges"
    return rel


def ssss_frequencies(nx, ny, nz, count=4):
    """Lowest bending frequencies (Hz), uz = 0 at the nodes of the four lateral edges."""
    k, m, xyz = assemble(nx, ny, nz)
    fixed = {3 * p + 2 for p, (x, y, _) in enumerate(xyz) if on_lateral_edge(x, y)}
    free = [i for i in range(len(k)) if i not in fixed]
    lc = np.linalg.cholesky(m[np.ix_(free, free)])
    li = np.linalg.inv(lc)
    w2 = np.linalg.eigvalsh(li @ k[np.ix_(free, free)] @ li.T)
    # three in-plane rigid motions (ux, uy, rz) are left free: zeros, skipped
    w2 = np.sort(w2)
    assert np.abs(w2[:3]).max() < 1e-6 * w2[3], "three in-plane rigid motions expected"
    w2 = w2[3:]
    return np.sqrt(w2[:count]) / (2 * np.pi)


def kirchhoff_ssss(count=4):
    d = E * H**3 / (12 * (1 - NU**2))
    w = sorted(np.pi**2 * (p**2 / A_X**2 + q**2 / B_Y**2) * np.sqrt(d / (RHO * H))
               for p in range(1, 6) for q in range(1, 6))
    return np.array(w[:count]) / (2 * np.pi)


def write_mtx(path, a, what):
    n = len(a)
    rows = [(i, j, a[i, j]) for j in range(n) for i in range(j, n) if a[i, j] != 0.0]
    with open(path, "w") as f:
        f.write("%%MatrixMarket matrix coordinate real symmetric\n")
        f.write(f"% {what}. decks/superelement/plate_solid_mesh.py: 8-node bricks with incompatible "
                f"modes, {NX} x {NY} x {NZ}, {A_X} x {B_Y} x {H} m aluminium; rows: dofs.csv\n")
        f.write(f"{n} {n} {len(rows)}\n")
        for i, j, v in rows:
            f.write(f"{i + 1} {j + 1} {float(v)!r}\n")


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "plate_solid")
    k, m, xyz = assemble(NX, NY, NZ)
    # a trilinear brick's K has round-off where the exact entry is 0: keep what is above
    # 1e-13 of the row's diagonal scale, so the files hold the element's structure
    scale = np.sqrt(np.outer(np.diag(k), np.diag(k)))
    k[np.abs(k) < 1e-13 * scale] = 0.0
    rel = patch_test(k, xyz)
    print(f"patch test: largest force off the lateral edges {rel:.1e} of the largest nodal force")
    exact = kirchhoff_ssss()
    errs = []
    for f in (1, 2):
        fe = ssss_frequencies(NX * f, NY * f, NZ)
        e = np.abs(fe - exact) / exact
        errs.append(e.max())
        print(f"simply supported, {NX * f} x {NY * f} x {NZ}: f = {np.round(fe, 3)} Hz, Kirchhoff "
              f"{np.round(exact, 3)}; largest relative error {e.max():.2e}")
    ratio = errs[0] / errs[1]
    print(f"error ratio for half the element size: {ratio:.2f} (h^2: 4; above it before the asymptote)")
    assert errs[0] < 0.5 and ratio > 3.0, "the plate's frequencies do not converge"
    os.makedirs(out, exist_ok=True)
    write_mtx(os.path.join(out, "K.mtx"), k, "stiffness K, N/m")
    write_mtx(os.path.join(out, "M.mtx"), m, "mass M, kg")
    with open(os.path.join(out, "nodes.csv"), "w") as f:
        f.write("node,x,y,z\n")
        for p, (x, y, z) in enumerate(xyz):
            f.write(f"{p + 1},{float(x)!r},{float(y)!r},{float(z)!r}\n")
    with open(os.path.join(out, "dofs.csv"), "w") as f:
        f.write("dof,node,component\n")
        for p in range(len(xyz)):
            for c in range(3):
                f.write(f"{3 * p + c + 1},{p + 1},{c + 1}\n")
    print(f"wrote {out}: {len(k)} dofs, mass {m[0::3, 0::3].sum():.6f} kg "
          f"(rho a b h = {RHO * A_X * B_Y * H:.6f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
