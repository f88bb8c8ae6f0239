//! The factorisation with partial pivoting, written straight into our storage.
//!
//! Gilbert & Peierls' left-looking LU (SIAM J. Sci. Stat. Comput. 9(5), 1988): for each
//! column j of `A Q`, the rows reached from its pattern through the graph of `L` (a
//! depth-first search) in topological order, the sparse solve `x = L⁻¹ a_j` over them, the
//! pivot = the largest `|x_i|` among the rows not yet pivoted, `L(:, j) = x / x_piv`.
//! This is faer 0.24.4's `factorize_simplicial_numeric_lu` (MIT licence,
//! `src/sparse/linalg/lu.rs`), operation for operation: the same search order, the same
//! sums in the same order, the same pivot choice (`partial_cmp`, ties to the first), the
//! same multiplication by the reciprocal of the pivot, hence the same pivots and the same
//! bits (`tests::the_pivoting_factorisation_is_faers_bit_for_bit`). Ported so that faer's
//! copy of the factors never exists beside ours: the two copies were 0.5 kB per unknown
//! of the peak memory of a million-unknown run (docs/large.md).

use super::factors::Factors;

/// Work space of the factorisation (`n` each; sized at the first factorisation).
#[derive(Default)]
pub(super) struct Scratch {
    marked: Vec<usize>,
    xj: Vec<usize>,
    stack: Vec<usize>,
    row_inv: Vec<usize>,
}

/// The factorisation failed: no candidate pivot in an elimination step (structurally
/// singular).
pub(super) struct NoPivot(pub(super) usize);

impl Factors {
    /// `P A Q = L U` with partial pivoting (module docs) of `A` (compressed columns
    /// `col_ptr`, `row_idx`, `values`), `col_fwd` = the fill-reducing column order `Q`.
    /// Fills the sorted storage as [`Factors::load`] did from faer's factors.
    pub(super) fn factor_pivoting(
        &mut self,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
        col_fwd: &[usize],
        s: &mut Scratch,
    ) -> Result<(), NoPivot> {
        let n = col_fwd.len();
        self.valid = false;
        // Row indices are stored in 32 bits.
        if u32::try_from(n).is_err() {
            return Err(NoPivot(0));
        }
        for v in [&mut s.marked, &mut s.xj, &mut s.stack] {
            v.clear();
            v.resize(n, 0);
        }
        s.row_inv.clear();
        s.row_inv.resize(n, n);
        self.work.clear();
        self.work.resize(n, 0.0);
        for v in [&mut self.l_ptr, &mut self.u_ptr] {
            v.clear();
            v.push(0);
        }
        self.l_row.clear();
        self.l_val.clear();
        self.u_row.clear();
        self.u_val.clear();
        self.u_diag.clear();
        let x = &mut self.work;
        let row_inv = &mut s.row_inv;
        for (j, &pj) in col_fwd.iter().enumerate() {
            // `L` is kept strictly lower with the rows of `A` (not yet pivot rows) in
            // faer's order; faer also stores the unit diagonal first in each column, which
            // its search meets already marked and its solve skips.
            let mark = j + 1;
            let bi = &row_idx[col_ptr[pj]..col_ptr[pj + 1]];
            let mut tail = n;
            for &b in bi {
                if s.marked[b] < mark {
                    tail = dfs(
                        &mut s.marked,
                        mark,
                        &mut s.xj[..tail],
                        &self.l_ptr,
                        &self.l_row,
                        row_inv,
                        b,
                        &mut s.stack,
                    );
                }
            }
            for (&i, &b) in bi.iter().zip(&values[col_ptr[pj]..col_ptr[pj + 1]]) {
                x[i] += b;
            }
            for &i in &s.xj[tail..] {
                let pi = row_inv[i];
                if pi >= j {
                    continue;
                }
                let xi = x[i];
                for p in self.l_ptr[pi]..self.l_ptr[pi + 1] {
                    x[self.l_row[p] as usize] -= self.l_val[p] * xi;
                }
            }
            let mut pivot = n;
            let mut pivot_abs = -1.0f64;
            let u_start = self.u_row.len();
            for &i in &s.xj[tail..] {
                if row_inv[i] == n {
                    let a = x[i].abs();
                    if matches!(
                        a.partial_cmp(&pivot_abs),
                        None | Some(std::cmp::Ordering::Greater)
                    ) {
                        pivot = i;
                        pivot_abs = a;
                    }
                } else {
                    self.u_row.push(row_inv[i] as u32);
                    self.u_val.push(x[i]);
                }
            }
            if pivot == n {
                for &i in &s.xj[tail..] {
                    x[i] = 0.0;
                }
                return Err(NoPivot(j));
            }
            let x_piv = x[pivot];
            let inv = x_piv.recip();
            row_inv[pivot] = j;
            self.u_diag.push(x_piv);
            sort_column(
                &mut self.u_row[u_start..],
                &mut self.u_val[u_start..],
                &mut self.sort,
            );
            self.u_ptr.push(self.u_row.len());
            for &i in &s.xj[tail..] {
                if row_inv[i] == n {
                    self.l_row.push(i as u32);
                    self.l_val.push(x[i] * inv);
                }
                x[i] = 0.0;
            }
            self.l_ptr.push(self.l_row.len());
        }
        // Rows of `L` to pivot order, sorted in each column.
        for r in &mut self.l_row {
            *r = row_inv[*r as usize] as u32;
        }
        for j in 0..n {
            let (a, b) = (self.l_ptr[j], self.l_ptr[j + 1]);
            sort_column(&mut self.l_row[a..b], &mut self.l_val[a..b], &mut self.sort);
        }
        self.row_fwd.clear();
        self.row_fwd.resize(n, 0);
        for (i, &p) in row_inv.iter().enumerate() {
            self.row_fwd[p] = i;
        }
        self.col_fwd.clear();
        self.col_fwd.extend_from_slice(col_fwd);
        self.a_row.clear();
        self.a_row.reserve_exact(row_idx.len());
        // `as u32` cannot truncate: n ≤ u32::MAX was checked at the start.
        self.a_row
            .extend(row_idx.iter().map(|&r| row_inv[r] as u32));
        self.finish(n);
        Ok(())
    }
}

