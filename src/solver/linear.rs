//! Sparse iteration matrix and its LU factorisation with faer.
//!
//! The sparsity pattern is computed once from the element connectivity; the symbolic LU
//! (fill-reducing COLAMD ordering, simplicial: see [`SparseSystem::new`]) is computed once per
//! pattern and reused by every numeric factorisation; the numeric factors, the work space
//! and the right-hand side live in buffers sized once, so a Newton iteration allocates
//! nothing once the first factorisation has sized them.
//!
//! faer's simplicial factorisation with partial pivoting (Gilbert & Peierls
//! 1988) is run once and then only when a pivot no longer passes: the next matrices are
//! *refactored* with the same row pivots and the same pattern of `L` and `U` (the
//! refactorisation of KLU: Davis & Palamadai Natarajan, ACM TOMS 37(3), 2010, §3), with the
//! threshold test of threshold partial pivoting (`|u_jj| ≥ u · max_i |l_ij u_jj|`,
//! u = [`PIVOT_THRESHOLD`]; Duff, Erisman & Reid, *Direct Methods for Sparse Matrices*,
//! §5.4) on every pivot. This skips the depth-first searches and the pivot searches; the
//! triangular solves run on the same factors, stored with sorted row indices.

use faer::sparse::SymbolicSparseColMatRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::lu::{LuSymbolicParams, SymbolicLu, factorize_symbolic_lu};

mod factors;
mod pivoting;
mod state;
use factors::Factors;
pub use state::LuState;

/// Errors of the linear solver.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum LinearError {
    /// The symbolic analysis failed (out of memory or an invalid pattern).
    #[error("symbolic factorisation failed: {0}")]
    Symbolic(String),
    /// The numeric factorisation failed (singular matrix).
    #[error("the iteration matrix is singular (numeric LU failed: {0})")]
    Singular(String),
    /// A saved state ([`LuState`]) does not fit this matrix.
    #[error("the saved LU state does not fit: {0}")]
    State(String),
}

/// Threshold `u` of the pivot test of a refactorisation: a kept pivot must be at least `u`
/// times the largest entry of its column of `L·u_jj` (1 = partial pivoting; 0.1 is the
/// usual choice for sparse LU: Duff, Erisman & Reid, §5.4; growth stays within (1 + 1/u)
/// per elimination step).
pub const PIVOT_THRESHOLD: f64 = 0.1;

/// A square sparse matrix with a fixed pattern (compressed sparse columns) and its LU.
pub struct SparseSystem {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Values, in pattern order.
    pub values: Vec<f64>,
    symbolic: SymbolicLu<usize>,
    factored: bool,
    /// Work space of the factorisation with pivoting.
    scratch: pivoting::Scratch,
    factors: Factors,
    /// Factorisations with pivoting (the others were refactorisations).
    pivoting_factorizations: u64,
}

