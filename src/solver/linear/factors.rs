//! The simplicial factors in our own storage: loaded from faer's factorisation with
//! pivoting, refactored on kept pivots (KLU's refactorisation), solved by columns, with the
//! rows of each column grouped in runs of consecutive rows for vectorised updates.

use super::PIVOT_THRESHOLD;
#[cfg(test)]
use faer::sparse::linalg::lu::simplicial::SimplicialLu;

/// The simplicial factors `P A Q = L U` in our own storage (compressed columns, row
/// indices sorted, in pivot order): strictly lower `L` (unit diagonal implied), strictly
/// upper `U` and its diagonal, and where each entry of `A` goes.
#[derive(Default)]
pub(super) struct Factors {
    /// A factorisation with pivoting has filled the patterns.
    pub(super) valid: bool,
    pub(super) l_ptr: Vec<usize>,
    /// Row indices in 32 bits (n ≤ u32::MAX is checked where they are made): 0.1 kB per
    /// unknown less at a million unknowns than `usize`.
    pub(super) l_row: Vec<u32>,
    pub(super) l_val: Vec<f64>,
    pub(super) u_ptr: Vec<usize>,
    pub(super) u_row: Vec<u32>,
    pub(super) u_val: Vec<f64>,
    pub(super) u_diag: Vec<f64>,
    /// Row perm: `row_fwd[k]` = row of `A` pivoted at step k.
    pub(super) row_fwd: Vec<usize>,
    /// Column order `Q`: `col_fwd[j]` = column of `A` eliminated at step j.
    pub(super) col_fwd: Vec<usize>,
    /// Pivot-order row of each stored entry of `A` (32 bits: the dimension is checked
    /// against `u32::MAX` in `load`; half the memory of `usize` for nnz(A) entries).
    pub(super) a_row: Vec<u32>,
    /// Dense work vector (zero between uses).
    pub(super) work: Vec<f64>,
    /// (row, value) buffer for sorting a column.
    pub(super) sort: Vec<(usize, f64)>,
    /// Runs of consecutive rows of `L` and `U`, per column (see [`Runs`]).
    pub(super) l_runs: Runs,
    pub(super) u_runs: Runs,
}

/// The rows of a column of a triangular factor grouped in runs of consecutive rows, so
/// that the triangular solves update `y[row..row + len]` with a contiguous slice of
/// values (vectorised) instead of entry by entry with an indirect row index. Dense blocks
/// of the matrix (an element of order p couples 6(p + 1) unknowns) leave long runs in the
/// factors; the two-node beams' banded matrices short ones, so the runs are used only when
/// they are long on average ([`MIN_MEAN_RUN`]).
#[derive(Default)]
pub(super) struct Runs {
    /// Column `j`'s runs are `run[ptr[j]..ptr[j + 1]]`.
    ptr: Vec<usize>,
    /// `(first row, first value index, length)`.
    pub(super) run: Vec<(usize, usize, usize)>,
    /// Use the runs in the solves.
    pub(super) used: bool,
    simd: Simd,
}

/// Mean run length from which a factor's solves go by runs (measured: on the seed scene
/// with one element of order 8 per bar the runs of `U` average 25–30 rows and those of `L`
/// about 11; on 120 two-node beams per bar, 2–14).
const MIN_MEAN_RUN: usize = 8;

impl Runs {
    /// Builds the runs if they will be used (mean length at least [`MIN_MEAN_RUN`]); else
    /// frees them: a banded factor's runs are short and would take 24 bytes each for
    /// nothing (0.08 kB per unknown on the beam cantilever of `benches/large.sh`).
    fn build(&mut self, ptr: &[usize], row: &[u32]) {
        self.ptr.clear();
        self.run.clear();
        self.simd = Simd::detect();
        let mut count = 0;
        for j in 0..ptr.len() - 1 {
            for k in ptr[j]..ptr[j + 1] {
                if k == ptr[j] || row[k] != row[k - 1] + 1 {
                    count += 1;
                }
            }
        }
        self.used = count * MIN_MEAN_RUN <= row.len();
        if !self.used {
            self.ptr = Vec::new();
            self.run = Vec::new();
            return;
        }
        // Kept (cleared, not freed) while used: a later factorisation with pivoting (a
        // contact's restart of the accelerations) rebuilds them without allocating once
        // they are large enough (tests/alloc.rs, the contact path).
        self.ptr.reserve_exact(ptr.len());
        self.run.reserve(count);
        self.ptr.push(0);
        for j in 0..ptr.len() - 1 {
            for k in ptr[j]..ptr[j + 1] {
                match self.run.last_mut() {
                    Some((r, o, len))
                        if k > ptr[j] && row[k] as usize == *r + *len && k == *o + *len =>
                    {
                        *len += 1
                    }
                    _ => self.run.push((row[k] as usize, k, 1)),
                }
            }
            self.ptr.push(self.run.len());
        }
        debug_assert_eq!(self.run.len(), count);
    }

