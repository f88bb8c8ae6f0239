//! The Krylov solvers' kernels, shared by the symmetric ([`super::sparse`]) and the
//! first-order ([`super::sparse_damped`]) paths: vector products that vectorise, products
//! over the iteration matrix's pattern, an `M`-orthonormal basis by two passes of
//! Gram–Schmidt (Parlett, *The Symmetric Eigenvalue Problem*, §6.9: "twice is enough"),
//! and their errors ([`SparseError`]; so that neither path imports the other's module).

use crate::solver::linear::{LinearError, SparseSystem};

pub(super) use crate::lanczos::{DROP, axpy, dot};

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

impl From<crate::lanczos::LanczosError> for SparseError {
    fn from(e: crate::lanczos::LanczosError) -> Self {
        match e {
            crate::lanczos::LanczosError::Massless => SparseError::Massless,
            crate::lanczos::LanczosError::NoConvergence {
                converged,
                count,
                solves,
            } => SparseError::NoConvergence {
                converged,
                count,
                solves,
            },
        }
    }
}

impl From<LinearError> for SparseError {
    fn from(e: LinearError) -> Self {
        SparseError::Singular(e.to_string())
    }
}
