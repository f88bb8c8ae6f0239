//! A linear 3D Euler–Bernoulli frame (consistent mass; Przemieniecki, *Theory of Matrix
//! Structural Analysis*, 1968, §5 and §11) assembled as an FE model of six dofs per node:
//! the independent reference model of the superelement's tests and the mesh of its cost
//! bench (`benches/superelement.rs`), never part of a run.

use super::fe::FeModel;
use super::mtx::SymMatrix;
use nalgebra::{DMatrix, Matrix3, Vector3};

// The section of the frame (steel, a thin rectangle of 1 cm²).
/// Young's modulus, Pa.
pub const E: f64 = 2.1e11;
/// Shear modulus, Pa.
pub const G: f64 = 8.0e10;
/// Section area, m².
pub const A: f64 = 1e-4;
/// Second moment about the local y axis, m⁴.
pub const IY: f64 = 8.3e-10;
/// Second moment about the local z axis, m⁴.
pub const IZ: f64 = 2.1e-9;
/// Torsion constant, m⁴.
pub const J: f64 = 2.5e-9;
/// Density, kg/m³.
pub const RHO: f64 = 7800.0;

/// The local 12×12 stiffness and consistent mass of a 3D Euler–Bernoulli beam.
fn local(l: f64) -> (DMatrix<f64>, DMatrix<f64>) {
    let (mut k, mut m) = (DMatrix::zeros(12, 12), DMatrix::zeros(12, 12));
    let put2 = |a: &mut DMatrix<f64>, dofs: [usize; 2], c: f64, b: [[f64; 2]; 2]| {
        for i in 0..2 {
            for j in 0..2 {
                a[(dofs[i], dofs[j])] += c * b[i][j];
            }
        }
    };
    put2(&mut k, [0, 6], E * A / l, [[1.0, -1.0], [-1.0, 1.0]]);
    put2(&mut k, [3, 9], G * J / l, [[1.0, -1.0], [-1.0, 1.0]]);
    put2(&mut m, [0, 6], RHO * A * l / 6.0, [[2.0, 1.0], [1.0, 2.0]]);
    put2(
        &mut m,
        [3, 9],
        RHO * (IY + IZ) * l / 6.0,
        [[2.0, 1.0], [1.0, 2.0]],
    );
    let kb = |ei: f64| {
        let c = ei / l.powi(3);
        [
            [12.0 * c, 6.0 * l * c, -12.0 * c, 6.0 * l * c],
            [6.0 * l * c, 4.0 * l * l * c, -6.0 * l * c, 2.0 * l * l * c],
            [-12.0 * c, -6.0 * l * c, 12.0 * c, -6.0 * l * c],
            [6.0 * l * c, 2.0 * l * l * c, -6.0 * l * c, 4.0 * l * l * c],
        ]
    };
    let c = RHO * A * l / 420.0;
    let mb = [
        [156.0 * c, 22.0 * l * c, 54.0 * c, -13.0 * l * c],
        [
            22.0 * l * c,
            4.0 * l * l * c,
            13.0 * l * c,
            -3.0 * l * l * c,
        ],
        [54.0 * c, 13.0 * l * c, 156.0 * c, -22.0 * l * c],
        [
            -13.0 * l * c,
            -3.0 * l * l * c,
            -22.0 * l * c,
            4.0 * l * l * c,
        ],
    ];
    let put4 = |a: &mut DMatrix<f64>, dofs: [usize; 4], b: [[f64; 4]; 4], sign: [f64; 4]| {
        for i in 0..4 {
            for j in 0..4 {
                a[(dofs[i], dofs[j])] += sign[i] * sign[j] * b[i][j];
            }
        }
    };
    // v, θz (plane xy) and w, θy (plane xz: θy = −w′).
    put4(&mut k, [1, 5, 7, 11], kb(E * IZ), [1.0; 4]);
    put4(&mut m, [1, 5, 7, 11], mb, [1.0; 4]);
    put4(&mut k, [2, 4, 8, 10], kb(E * IY), [1.0, -1.0, 1.0, -1.0]);
    put4(&mut m, [2, 4, 8, 10], mb, [1.0, -1.0, 1.0, -1.0]);
    (k, m)
}

