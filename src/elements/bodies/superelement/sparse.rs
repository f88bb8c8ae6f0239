//! The Hurty–Craig–Bampton reduction of [`super::reduce`], sparse end to end: `K` and `M`
//! stay the reader's lower triangles ([`SymMatrix`]), `K_II` is factored once by faer's
//! sparse Cholesky (`K_II = L Lᵀ`, AMD-ordered, supernodal), the static constraint modes
//! `Ψ = −K_II⁻¹ K_IB` are its solves, and the fixed-interface modes are the largest
//! `θ = 1/ω²` of `T = K_II⁻¹ M_II` by the project's block Lanczos ([`crate::lanczos`],
//! the shift-invert eigen-solver of `modes::sparse`, here at the shift `σ = 0`: `K_II` is
//! positive definite when the interface holds the body). Cholesky rather than the
//! project's LU: `K_II` is symmetric positive definite, the factorisation is half the
//! work, and its failure (a non-positive pivot) *is* the test that the interface holds
//! the body — the LU would factor an indefinite `K_II` silently.
//!
//! The Lanczos vectors are `M_II`-orthonormal (`φᵀM_IIφ = 1`, as the dense path's) and
//! converged to `‖Tφ − θφ‖_M ≤ TOL θ` ([`crate::lanczos::TOL`] = 1e-9), so `ω² = 1/θ` is
//! exact to ~1e-9 relative (the residual bounds the eigenvalue's error inside a cluster,
//! its square over the gap outside). [`crate::lanczos::BLOCK`] more modes than kept are
//! computed, so that a kept count ending inside a multiple eigenvalue is refused as on the
//! dense path ([`super::reduce::check_whole`]; the counts it names are exact for a
//! multiplicity up to that block).

use super::fe::FeModel;
use super::mtx::SymMatrix;
use super::reduce::{Partition, ReduceError, Reduction, check_kept, partition};
use crate::lanczos::{self, LanczosError, ShiftInvert};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::LltError;
use faer::sparse::linalg::solvers::Llt;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use nalgebra::DMatrix;

impl From<LanczosError> for ReduceError {
    fn from(e: LanczosError) -> Self {
        match e {
            LanczosError::Massless => ReduceError::Massless { asked: 1, found: 0 },
            LanczosError::NoConvergence {
                converged,
                count,
                solves,
            } => ReduceError::NoConvergence {
                converged,
                count,
                solves,
            },
        }
    }
}

/// `y = A x` for a symmetric `A` given by its lower-triangle entries.
pub fn sym_mul(entries: &[(usize, usize, f64)], x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    for &(i, j, v) in entries {
        y[i] += v * x[j];
        if i != j {
            y[j] += v * x[i];
        }
    }
}

/// `A X` for a symmetric sparse `A` (lower triangle) and a dense `X`.
pub fn sym_mul_dense(a: &SymMatrix, x: &DMatrix<f64>) -> DMatrix<f64> {
    let mut y = DMatrix::zeros(a.n, x.ncols());
    for c in 0..x.ncols() {
        let xc = x.column(c);
        let mut yc = y.column_mut(c);
        for &(i, j, v) in &a.entries {
            yc[i] += v * xc[j];
            if i != j {
                yc[j] += v * xc[i];
            }
        }
    }
    y
}

/// `T = K_II⁻¹ M_II` through the Cholesky factors.
struct Interior {
    llt: Llt<usize, f64>,
    m: Vec<(usize, usize, f64)>,
    n: usize,
    solves: usize,
}

impl ShiftInvert for Interior {
    type Error = ReduceError;
    fn dim(&self) -> usize {
        self.n
    }
    fn free(&self) -> usize {
        self.n
    }
    fn mass(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.n];
        sym_mul(&self.m, x, &mut y);
        y
    }
    fn apply_mass(&mut self, mv: &[f64]) -> Result<Vec<f64>, ReduceError> {
        let mut rhs = Mat::from_fn(self.n, 1, |i, _| mv[i]);
        self.llt.solve_in_place(rhs.as_mut());
        self.solves += 1;
        Ok((0..self.n).map(|i| rhs[(i, 0)]).collect())
    }
    fn solves(&self) -> usize {
        self.solves
    }
}

