//! The sparse reduction ([`super::sparse`]) against the dense one ([`super::reduce`]), the
//! reference, on the test frame of [`super::tests`]: the same static constraint modes,
//! fixed-interface frequencies and modes (up to sign), reduced stiffness and inertia
//! invariants, each to a tolerance derived from what the two routes compute differently.

use super::frame_model::l_frame;
use super::reduce::{DENSE_UP_TO, reduce, reduce_body};
use super::sparse;
use crate::lanczos;
use nalgebra::{DMatrix, SymmetricEigen};

/// `‖a − b‖_max / ‖b‖_max`.
fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

/// The 2-norm condition number of a symmetric positive definite matrix.
fn condition(a: &DMatrix<f64>) -> f64 {
    let ev = SymmetricEigen::new(a.clone()).eigenvalues;
    ev.max() / ev.min()
}

/// Both routes solve `K_II Ψ = −K_IB` by a Cholesky factorisation (dense unordered, sparse
/// AMD-ordered): backward stable, so each `Ψ` is within `c·κ(K_II)·ε` of the exact one
/// (Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., Thm 10.4 with
/// `c = 10` for the growth of the `n`-term sums of this banded matrix). The frequencies:
/// Lanczos stops at `‖Tφ − θφ‖_M ≤ TOL·θ`, which bounds `θ`'s relative error by `TOL`
/// (Parlett, *The Symmetric Eigenvalue Problem*, Thm 11.7.1) and the vector's angle by
/// `TOL / gap` (gap: the relative distance to the nearest other `θ`, Davis–Kahan).
#[test]
fn sparse_reduction_is_the_dense_one() {
    let fe = l_frame(10); // 21 nodes, 126 dofs
    let interface = [1, 21, 11];
    let modes = 8;
    let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
    let dense = reduce(&fe, &k, &m, &interface, modes).expect("dense");
    let sparse = sparse::reduce(&fe, &interface, modes).expect("sparse");
    assert_eq!(dense.frame, sparse.frame);
    assert_eq!(dense.boundary, sparse.boundary);
    let nb = dense.boundary.len();
    let held: Vec<usize> = dense.frame.iter().chain(&dense.boundary).copied().collect();
    let interior: Vec<usize> = (0..fe.dofs.len()).filter(|r| !held.contains(r)).collect();
    let kii = DMatrix::from_fn(interior.len(), interior.len(), |i, j| {
        k[(interior[i], interior[j])]
    });
    let kappa = condition(&kii);
    let psi_tol = 10.0 * kappa * f64::EPSILON;
    let psi = rel(
        &sparse.basis.columns(0, nb).into_owned(),
        &dense.basis.columns(0, nb).into_owned(),
    );
    eprintln!("κ(K_II) = {kappa:.3e}: constraint modes differ by {psi:.3e} (bound {psi_tol:.3e})");
    assert!(psi <= psi_tol, "constraint modes {psi} > {psi_tol}");
    // Frequencies and modes.
    let tol = lanczos::TOL;
    for c in 0..modes {
        let (ws, wd) = (sparse.omega2[c], dense.omega2[c]);
        let e = (ws - wd).abs() / wd;
        // Relative gap in θ = 1/ω² to the neighbours among the dense route's values.
        let theta = |i: usize| 1.0 / dense.omega2[i];
        let mut gap = f64::INFINITY;
        for o in [c.wrapping_sub(1), c + 1] {
            if o < modes {
                gap = gap.min((theta(c) - theta(o)).abs() / theta(c));
            }
        }
        if c + 1 == modes {
            // The next, not kept: its θ is below θ_c by at least the kept spacing's order;
            // take the dense route's ω² of one more mode.
            let more = reduce(&fe, &k, &m, &interface, modes + 1).expect("dense");
            gap = gap.min((theta(c) - 1.0 / more.omega2[modes]).abs() / theta(c));
        }
        let (a, b) = (
            sparse.basis.column(nb + c).into_owned(),
            dense.basis.column(nb + c).into_owned(),
        );
        let sign = if a.dot(&(&m * &b)) < 0.0 { -1.0 } else { 1.0 };
        let d = &a * sign - &b;
        let dm = d.dot(&(&m * &d)).sqrt(); // both are M-normalised
        let vec_tol = 10.0 * tol / gap;
        eprintln!(
            "mode {c}: ω² {wd:.6e}, relative difference {e:.2e}; ‖Δφ‖_M {dm:.2e} (gap {gap:.2e}, bound {vec_tol:.2e})"
        );
        assert!(e <= 10.0 * tol, "mode {c}: ω² differs by {e}");
        assert!(dm <= vec_tol, "mode {c}: ‖Δφ‖_M {dm} > {vec_tol}");
    }
}

/// Above [`DENSE_UP_TO`] FE dofs [`reduce_body`] takes the sparse route; its body (mass
/// from the reader's sparse `M`) has the dense body's mass, first moment and free–free
/// eigenvalues (basis-independent), to the two routes' errors: the Lanczos's `TOL` and
/// the dense route's `κ(K_II)·ε` (it forms `L⁻¹ M_II L⁻ᵀ` from the Cholesky factor).
#[test]
fn a_large_model_takes_the_sparse_route_to_the_same_body() {
    let fe = l_frame(51); // 103 nodes, 618 dofs
    assert!(fe.dofs.len() > DENSE_UP_TO);
    let interface = [1, 103];
    let modes = 6;
    let sparse = reduce_body(&fe, &interface, modes).expect("sparse body");
    let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
    let red = reduce(&fe, &k, &m, &interface, modes).expect("dense");
    let dense = super::invariants::Body::new(&fe, &m, &red, 1, &interface[1..]).expect("dense");
    assert!((sparse.mass - dense.mass).abs() <= 1e-12 * dense.mass);
    assert!((sparse.c0 - dense.c0).norm() <= 1e-12 * dense.c0.norm());
    let eig = |b: &super::invariants::Body| {
        let (mm, kk) = b.free_free();
        let all: Vec<usize> = (0..mm.nrows()).collect();
        super::reduce::lowest_eigenvalues(&kk, &mm, &all, 6 + 6).expect("eigen")
    };
    let (es, ed) = (eig(&sparse), eig(&dense));
    let held: Vec<usize> = red.frame.iter().chain(&red.boundary).copied().collect();
    let interior: Vec<usize> = (0..fe.dofs.len()).filter(|r| !held.contains(r)).collect();
    let kii = DMatrix::from_fn(interior.len(), interior.len(), |i, j| {
        k[(interior[i], interior[j])]
    });
    let bound = 10.0 * (lanczos::TOL + condition(&kii) * f64::EPSILON);
    for (s, d) in es[6..].iter().zip(&ed[6..]) {
        let e = (s - d).abs() / d;
        eprintln!("free-free ω² {d:.6e}: sparse route differs by {e:.2e} (bound {bound:.2e})");
        assert!(e <= bound, "{e}");
    }
}