    /// `y[rows of column j] −= vals · yj`, run by run (compiled into each of
    /// [`Factors`]' vector variants: see [`Simd`]).
    #[inline(always)]
    fn update(&self, j: usize, vals: &[f64], y: &mut [f64], yj: f64) {
        for &(r, o, len) in &self.run[self.ptr[j]..self.ptr[j + 1]] {
            for (yi, &v) in y[r..r + len].iter_mut().zip(&vals[o..o + len]) {
                *yi -= v * yj;
            }
        }
    }
}

/// The widest vector instructions of the CPU, detected at run time: the solves and the
/// refactorisation are compiled once per set ([`Factors::solve`], [`Factors::refactor`]),
/// the runs' updates inlined into them. The same multiplications and subtractions lane by
/// lane (no fused multiply–add), so the same bits on any CPU.
#[derive(Default, Clone, Copy)]
enum Simd {
    #[default]
    Base,
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    Avx2,
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    Avx512,
}

impl Simd {
    fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                return Simd::Avx512;
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                return Simd::Avx2;
            }
        }
        Simd::Base
    }
}

impl Factors {
    /// Copies faer's factors (rows unsorted, diagonals included) into sorted storage (the
    /// reference of the tests of [`Factors::factor_pivoting`]).
    #[cfg(test)]
    pub(super) fn load(
        &mut self,
        lu: &SimplicialLu<usize, f64>,
        row_fwd: &[usize],
        row_inv: &[usize],
        col_fwd: &[usize],
        a_rows: &[usize],
    ) {
        let n = row_fwd.len();
        let (l, u) = (lu.l_factor_unsorted(), lu.u_factor_unsorted());
        // Sized exactly (faer's counts less the n diagonals of each factor), not grown by
        // doubling: at a million unknowns the spare capacity was 0.2 kB per unknown.
        let exact = |v: &mut Vec<usize>, len: usize| {
            v.clear();
            v.shrink_to(len);
            v.reserve_exact(len);
        };
        let exact_f = |v: &mut Vec<f64>, len: usize| {
            v.clear();
            v.shrink_to(len);
            v.reserve_exact(len);
        };
        let l_nnz = l.compute_nnz().saturating_sub(n);
        let u_nnz = u.compute_nnz().saturating_sub(n);
        exact(&mut self.l_ptr, n + 1);
        exact(&mut self.u_ptr, n + 1);
        self.l_row.clear();
        self.l_row.reserve_exact(l_nnz);
        self.u_row.clear();
        self.u_row.reserve_exact(u_nnz);
        exact_f(&mut self.l_val, l_nnz);
        exact_f(&mut self.u_val, u_nnz);
        exact_f(&mut self.u_diag, n);
        self.l_ptr.push(0);
        self.u_ptr.push(0);
        for j in 0..n {
            for (rows, vals, lower) in [
                (l.row_idx_of_col_raw(j), l.val_of_col(j), true),
                (u.row_idx_of_col_raw(j), u.val_of_col(j), false),
            ] {
                self.sort.clear();
                for (&r, &v) in rows.iter().zip(vals) {
                    if r == j {
                        if !lower {
                            self.u_diag.push(v);
                        }
                    } else {
                        self.sort.push((r, v));
                    }
                }
                self.sort.sort_unstable_by_key(|e| e.0);
                let (row, val, ptr) = if lower {
                    (&mut self.l_row, &mut self.l_val, &mut self.l_ptr)
                } else {
                    (&mut self.u_row, &mut self.u_val, &mut self.u_ptr)
                };
                for &(r, v) in &self.sort {
                    row.push(r as u32);
                    val.push(v);
                }
                ptr.push(row.len());
            }
        }
        self.row_fwd.clear();
        self.row_fwd.extend_from_slice(row_fwd);
        self.col_fwd.clear();
        self.col_fwd.extend_from_slice(col_fwd);
        self.a_row.clear();
        self.a_row.reserve_exact(a_rows.len());
        // `as u32` cannot truncate: `finish` requires n ≤ u32::MAX.
        self.a_row.extend(a_rows.iter().map(|&r| row_inv[r] as u32));
        self.work.clear();
        self.work.resize(n, 0.0);
        self.finish(n);
    }

    /// Checks the stored indices against `n` and sets `valid` (the unchecked indexing of
    /// `solve` and `refactor` relies on it), then groups the rows in runs.
    pub(super) fn finish(&mut self, n: usize) {
        self.valid = self.u_diag.len() == n
            && u32::try_from(n).is_ok()
            && self
                .l_row
                .iter()
                .chain(&self.u_row)
                .all(|&r| (r as usize) < n)
            && self.a_row.iter().all(|&r| (r as usize) < n);
        self.index_runs();
    }

    /// Groups the rows of `L` and `U` in runs (after a factorisation with pivoting, or a
    /// restored state: both fix the patterns).
    pub(super) fn index_runs(&mut self) {
        self.l_runs.build(&self.l_ptr, &self.l_row);
        self.u_runs.build(&self.u_ptr, &self.u_row);
    }