/// Sparse Cholesky of `a` (lower-triangle triplets, duplicates summed) of size `n`:
/// a non-positive pivot is [`ReduceError::NotHeld`].
pub fn cholesky(n: usize, a: &[(usize, usize, f64)]) -> Result<Llt<usize, f64>, ReduceError> {
    let trip: Vec<Triplet<usize, usize, f64>> =
        a.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
    let mat = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &trip)
        .map_err(|e| ReduceError::Sparse(format!("{e:?}")))?;
    mat.sp_cholesky(Side::Lower).map_err(|e| match e {
        LltError::Numeric(_) => ReduceError::NotHeld,
        LltError::Generic(g) => ReduceError::Sparse(format!("{g:?}")),
    })
}

/// The blocks of `fe`'s matrices the reduction needs, sparse.
pub struct Blocks {
    /// `K_II`, lower triangle, interior numbering.
    pub kii: Vec<(usize, usize, f64)>,
    /// `M_II`, lower triangle, interior numbering.
    pub mii: Vec<(usize, usize, f64)>,
    /// `K_IB` dense (interior × boundary: a few columns).
    pub kib: Mat<f64>,
}

/// Splits `K`, `M` into the interior and interior–boundary blocks.
pub fn blocks(fe: &FeModel, p: &Partition) -> Blocks {
    let n = fe.dofs.len();
    let (mut ii, mut bi) = (vec![usize::MAX; n], vec![usize::MAX; n]);
    p.interior.iter().enumerate().for_each(|(a, &r)| ii[r] = a);
    p.boundary.iter().enumerate().for_each(|(a, &r)| bi[r] = a);
    let inner = |e: &[(usize, usize, f64)]| -> Vec<(usize, usize, f64)> {
        e.iter()
            .filter(|&&(i, j, _)| ii[i] != usize::MAX && ii[j] != usize::MAX)
            .map(|&(i, j, v)| {
                let (a, b) = (ii[i], ii[j]);
                (a.max(b), a.min(b), v)
            })
            .collect()
    };
    let mut kib = Mat::zeros(p.interior.len(), p.boundary.len());
    for &(i, j, v) in &fe.k.entries {
        if ii[i] != usize::MAX && bi[j] != usize::MAX {
            kib[(ii[i], bi[j])] += v;
        } else if ii[j] != usize::MAX && bi[i] != usize::MAX {
            kib[(ii[j], bi[i])] += v;
        }
    }
    Blocks {
        kii: inner(&fe.k.entries),
        mii: inner(&fe.m.entries),
        kib,
    }
}

/// The Craig–Bampton reduction of `fe` about `interface` (the first the frame node) with
/// `modes` fixed-interface modes, sparse (module docs): the same basis as
/// [`super::reduce::reduce`] up to the signs of the modes.
pub fn reduce(fe: &FeModel, interface: &[u32], modes: usize) -> Result<Reduction, ReduceError> {
    let p = partition(fe, interface, modes)?;
    let n = fe.dofs.len();
    let (ni, nb) = (p.interior.len(), p.boundary.len());
    let mut basis = DMatrix::zeros(n, nb + modes);
    for (j, &r) in p.boundary.iter().enumerate() {
        basis[(r, j)] = 1.0;
    }
    let mut omega2 = Vec::with_capacity(modes);
    if ni > 0 {
        let Blocks { kii, mii, mut kib } = blocks(fe, &p);
        let llt = cholesky(ni, &kii)?;
        if nb > 0 {
            llt.solve_in_place(kib.as_mut());
            for j in 0..nb {
                for (i, &r) in p.interior.iter().enumerate() {
                    basis[(r, j)] = -kib[(i, j)];
                }
            }
        }
        if modes > 0 {
            let count = (modes + lanczos::BLOCK).min(ni);
            let mut op = Interior {
                llt,
                m: mii,
                n: ni,
                solves: 0,
            };
            let (theta, vecs) = lanczos::largest(&mut op, count)?;
            let mut order: Vec<usize> = (0..theta.len()).collect();
            order.sort_by(|&a, &b| theta[b].total_cmp(&theta[a]));
            let mu: Vec<f64> = order.iter().map(|&i| theta[i]).collect();
            check_kept(&mu, modes)?;
            for (c, &o) in order.iter().take(modes).enumerate() {
                for (i, &r) in p.interior.iter().enumerate() {
                    basis[(r, nb + c)] = vecs[o][i];
                }
                omega2.push(1.0 / theta[o]);
            }
        }
    }
    let kb = basis.transpose() * sym_mul_dense(&fe.k, &basis);
    let k_red = (&kb + kb.transpose()) * 0.5;
    Ok(Reduction {
        frame: p.frame,
        boundary: p.boundary,
        basis,
        k: k_red,
        omega2,
    })
}