impl SparseSystem {
    /// Builds the pattern from per-column sorted, de-duplicated row lists, and the
    /// symbolic factorisation, simplicial: it allocates nothing once its factors have
    /// grown to their fill, whereas faer 0.24's supernodal LU allocates its contribution
    /// blocks at every factorisation (~20 allocations per call on the pendulum), for a
    /// factorisation 25–35 % faster but a whole run only ~5 % faster (measured on the
    /// pendulum's matrices, 141 to 981 equations); and only the simplicial factors are
    /// refactored on kept pivots (module docs), a refactorisation ~3× cheaper than a
    /// pivoting factorisation. (faer's supernodal and automatic choices were selectable
    /// until issue 27; no run used them.)
    pub fn new(columns: &[Vec<usize>]) -> Result<Self, LinearError> {
        let n = columns.len();
        let mut col_ptr = Vec::with_capacity(n + 1);
        // Sized exactly: grown by doubling it kept up to 0.1 kB per unknown spare.
        let mut row_idx = Vec::with_capacity(columns.iter().map(Vec::len).sum());
        col_ptr.push(0);
        for col in columns {
            row_idx.extend_from_slice(col);
            col_ptr.push(row_idx.len());
        }
        let symbolic = {
            let pat = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
            let params = LuSymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
                ..Default::default()
            };
            factorize_symbolic_lu(pat, params)
                .map_err(|e| LinearError::Symbolic(format!("{e:?}")))?
        };
        let nnz = row_idx.len();
        Ok(SparseSystem {
            n,
            col_ptr,
            row_idx,
            values: vec![0.0; nnz],
            symbolic,
            factored: false,
            scratch: pivoting::Scratch::default(),
            factors: Factors::default(),
            pivoting_factorizations: 0,
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

    /// Numeric LU of the current values, reusing the symbolic factorisation: a refactorisation on the last pivots when they all pass the
    /// threshold test, else a factorisation with partial pivoting.
    pub fn factor(&mut self) -> Result<(), LinearError> {
        self.factored = false;
        if self.factors.valid && self.factors.refactor(&self.col_ptr, &self.values) {
            self.factored = true;
            return Ok(());
        }
        self.pivoting_factorizations += 1;
        let col_fwd = self.symbolic.col_perm().arrays().0;
        self.factors
            .factor_pivoting(
                &self.col_ptr,
                &self.row_idx,
                &self.values,
                col_fwd,
                &mut self.scratch,
            )
            .map_err(|e| LinearError::Singular(format!("no pivot in elimination step {}", e.0)))?;
        if !self.factors.valid {
            return Err(LinearError::Singular("incomplete factors".into()));
        }
        // The largest candidate is the pivot even when it is zero.
        if let Some(j) = self.factors.u_diag.iter().position(|d| !d.is_normal()) {
            self.factors.valid = false;
            return Err(LinearError::Singular(format!(
                "zero pivot in elimination step {j} of {}",
                self.n
            )));
        }
        self.factored = true;
        Ok(())
    }

    /// Numeric factorisations that searched for pivots (the others were refactorisations on kept pivots).
    pub fn pivoting_factorizations(&self) -> u64 {
        self.pivoting_factorizations
    }

    /// Solves `A x = b` in place (`rhs` holds `b` on entry, `x` on exit).
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<(), LinearError> {
        if !self.factored {
            return Err(LinearError::Singular("not factored".into()));
        }
        self.factors.solve(rhs);
        Ok(())
    }

    /// `y = A x` with the current values.
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        self.mul_add(&self.values, 1.0, x, y);
    }

    /// `y += s B x`, `B` the matrix of this pattern with the values `values` (in pattern
    /// order, as [`Self::values`]).
    pub fn mul_add(&self, values: &[f64], s: f64, x: &[f64], y: &mut [f64]) {
        for col in 0..self.n {
            let sx = s * x[col];
            for k in self.col_ptr[col]..self.col_ptr[col + 1] {
                y[self.row_idx[k]] += values[k] * sx;
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
        // New values, same pattern.
        s.values.iter_mut().for_each(|v| *v *= 2.0);
        s.factor().unwrap();
        let mut b = vec![0.0; 3];
        s.mul(&x, &mut b);
        s.solve(&mut b).unwrap();
        assert!((b[1] + 2.0).abs() < 1e-14);
    }

    /// Values in [−0.5, 0.5) from a linear congruential sequence seeded by `seed`.
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// A deterministic sparse unsymmetric matrix: a band of 3 plus a few far entries, with
    /// values from a linear congruential sequence seeded by `seed`.
    type Entries = Vec<(usize, usize, f64)>;

    fn banded(n: usize, seed: u64) -> (Vec<Vec<usize>>, Entries) {
        let mut next = uniform(seed);
        let mut cols = vec![Vec::new(); n];
        let mut entries = Vec::new();
        for c in 0..n {
            let mut rows: Vec<usize> = (c.saturating_sub(3)..(c + 4).min(n)).collect();
            rows.push((7 * c + 3) % n);
            rows.sort_unstable();
            rows.dedup();
            for &r in &rows {
                // Weak diagonal: pivoting has work to do.
                let v = next() + if r == c { 0.1 } else { 0.0 };
                entries.push((r, c, v));
            }
            cols[c] = rows;
        }
        (cols, entries)
    }

    fn residual_of_solve(s: &mut SparseSystem, x: &[f64]) -> f64 {
        let mut b = vec![0.0; x.len()];
        s.mul(x, &mut b);
        s.solve(&mut b).unwrap();
        b.iter()
            .zip(x)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
    }

    #[test]
    fn refactorisation_on_kept_pivots_solves_like_a_pivoting_factorisation() {
        let n = 40;
        let (cols, entries) = banded(n, 7);
        let mut s = SparseSystem::new(&cols).unwrap();
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        for (r, c, v) in &entries {
            let p = s.position(*r, *c).unwrap();
            s.values[p] = *v;
        }
        s.factor().unwrap();
        assert_eq!(s.pivoting_factorizations(), 1);
        // Condition ~1e2–1e3 here: 1e-12 is round-off times that, with margin.
        assert!(residual_of_solve(&mut s, &x) < 1e-12);
        // Small changes of every value (a Newton matrix a step later) keep the pivots:
        // refactored, and the solution is as accurate as a fresh pivoting LU's.
        for k in 1..=5 {
            for (p, v) in s.values.iter_mut().enumerate() {
                *v *= 1.0 + 1e-3 * k as f64 * ((p % 7) as f64 - 3.0);
            }
            s.factor().unwrap();
            let kept = residual_of_solve(&mut s, &x);
            let mut fresh = SparseSystem::new(&cols).unwrap();
            fresh.values.copy_from_slice(&s.values);
            fresh.factor().unwrap();
            let reference = residual_of_solve(&mut fresh, &x);
            assert!(
                kept < 1e-12 && kept <= 10.0 * reference.max(1e-15),
                "{kept:e} {reference:e}"
            );
        }
        assert_eq!(
            s.pivoting_factorizations(),
            1,
            "small changes must keep the pivots"
        );
    }

    #[test]
    fn a_pivot_that_fails_the_threshold_is_searched_again() {
        // [1 2; 3 4]: partial pivoting takes row 1 (|3| > |1|) in the first column.
        let cols = vec![vec![0, 1], vec![0, 1]];
        let mut s = SparseSystem::new(&cols).unwrap();
        let set = |s: &mut SparseSystem, m: [[f64; 2]; 2]| {
            for (r, row) in m.iter().enumerate() {
                for (c, v) in row.iter().enumerate() {
                    let p = s.position(r, c).unwrap();
                    s.values[p] = *v;
                }
            }
        };
        set(&mut s, [[1.0, 2.0], [3.0, 4.0]]);
        s.factor().unwrap();
        assert!(residual_of_solve(&mut s, &[1.0, -1.0]) < 1e-15);
        // Now row 1's entry is 1e-3 of row 0's: the kept pivot fails u = 0.1.
        set(&mut s, [[5.0, 2.0], [5e-3, 4.0]]);
        s.factor().unwrap();
        assert_eq!(s.pivoting_factorizations(), 2);
        assert!(residual_of_solve(&mut s, &[1.0, -1.0]) < 1e-15);
        // A kept pivot at 0.2 of its column passes and is refactored.
        set(&mut s, [[1.0, 2.0], [5.0, 4.0]]);
        s.factor().unwrap();
        assert_eq!(s.pivoting_factorizations(), 2);
        assert!(residual_of_solve(&mut s, &[1.0, -1.0]) < 1e-14);
        // A singular matrix is reported, not solved.
        set(&mut s, [[1.0, 2.0], [2.0, 4.0]]);
        assert!(matches!(s.factor(), Err(LinearError::Singular(_))));
        assert!(s.solve(&mut [1.0, 1.0]).is_err());
    }

    #[test]
    fn solves_by_runs_of_rows_give_the_bits_of_solves_entry_by_entry() {
        // A dense 40×40 block with a sparse border (an element of order p couples 6(p + 1)
        // unknowns; the joints' few equations come last): the factors have long runs of
        // consecutive rows, which the solves and refactorisations then use; switching the
        // runs off must change no bit.
        let (n, b) = (48, 40);
        let mut next = uniform(7);
        let mut cols = vec![Vec::new(); n];
        let mut entries = Vec::new();
        for c in 0..n {
            let mut rows: Vec<usize> = if c < b {
                (0..b).chain([b + c % (n - b)]).collect()
            } else {
                vec![c - b, c]
            };
            if c >= b {
                rows.extend((0..b).filter(|r| r % (n - b) == c - b));
            }
            rows.sort_unstable();
            rows.dedup();
            for &r in &rows {
                entries.push((r, c, next() + if r == c { 4.0 } else { 0.0 }));
            }
            cols[c] = rows;
        }
        let mut s = SparseSystem::new(&cols).unwrap();
        for &(r, c, v) in &entries {
            let p = s.position(r, c).unwrap();
            s.values[p] = v;
        }
        s.factor().unwrap();
        assert!(
            s.factors.l_runs.used && s.factors.u_runs.used,
            "long runs expected"
        );
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let solve = |s: &mut SparseSystem| {
            let mut rhs = vec![0.0; n];
            s.mul(&x, &mut rhs);
            s.solve(&mut rhs).unwrap();
            rhs
        };
        let by_runs = solve(&mut s);
        let err = by_runs
            .iter()
            .zip(&x)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(err < 1e-12, "solution error {err}");
        // A refactorisation on the kept pivots (new values, same pattern), by runs.
        s.values.iter_mut().for_each(|v| *v *= 1.5);
        s.factor().unwrap();
        let refactored_by_runs = solve(&mut s);
        // The same two factorisations and solves entry by entry.
        let mut t = SparseSystem::new(&cols).unwrap();
        for &(r, c, v) in &entries {
            let p = t.position(r, c).unwrap();
            t.values[p] = v;
        }
        t.factor().unwrap();
        t.factors.l_runs.used = false;
        t.factors.u_runs.used = false;
        assert_eq!(solve(&mut t), by_runs);
        t.values.iter_mut().for_each(|v| *v *= 1.5);
        t.factor().unwrap();
        t.factors.l_runs.used = false;
        t.factors.u_runs.used = false;
        assert_eq!(solve(&mut t), refactored_by_runs);
    }

    /// Our factorisation with pivoting ([`Factors::factor_pivoting`], a port of faer's) gives
    /// faer's pivots and values bit for bit: compared with faer's factors copied into the
    /// same sorted storage ([`Factors::load`]), on matrices with and without pivoting work.
    #[test]
    fn the_pivoting_factorisation_is_faers_bit_for_bit() {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::sparse::SparseColMatRef;
        use faer::sparse::linalg::lu::simplicial::{
            SimplicialLu, factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch,
        };
        for (n, seed) in [(3, 1), (40, 7), (200, 3), (1000, 11)] {
            let (cols, entries) = banded(n, seed);
            let mut s = SparseSystem::new(&cols).unwrap();
            for (r, c, v) in &entries {
                let p = s.position(*r, *c).unwrap();
                s.values[p] = *v;
            }
            s.factor().unwrap();
            let (mut fwd, mut inv, mut lu) = (vec![0; n], vec![0; n], SimplicialLu::new());
            let mut mem =
                MemBuffer::new(factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n));
            let pat = SymbolicSparseColMatRef::new_checked(n, n, &s.col_ptr, None, &s.row_idx);
            factorize_simplicial_numeric_lu(
                &mut fwd,
                &mut inv,
                &mut lu,
                SparseColMatRef::new(pat, &s.values),
                s.symbolic.col_perm(),
                MemStack::new(&mut mem),
            )
            .unwrap();
            let mut f = Factors::default();
            let col_fwd = s.symbolic.col_perm().arrays().0;
            f.load(&lu, &fwd, &inv, col_fwd, &s.row_idx);
            let o = &s.factors;
            assert!(f.valid && o.valid);
            assert_eq!(f.row_fwd, o.row_fwd, "n = {n}: pivots");
            assert_eq!((&f.l_ptr, &f.l_row), (&o.l_ptr, &o.l_row));
            assert_eq!((&f.u_ptr, &f.u_row), (&o.u_ptr, &o.u_row));
            assert_eq!(f.a_row, o.a_row);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&f.l_val), bits(&o.l_val), "n = {n}: L");
            assert_eq!(bits(&f.u_val), bits(&o.u_val), "n = {n}: U");
            assert_eq!(bits(&f.u_diag), bits(&o.u_diag), "n = {n}: diagonal of U");
        }
    }
}