/// An L-shaped frame in the xy plane, 1 m legs, `per` elements each: FE nodes 1 (origin)
/// to 2·per + 1.
pub fn l_frame(per: usize) -> FeModel {
    frame(
        &[
            Vector3::zeros(),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(1.0, 0.8, 0.3),
        ],
        per,
    )
}

/// A 3D frame: the polyline through `corners`, each segment in `per` elements; FE nodes
/// numbered 1, 2, … along it.
pub fn frame(corners: &[Vector3<f64>], per: usize) -> FeModel {
    let mut pts = vec![corners[0]];
    for w in corners.windows(2) {
        for i in 1..=per {
            pts.push(w[0] + (w[1] - w[0]) * (i as f64 / per as f64));
        }
    }
    let bars: Vec<(usize, usize)> = (1..pts.len()).map(|e| (e - 1, e)).collect();
    assemble(&pts, &bars)
}

/// A grillage: `nx × ny` nodes on a square grid of spacing `step` in the xy plane, each
/// joined to its neighbours along x and y by one beam; FE node `j·nx + i + 1` at
/// `(i·step, j·step, 0)`. A mesh of `6·nx·ny` dofs with a sparse `K` (the cost bench).
pub fn grillage(nx: usize, ny: usize, step: f64) -> FeModel {
    let pts: Vec<Vector3<f64>> = (0..nx * ny)
        .map(|p| Vector3::new((p % nx) as f64 * step, (p / nx) as f64 * step, 0.0))
        .collect();
    let mut bars = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let p = j * nx + i;
            if i + 1 < nx {
                bars.push((p, p + 1));
            }
            if j + 1 < ny {
                bars.push((p, p + nx));
            }
        }
    }
    assemble(&pts, &bars)
}

/// The FE model of beams joining `pts[a]` to `pts[b]` for each `(a, b)` of `bars`: six
/// dofs per node in node order, the element matrices rotated to global axes
/// (`Tᵀ k T`, `T = diag(Λ, Λ, Λ, Λ)`, Λ's rows the local axes) and summed as lower-triangle
/// triplets.
pub fn assemble(pts: &[Vector3<f64>], bars: &[(usize, usize)]) -> FeModel {
    let n = 6 * pts.len();
    let (mut k, mut m) = (Vec::new(), Vec::new());
    for &(a, b) in bars {
        let d = pts[b] - pts[a];
        let l = d.norm();
        let ex = d / l;
        let t = if ex.z.abs() < 0.9 {
            Vector3::z()
        } else {
            Vector3::x()
        };
        let ey = t.cross(&ex).normalize();
        let ez = ex.cross(&ey);
        let lam = Matrix3::from_rows(&[ex.transpose(), ey.transpose(), ez.transpose()]);
        let (kl, ml) = local(l);
        let mut tt = DMatrix::zeros(12, 12);
        for q in 0..4 {
            tt.view_mut((3 * q, 3 * q), (3, 3)).copy_from(&lam);
        }
        let kg = tt.transpose() * kl * &tt;
        let mg = tt.transpose() * ml * &tt;
        let row = |i: usize| if i < 6 { 6 * a + i } else { 6 * b + i - 6 };
        for i in 0..12 {
            for j in 0..12 {
                let (gi, gj) = (row(i), row(j));
                if gi >= gj {
                    if kg[(i, j)] != 0.0 {
                        k.push((gi, gj, kg[(i, j)]));
                    }
                    if mg[(i, j)] != 0.0 {
                        m.push((gi, gj, mg[(i, j)]));
                    }
                }
            }
        }
    }
    FeModel {
        k: SymMatrix { n, entries: k },
        m: SymMatrix { n, entries: m },
        nodes: pts
            .iter()
            .enumerate()
            .map(|(i, p)| (i as u32 + 1, *p))
            .collect(),
        dofs: (0..n)
            .map(|r| ((r / 6) as u32 + 1, (r % 6) as u8))
            .collect(),
    }
}
