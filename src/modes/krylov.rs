//! The Krylov solvers' kernels, shared by the symmetric ([`super::sparse`]) and the
//! first-order ([`super::sparse_damped`]) paths: vector products that vectorise, products
//! over the iteration matrix's pattern, an `M`-orthonormal basis by two passes of
//! Gram–Schmidt (Parlett, *The Symmetric Eigenvalue Problem*, §6.9: "twice is enough"),
//! and their errors ([`SparseError`]; so that neither path imports the other's module).

use crate::solver::linear::{LinearError, SparseSystem};

/// A vector whose norm (in the basis's inner product: `M` for the symmetric path, a scaled
/// Euclidean one for the first-order path) falls below this fraction of its norm before
/// projection is linearly dependent on the basis (after two Gram–Schmidt passes,
/// round-off leaves ~ε).
pub(super) const DROP: f64 = 1e-10;

/// `aᵀb` with eight partial sums (a sequential sum does not vectorise: the
/// orthogonalisation, bound by these products, ran at a quarter of the speed).
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for ((s, x), y) in acc.iter_mut().zip(x).zip(y) {
            *s += x * y;
        }
    }
    acc.iter().sum::<f64>() + tail
}

/// `y += a x`.
pub(super) fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    y.iter_mut().zip(x).for_each(|(y, x)| *y += a * x);
}

/// An `M`-orthonormal basis with the mass images of its vectors.
#[derive(Default)]
pub(super) struct Basis {
    pub(super) q: Vec<Vec<f64>>,
    pub(super) mq: Vec<Vec<f64>>,
}

impl Basis {
    /// Projects `w` on the basis twice (Gram–Schmidt), returning the summed coefficients;
    /// `mw`, when given, is `M w` and is kept so (`M q` is stored: no product).
    pub(super) fn project(&self, w: &mut [f64], mut mw: Option<&mut [f64]>) -> Vec<f64> {
        let mut coef = vec![0.0; self.q.len()];
        for _ in 0..2 {
            for (i, (q, mq)) in self.q.iter().zip(&self.mq).enumerate() {
                let c = dot(mq, w);
                axpy(w, -c, q);
                if let Some(mw) = mw.as_deref_mut() {
                    axpy(mw, -c, mq);
                }
                coef[i] += c;
            }
        }
        coef
    }

    /// `M`-orthonormalises `ws` (each with its mass image `M w`) against the basis and
    /// each other, appending those that are independent; returns how many were appended.
    pub(super) fn extend(&mut self, ws: Vec<(Vec<f64>, Vec<f64>)>) -> usize {
        let mut added = 0;
        for (mut w, mut mw) in ws {
            let n0 = dot(&mw, &w).max(0.0).sqrt();
            self.project(&mut w, Some(&mut mw));
            let n1 = dot(&mw, &w).max(0.0).sqrt();
            if n1 <= DROP * n0 || n1 == 0.0 {
                continue;
            }
            w.iter_mut().for_each(|v| *v /= n1);
            self.mq.push(mw.into_iter().map(|v| v / n1).collect());
            self.q.push(w);
            added += 1;
        }
        added
    }

    /// `Σ_j s_j q_j` over the basis.
    pub(super) fn combine(vs: &[Vec<f64>], s: impl Iterator<Item = f64>, n: usize) -> Vec<f64> {
        let mut y = vec![0.0; n];
        for (v, sj) in vs.iter().zip(s) {
            if sj != 0.0 {
                axpy(&mut y, sj, v);
            }
        }
        y
    }
}

/// `y = A x` over the pattern of `mat` with values `a`, rows and columns below `rows`,
/// `cols` (`y` has `rows` entries).
pub(super) fn pattern_mul(
    mat: &SparseSystem,
    a: &[f64],
    x: &[f64],
    y: &mut [f64],
    rows: usize,
    abs: bool,
) {
    y.iter_mut().for_each(|v| *v = 0.0);
    for (col, xc) in x.iter().enumerate() {
        if *xc == 0.0 {
            continue;
        }
        for p in mat.position_range(col) {
            let r = mat.row_of(p);
            if r < rows {
                y[r] += if abs {
                    a[p].abs() * xc.abs()
                } else {
                    a[p] * xc
                };
            }
        }
    }
}

/// The Euclidean norm.
pub(super) fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// Why the sparse solve did not give modes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SparseError {
    /// The model at this state is damped, gyroscopic or non-symmetric.
    #[error(
        "the sparse solver handles conservative undamped models: at this state the reduced stiffness is asymmetric to {asymmetry:.1e} and the damping/gyroscopic matrix is {damping:.1e} of it"
    )]
    NotConservative {
        /// Relative asymmetry of `QᵀKQ`.
        asymmetry: f64,
        /// `max|QᵀCQ| / √max|QᵀKQ|`.
        damping: f64,
    },
    /// `A(σ)` is singular (redundant constraints, or a free direction with no mass).
    #[error(
        "the shifted saddle-point matrix [K - sM, B'; B, 0] is singular ({0}): redundant constraints?"
    )]
    Singular(String),
    /// No mass on the free unknowns.
    #[error("no mass on any free degree of freedom")]
    Massless,
    /// The iteration did not converge within its budget of solves.
    #[error("shift-invert Lanczos: {converged} of {count} modes converged after {solves} solves")]
    NoConvergence {
        /// Converged modes.
        converged: usize,
        /// Asked for.
        count: usize,
        /// Solves spent.
        solves: usize,
    },
}

impl From<LinearError> for SparseError {
    fn from(e: LinearError) -> Self {
        SparseError::Singular(e.to_string())
    }
}