    /// Left-looking numeric LU of `A` (pattern `col_ptr`, values `values`) on the stored
    /// pivots and patterns: for each column j of `P A Q`, `x = L⁻¹ a_j` over the known
    /// pattern of `U(:, j)` (ascending rows are a topological order), then `u_jj = x_j`
    /// and `L(:, j) = x / u_jj`. Returns false, with the factors invalid, if a pivot fails
    /// the threshold test (or is zero or not finite).
    pub(super) fn refactor(&mut self, col_ptr: &[usize], values: &[f64]) -> bool {
        #[cfg(target_arch = "x86_64")]
        match self.l_runs.simd {
            // SAFETY: `simd` comes from the CPU's feature detection (`Simd::detect`).
            Simd::Avx512 => return unsafe { self.refactor_avx512(col_ptr, values) },
            Simd::Avx2 => return unsafe { self.refactor_avx2(col_ptr, values) },
            Simd::Base => {}
        }
        self.refactor_impl(col_ptr, values)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn refactor_avx512(&mut self, col_ptr: &[usize], values: &[f64]) -> bool {
        self.refactor_impl(col_ptr, values)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn refactor_avx2(&mut self, col_ptr: &[usize], values: &[f64]) -> bool {
        self.refactor_impl(col_ptr, values)
    }

    #[inline(always)]
    fn refactor_impl(&mut self, col_ptr: &[usize], values: &[f64]) -> bool {
        let x = &mut self.work;
        for (j, &pj) in self.col_fwd.iter().enumerate() {
            for p in col_ptr[pj]..col_ptr[pj + 1] {
                x[self.a_row[p] as usize] += values[p];
            }
            for q in self.u_ptr[j]..self.u_ptr[j + 1] {
                let k = self.u_row[q] as usize;
                let xk = std::mem::take(&mut x[k]);
                self.u_val[q] = xk;
                if self.l_runs.used {
                    self.l_runs.update(k, &self.l_val, x, xk);
                    continue;
                }
                let (a, b) = (self.l_ptr[k], self.l_ptr[k + 1]);
                for (&i, &l) in self.l_row[a..b].iter().zip(&self.l_val[a..b]) {
                    // SAFETY: `load` checked every stored row index against n = x.len().
                    unsafe { *x.get_unchecked_mut(i as usize) -= l * xk };
                }
            }
            let d = std::mem::take(&mut x[j]);
            let lower = self.l_ptr[j]..self.l_ptr[j + 1];
            let cmax = self.l_row[lower.clone()]
                .iter()
                .fold(0.0f64, |m, &i| m.max(x[i as usize].abs()));
            if !(d.is_normal() && d.abs() >= PIVOT_THRESHOLD * cmax) {
                x.iter_mut().for_each(|v| *v = 0.0);
                self.valid = false;
                return false;
            }
            self.u_diag[j] = d;
            let inv = 1.0 / d;
            for r in lower {
                let i = self.l_row[r] as usize;
                self.l_val[r] = std::mem::take(&mut x[i]) * inv;
            }
        }
        true
    }

    /// Solves `A x = b` in place: `y = P b`, `L z = y`, `U w = z`, `x = Q w`.
    pub(super) fn solve(&mut self, rhs: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        match self.l_runs.simd {
            // SAFETY: `simd` comes from the CPU's feature detection (`Simd::detect`).
            Simd::Avx512 => return unsafe { self.solve_avx512(rhs) },
            Simd::Avx2 => return unsafe { self.solve_avx2(rhs) },
            Simd::Base => {}
        }
        self.solve_impl(rhs)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn solve_avx512(&mut self, rhs: &mut [f64]) {
        self.solve_impl(rhs)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn solve_avx2(&mut self, rhs: &mut [f64]) {
        self.solve_impl(rhs)
    }

    #[inline(always)]
    fn solve_impl(&mut self, rhs: &mut [f64]) {
        let y = &mut self.work[..];
        for (yk, &r) in y.iter_mut().zip(&self.row_fwd) {
            *yk = rhs[r];
        }
        let n = y.len();
        for j in 0..n {
            let yj = y[j];
            if yj != 0.0 && self.l_runs.used {
                self.l_runs.update(j, &self.l_val, y, yj);
            } else if yj != 0.0 {
                let (a, b) = (self.l_ptr[j], self.l_ptr[j + 1]);
                for (&i, &l) in self.l_row[a..b].iter().zip(&self.l_val[a..b]) {
                    // SAFETY: `load` checked every stored row index against n = y.len().
                    unsafe { *y.get_unchecked_mut(i as usize) -= l * yj };
                }
            }
        }
        for j in (0..n).rev() {
            let yj = y[j] / self.u_diag[j];
            y[j] = yj;
            if yj != 0.0 && self.u_runs.used {
                self.u_runs.update(j, &self.u_val, y, yj);
            } else if yj != 0.0 {
                let (a, b) = (self.u_ptr[j], self.u_ptr[j + 1]);
                for (&i, &u) in self.u_row[a..b].iter().zip(&self.u_val[a..b]) {
                    // SAFETY: as above.
                    unsafe { *y.get_unchecked_mut(i as usize) -= u * yj };
                }
            }
        }
        for (yj, &c) in y.iter_mut().zip(&self.col_fwd) {
            rhs[c] = std::mem::take(yj);
        }
    }
}
