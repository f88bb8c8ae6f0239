//! The Hurty–Craig–Bampton reduction of a finite-element model about one of its
//! interface nodes (the frame node), dense.
//!
//! The FE dofs split into the frame node's `F` (6), the other interface nodes' `B` and the
//! interior `I`. With `F` and `B` held, the basis is (Craig & Bampton, AIAA J. 6(7), 1968;
//! Géradin & Rixen, *Mechanical Vibrations*, 3rd ed., §8.4)
//!
//! ```text
//!        ⎡ 0    0 ⎤ F         Ψ = −K_II⁻¹ K_IB   (static constraint modes)
//!   Φ =  ⎢ I    0 ⎥ B         K_II φ = ω² M_II φ (fixed-interface normal modes, the lowest)
//!        ⎣ Ψ    φ ⎦ I
//! ```
//!
//! so that a coordinate of `B` is the displacement (or small rotation) of that interface
//! dof relative to the frame node, and `Φᵀ K Φ`, `Φᵀ M Φ` are the superelement's matrices
//! clamped at the frame node. The frame node's own six constraint modes would be the
//! rigid motions (static condensation reproduces them exactly): the floating frame
//! ([`super::invariants`]) carries those. With every interior mode kept the basis spans
//! the whole space and the reduction is exact. The generalised eigenproblem is solved on
//! the Cholesky factor `L` of `K_II` (`μ = 1/ω²` of `L⁻¹ M_II L⁻ᵀ`): it needs `K_II`
//! positive definite (the interface holds the body) but only `M_II` semi-definite.

use super::fe::FeModel;
use super::invariants::Body;
use nalgebra::{Cholesky, DMatrix, Dyn, SymmetricEigen};

/// Up to this many FE dofs a model is reduced densely (the dense path is the reference
/// the sparse one is tested against, and avoids the Lanczos for models where asking for
/// most interior modes is common); above, sparsely ([`super::sparse`]).
pub const DENSE_UP_TO: usize = 600;

/// The reduction and its inertia invariants, on the dense path up to [`DENSE_UP_TO`] FE
/// dofs (or when the modes asked leave fewer than a Lanczos block of interior modes
/// beyond them), on the sparse path above.
pub fn reduce_body(fe: &FeModel, interface: &[u32], modes: usize) -> Result<Body, String> {
    reduce_body_and_basis(fe, interface, modes).map(|(b, _)| b)
}

/// [`reduce_body`] and the reduction's basis `Φ` (FE dofs × elastic coordinates), which
/// the deformed mesh's recovery needs.
pub fn reduce_body_and_basis(
    fe: &FeModel,
    interface: &[u32],
    modes: usize,
) -> Result<(Body, DMatrix<f64>), String> {
    let n = fe.dofs.len();
    let interior = n.saturating_sub(6 * interface.len());
    let dense = n <= DENSE_UP_TO || modes + crate::lanczos::BLOCK > interior;
    let (frame, iface) = (interface[0], &interface[1..]);
    if dense && n <= DENSE_MAX_DOFS {
        let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
        let red = reduce(fe, &k, &m, interface, modes).map_err(|e| e.to_string())?;
        let body = Body::new(fe, &m, &red, frame, iface).map_err(|e| e.to_string())?;
        Ok((body, red.basis))
    } else {
        let red = super::sparse::reduce(fe, interface, modes).map_err(|e| e.to_string())?;
        let body = Body::new(fe, &fe.m, &red, frame, iface).map_err(|e| e.to_string())?;
        Ok((body, red.basis))
    }
}

/// Above this many FE dofs the dense reduction is refused (`O(n³)` flops, `n²` memory).
pub const DENSE_MAX_DOFS: usize = 4000;

/// A Craig–Bampton basis and the reduced stiffness.
#[derive(Debug, Clone)]
pub struct Reduction {
    /// FE rows of the frame node's six dofs.
    pub frame: [usize; 6],
    /// FE rows of the other interface nodes' dofs, six per node in the deck's order.
    pub boundary: Vec<usize>,
    /// The basis `Φ` (FE dofs × elastic coordinates): the boundary dofs, then the modes.
    pub basis: DMatrix<f64>,
    /// Reduced stiffness `Φᵀ K Φ`.
    pub k: DMatrix<f64>,
    /// The kept fixed-interface modes' `ω²`, rad²/s².
    pub omega2: Vec<f64>,
}

