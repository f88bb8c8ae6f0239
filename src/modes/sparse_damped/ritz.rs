//! Ritz pairs of the first-order path's Rayleigh quotient `H = VᵀTV` (a real,
//! non-symmetric matrix): its eigenvalues `μ` and the real and imaginary parts of their
//! vectors, by faer's dense eigen-decomposition.

use super::super::krylov::SparseError;
use super::super::krylov::dot;
use faer::Mat;
use nalgebra::DMatrix;

/// A Ritz pair of `H`: `μ` and the real and imaginary parts of its vector.
pub(super) struct Ritz {
    pub(super) mu: (f64, f64),
    pub(super) s: (Vec<f64>, Vec<f64>),
}

/// `a / b` in complex arithmetic.
pub(super) fn cdiv(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

/// The Ritz pairs of `h`, vectors of unit norm.
pub(super) fn ritz_pairs(h: &DMatrix<f64>) -> Result<Vec<Ritz>, SparseError> {
    let m = h.nrows();
    let a = Mat::<f64>::from_fn(m, m, |i, j| h[(i, j)]);
    let evd = a.eigen().map_err(|_| SparseError::NoConvergence {
        converged: 0,
        count: 0,
        solves: 0,
    })?;
    let s: Vec<_> = evd.S().column_vector().iter().copied().collect();
    let u = evd.U();
    Ok((0..m)
        .map(|k| {
            let re = (0..m).map(|i| u[(i, k)].re).collect::<Vec<_>>();
            let im = (0..m).map(|i| u[(i, k)].im).collect::<Vec<_>>();
            let nrm = (dot(&re, &re) + dot(&im, &im)).sqrt();
            Ritz {
                mu: (s[k].re, s[k].im),
                s: (
                    re.iter().map(|x| x / nrm).collect(),
                    im.iter().map(|x| x / nrm).collect(),
                ),
            }
        })
        .collect())
}