/// Sorts one column's `(row, value)` pairs by row.
fn sort_column(rows: &mut [u32], vals: &mut [f64], buf: &mut Vec<(usize, f64)>) {
    buf.clear();
    buf.extend(rows.iter().map(|&r| r as usize).zip(vals.iter().copied()));
    buf.sort_unstable_by_key(|e| e.0);
    for ((r, v), &(br, bv)) in rows.iter_mut().zip(vals.iter_mut()).zip(buf.iter()) {
        *r = br as u32;
        *v = bv;
    }
}

/// faer's `depth_first_search`: the rows reached from row `b` through the columns of `L`
/// of the rows already pivoted, pushed in reverse topological order at the tail of `xi`;
/// returns the new start of the tail.
#[allow(clippy::too_many_arguments)]
fn dfs(
    marked: &mut [usize],
    mark: usize,
    xi: &mut [usize],
    l_ptr: &[usize],
    l_row: &[u32],
    row_inv: &[usize],
    b: usize,
    stack: &mut [usize],
) -> usize {
    let ncols = l_ptr.len() - 1;
    let mut tail = xi.len();
    let mut head = 1usize;
    xi[0] = b;
    'dfs: while head > 0 {
        let b = xi[head - 1];
        let pb = row_inv[b];
        let range = if pb < ncols {
            l_ptr[pb]..l_ptr[pb + 1]
        } else {
            0..0
        };
        if marked[b] < mark {
            marked[b] = mark;
            stack[head - 1] = range.start;
        }
        let start = stack[head - 1];
        for p in start..range.end {
            let i = l_row[p] as usize;
            if marked[i] == mark {
                continue;
            }
            stack[head - 1] = p;
            xi[head] = i;
            head += 1;
            continue 'dfs;
        }
        head -= 1;
        tail -= 1;
        xi[tail] = b;
    }
    tail
}