/// Why a reduction cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReduceError {
    /// An interface node the FE model does not have with all six components.
    #[error(
        "interface node {node}: the FE model has no component {component} of it (rows of dofs.csv: node, component 1–6)"
    )]
    InterfaceDof {
        /// FE node.
        node: u32,
        /// Component, 1–6.
        component: u8,
    },
    /// An interface node named twice.
    #[error("FE node {0} is named twice in INTERFACE")]
    Repeated(u32),
    /// More modes asked for than interior dofs.
    #[error(
        "MODES {asked}: the FE model has {interior} interior degrees of freedom (dofs not on an interface node)"
    )]
    TooManyModes {
        /// Asked for.
        asked: usize,
        /// Interior dofs.
        interior: usize,
    },
    /// `K_II` is not positive definite: the interface leaves part of the body free.
    #[error(
        "with its interface nodes held, the FE model is not held: its interior stiffness K_II is not positive definite (a part of the mesh connected to no interface node, or a stiffness that is not positive)"
    )]
    NotHeld,
    /// A kept mode of zero (or negative) mass.
    #[error(
        "MODES {asked}: only {found} fixed-interface modes have mass (the mass matrix is not positive definite on the interior)"
    )]
    Massless {
        /// Asked for.
        asked: usize,
        /// With positive mass.
        found: usize,
    },
    /// The kept modes end inside a multiple eigenvalue: which vectors of its eigenspace
    /// are kept is arbitrary (a rotated FE model would keep others), so the model would
    /// not be objective.
    #[error(
        "MODES {asked} keeps part of {count} fixed-interface modes of equal frequency ({hz:.6e} Hz): keep {below} or {above}"
    )]
    SplitsMultiple {
        /// Asked for.
        asked: usize,
        /// The multiplicity.
        count: usize,
        /// Their frequency, Hz.
        hz: f64,
        /// The nearest counts that keep the eigenspace whole.
        below: usize,
        /// Above.
        above: usize,
    },
    /// The sparse factorisation or the eigen-solver failed otherwise.
    #[error("sparse reduction: {0}")]
    Sparse(String),
    /// The shift-invert Lanczos did not converge.
    #[error(
        "the fixed-interface modes did not converge: {converged} of {count} after {solves} solves (shift-invert Lanczos)"
    )]
    NoConvergence {
        /// Converged.
        converged: usize,
        /// Asked for (the kept modes and a block beyond, for the multiplicity check).
        count: usize,
        /// Solves spent.
        solves: usize,
    },
    /// Too large for the dense reduction.
    #[error(
        "{0} degrees of freedom: the dense reduction of this version takes at most {DENSE_MAX_DOFS}"
    )]
    TooLarge(usize),
}

/// The rows of the six components of FE node `node`.
fn six(fe: &FeModel, node: u32) -> Result<[usize; 6], ReduceError> {
    let mut r = [0; 6];
    for (c, row) in r.iter_mut().enumerate() {
        *row = fe.dof_of(node, c as u8).ok_or(ReduceError::InterfaceDof {
            node,
            component: c as u8 + 1,
        })?;
    }
    Ok(r)
}

/// `a[rows, cols]`.
fn sub(a: &DMatrix<f64>, rows: &[usize], cols: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), cols.len(), |i, j| a[(rows[i], cols[j])])
}

/// The FE rows split for the reduction: the frame node's, the other interface nodes', the
/// interior (ascending).
pub struct Partition {
    /// The frame node's six rows.
    pub frame: [usize; 6],
    /// The other interface nodes' rows, six per node.
    pub boundary: Vec<usize>,
    /// The interior rows, ascending.
    pub interior: Vec<usize>,
}

/// Splits `fe`'s rows about `interface` (the first the frame node), checking the interface
/// and that `modes` interior modes exist.
pub fn partition(fe: &FeModel, interface: &[u32], modes: usize) -> Result<Partition, ReduceError> {
    let n = fe.dofs.len();
    for (i, a) in interface.iter().enumerate() {
        if interface[..i].contains(a) {
            return Err(ReduceError::Repeated(*a));
        }
    }
    let frame = six(fe, interface[0])?;
    let mut boundary = Vec::with_capacity(6 * interface.len());
    for &node in &interface[1..] {
        boundary.extend(six(fe, node)?);
    }
    let mut held = vec![false; n];
    frame.iter().chain(&boundary).for_each(|&r| held[r] = true);
    let interior: Vec<usize> = (0..n).filter(|&r| !held[r]).collect();
    if modes > interior.len() {
        return Err(ReduceError::TooManyModes {
            asked: modes,
            interior: interior.len(),
        });
    }
    Ok(Partition {
        frame,
        boundary,
        interior,
    })
}

