//! Sparse iteration matrix and its LU factorisation with faer.
//!
//! The sparsity pattern is computed once from the element connectivity; the symbolic LU
//! (fill-reducing COLAMD ordering, simplicial by default, see [`LuStrategy`]) is computed once per
//! pattern and reused by every numeric factorisation; the numeric factors, the work space
//! and the right-hand side live in buffers sized once, so a Newton iteration allocates
//! nothing once the first factorisation has sized them.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::lu::{LuSymbolicParams, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

/// Errors of the linear solver.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum LinearError {
    /// The symbolic analysis failed (out of memory or an invalid pattern).
    #[error("symbolic factorisation failed: {0}")]
    Symbolic(String),
    /// The numeric factorisation failed (singular matrix).
    #[error("the iteration matrix is singular (numeric LU failed: {0})")]
    Singular(String),
}

/// Which sparse LU faer runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum LuStrategy {
    /// faer's choice from the estimated flops per nonzero.
    #[default]
    Auto,
    /// Left-looking simplicial LU (Gilbert–Peierls).
    Simplicial,
    /// Supernodal LU (dense blocks): on the pendulum's matrices (141 to 981 equations) its
    /// numeric factorisation took 25–35 % less time than the simplicial one, but it
    /// allocates at every call.
    Supernodal,
}

/// A square sparse matrix with a fixed pattern (compressed sparse columns) and its LU.
pub struct SparseSystem {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Values, in pattern order.
    pub values: Vec<f64>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    factor_mem: MemBuffer,
    solve_mem: MemBuffer,
    factored: bool,
}

impl SparseSystem {
    /// Builds the pattern from per-column sorted, de-duplicated row lists, and the
    /// symbolic factorisation, simplicial: it allocates nothing once its factors have
    /// grown to their fill, whereas faer 0.24's supernodal LU allocates its contribution
    /// blocks at every factorisation (~20 allocations per call on the pendulum), for a
    /// factorisation 25–35 % faster but a whole run only ~5 % faster (see [`LuStrategy`]).
    pub fn new(columns: &[Vec<usize>]) -> Result<Self, LinearError> {
        Self::with_strategy(columns, LuStrategy::Simplicial)
    }

    /// As [`SparseSystem::new`], with the choice of factorisation.
    pub fn with_strategy(
        columns: &[Vec<usize>],
        strategy: LuStrategy,
    ) -> Result<Self, LinearError> {
        let n = columns.len();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for col in columns {
            row_idx.extend_from_slice(col);
            col_ptr.push(row_idx.len());
        }
        let symbolic = {
            let pat = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
            let params = LuSymbolicParams {
                supernodal_flop_ratio_threshold: match strategy {
                    LuStrategy::Auto => SupernodalThreshold::AUTO,
                    LuStrategy::Simplicial => SupernodalThreshold::FORCE_SIMPLICIAL,
                    LuStrategy::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
                },
                ..Default::default()
            };
            factorize_symbolic_lu(pat, params)
                .map_err(|e| LinearError::Symbolic(format!("{e:?}")))?
        };
        let factor_mem = MemBuffer::try_new(
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
        )
        .map_err(|e| LinearError::Symbolic(format!("{e:?}")))?;
        let solve_mem = MemBuffer::try_new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq))
            .map_err(|e| LinearError::Symbolic(format!("{e:?}")))?;
        let nnz = row_idx.len();
        Ok(SparseSystem {
            n,
            col_ptr,
            row_idx,
            values: vec![0.0; nnz],
            symbolic,
            numeric: NumericLu::new(),
            factor_mem,
            solve_mem,
            factored: false,
        })
    }

    /// The pattern as per-column row lists (as given to [`SparseSystem::new`]).
    pub fn columns(&self) -> Vec<Vec<usize>> {
        (0..self.n)
            .map(|c| self.row_idx[self.position_range(c)].to_vec())
            .collect()
    }

    /// Dimension.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Position of entry `(row, col)` in [`SparseSystem::values`], if in the pattern.
    pub fn position(&self, row: usize, col: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        self.row_idx[a..b].binary_search(&row).ok().map(|k| a + k)
    }

    /// Range of positions of column `col` in [`SparseSystem::values`].
    pub fn position_range(&self, col: usize) -> std::ops::Range<usize> {
        self.col_ptr[col]..self.col_ptr[col + 1]
    }

    /// Row of the entry stored at position `p`.
    pub fn row_of(&self, p: usize) -> usize {
        self.row_idx[p]
    }

    /// Sets every value to zero (keeps the pattern).
    pub fn clear(&mut self) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
    }

    /// Numeric LU of the current values, reusing the symbolic factorisation.
    pub fn factor(&mut self) -> Result<(), LinearError> {
        self.factored = false;
        let pat = SymbolicSparseColMatRef::new_checked(
            self.n,
            self.n,
            &self.col_ptr,
            None,
            &self.row_idx,
        );
        let mat = SparseColMatRef::new(pat, &self.values);
        self.symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                mat,
                Par::Seq,
                MemStack::new(&mut self.factor_mem),
                Default::default(),
            )
            .map_err(|e| LinearError::Singular(format!("{e:?}")))?;
        self.factored = true;
        Ok(())
    }

    /// Solves `A x = b` in place (`rhs` holds `b` on entry, `x` on exit).
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<(), LinearError> {
        if !self.factored {
            return Err(LinearError::Singular("not factored".into()));
        }
        let lu = faer::sparse::linalg::lu::LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let m = MatMut::from_column_major_slice_mut(rhs, self.n, 1);
        lu.solve_in_place_with_conj(Conj::No, m, Par::Seq, MemStack::new(&mut self.solve_mem));
        Ok(())
    }

    /// `y = A x` with the current values.
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for col in 0..self.n {
            for k in self.col_ptr[col]..self.col_ptr[col + 1] {
                y[self.row_idx[k]] += self.values[k] * x[col];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_small_unsymmetric_system_twice_with_one_symbolic_factorisation() {
        // [4 1 0; 2 5 1; 0 3 6]
        let cols = vec![vec![0, 1], vec![0, 1, 2], vec![1, 2]];
        let mut s = SparseSystem::new(&cols).unwrap();
        for (r, c, v) in [
            (0, 0, 4.0),
            (1, 0, 2.0),
            (0, 1, 1.0),
            (1, 1, 5.0),
            (2, 1, 3.0),
            (1, 2, 1.0),
            (2, 2, 6.0),
        ] {
            let p = s.position(r, c).unwrap();
            s.values[p] = v;
        }
        s.factor().unwrap();
        let x = [1.0, -2.0, 0.5];
        let mut b = vec![0.0; 3];
        s.mul(&x, &mut b);
        s.solve(&mut b).unwrap();
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
        // The other factorisations give the same solution.
        for st in [LuStrategy::Auto, LuStrategy::Simplicial] {
            let mut t = SparseSystem::with_strategy(&s.columns(), st).unwrap();
            t.values.copy_from_slice(&s.values);
            t.factor().unwrap();
            let mut c = vec![0.0; 3];
            t.mul(&x, &mut c);
            t.solve(&mut c).unwrap();
            assert!(c.iter().zip(&x).all(|(a, b)| (a - b).abs() < 1e-14));
        }
        // New values, same pattern.
        s.values.iter_mut().for_each(|v| *v *= 2.0);
        s.factor().unwrap();
        let mut b = vec![0.0; 3];
        s.mul(&x, &mut b);
        s.solve(&mut b).unwrap();
        assert!((b[1] + 2.0).abs() < 1e-14);
    }
}