/// The Craig–Bampton reduction of `fe` (dense `k`, `m`) about `interface` (FE nodes; the
/// first is the frame node) with `modes` fixed-interface modes.
pub fn reduce(
    fe: &FeModel,
    k: &DMatrix<f64>,
    m: &DMatrix<f64>,
    interface: &[u32],
    modes: usize,
) -> Result<Reduction, ReduceError> {
    let n = fe.dofs.len();
    if n > DENSE_MAX_DOFS {
        return Err(ReduceError::TooLarge(n));
    }
    let Partition {
        frame,
        boundary,
        interior,
    } = partition(fe, interface, modes)?;
    let nb = boundary.len();
    let mut basis = DMatrix::zeros(n, nb + modes);
    for (j, &r) in boundary.iter().enumerate() {
        basis[(r, j)] = 1.0;
    }
    let mut omega2 = Vec::with_capacity(modes);
    if !interior.is_empty() {
        let kii = sub(k, &interior, &interior);
        let chol = Cholesky::new(kii).ok_or(ReduceError::NotHeld)?;
        if nb > 0 {
            let kib = sub(k, &interior, &boundary);
            let psi = -chol.solve(&kib);
            for j in 0..nb {
                for (i, &r) in interior.iter().enumerate() {
                    basis[(r, j)] = psi[(i, j)];
                }
            }
        }
        if modes > 0 {
            let (mu, y) = interior_modes(&chol, &sub(m, &interior, &interior));
            check_kept(&mu, modes)?;
            let l = chol.l();
            for (c, (&mu_c, yc)) in mu.iter().zip(y.column_iter()).take(modes).enumerate() {
                // φ = L⁻ᵀ y / √μ: φᵀ M_II φ = 1, φᵀ K_II φ = 1/μ = ω².
                let phi = l
                    .tr_solve_lower_triangular(&yc.into_owned())
                    .unwrap_or_else(|| yc.into_owned())
                    / mu_c.sqrt();
                for (i, &r) in interior.iter().enumerate() {
                    basis[(r, nb + c)] = phi[i];
                }
                omega2.push(1.0 / mu_c);
            }
        }
    }
    let kb = &basis.transpose() * (k * &basis);
    let k_red = (&kb + kb.transpose()) * 0.5;
    Ok(Reduction {
        frame,
        boundary,
        basis,
        k: k_red,
        omega2,
    })
}

/// The `modes` largest `μ` (descending) can be kept: each has mass (`μ > 0`), and they do
/// not end inside a multiple eigenvalue ([`check_whole`]).
pub(super) fn check_kept(mu: &[f64], modes: usize) -> Result<(), ReduceError> {
    let found = mu.iter().filter(|&&x| x > 0.0).count();
    if found < modes {
        return Err(ReduceError::Massless {
            asked: modes,
            found,
        });
    }
    check_whole(mu, modes)
}

/// Relative difference of `μ` below which two fixed-interface modes are one multiple
/// eigenvalue (a symmetric section's two bending modes agree to ~1e-13).
const MULTIPLE_TOL: f64 = 1e-9;

/// Refuses a count of modes that ends inside a multiple eigenvalue (`mu` descending).
pub(super) fn check_whole(mu: &[f64], modes: usize) -> Result<(), ReduceError> {
    if modes == 0 || modes >= mu.len() {
        return Ok(());
    }
    let same = |a: f64, b: f64| (a - b).abs() <= MULTIPLE_TOL * a.abs();
    if !same(mu[modes - 1], mu[modes]) {
        return Ok(());
    }
    let mut lo = modes - 1;
    while lo > 0 && same(mu[lo - 1], mu[modes - 1]) {
        lo -= 1;
    }
    let mut hi = modes;
    while hi < mu.len() && same(mu[hi], mu[modes - 1]) {
        hi += 1;
    }
    Err(ReduceError::SplitsMultiple {
        asked: modes,
        count: hi - lo,
        hz: (1.0 / mu[modes - 1]).sqrt() / (2.0 * std::f64::consts::PI),
        below: lo,
        above: hi,
    })
}

/// The eigenpairs of `L⁻¹ M_II L⁻ᵀ` (`μ = 1/ω²`), largest first.
fn interior_modes(chol: &Cholesky<f64, Dyn>, mii: &DMatrix<f64>) -> (Vec<f64>, DMatrix<f64>) {
    let l = chol.l();
    // A = L⁻¹ M L⁻ᵀ: solve L X = M, then L Aᵀ = Xᵀ.
    let x = l.solve_lower_triangular(mii).unwrap_or_else(|| mii.clone());
    let a = l
        .solve_lower_triangular(&x.transpose())
        .unwrap_or_else(|| x.transpose());
    let a = (&a + a.transpose()) * 0.5;
    let eig = SymmetricEigen::new(a);
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
    let mu = order.iter().map(|&i| eig.eigenvalues[i]).collect();
    let y = DMatrix::from_fn(eig.eigenvectors.nrows(), order.len(), |r, c| {
        eig.eigenvectors[(r, order[c])]
    });
    (mu, y)
}

/// The lowest `count` eigenvalues `ω²` of `K x = ω² M x` restricted to the dofs `keep`
/// (dense, for the validations: `M` positive definite on them).
pub fn lowest_eigenvalues(
    k: &DMatrix<f64>,
    m: &DMatrix<f64>,
    keep: &[usize],
    count: usize,
) -> Option<Vec<f64>> {
    let (kk, mm) = (sub(k, keep, keep), sub(m, keep, keep));
    let chol = Cholesky::new(mm)?;
    let l = chol.l();
    let x = l.solve_lower_triangular(&kk)?;
    let a = l.solve_lower_triangular(&x.transpose())?;
    let a = (&a + a.transpose()) * 0.5;
    let mut w: Vec<f64> = SymmetricEigen::new(a).eigenvalues.iter().copied().collect();
    w.sort_by(f64::total_cmp);
    w.truncate(count);
    Some(w)
}
