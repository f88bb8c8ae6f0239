//! The saved state of a [`SparseSystem`] (values, factors, pivots), for checkpoints.

use super::{LinearError, SparseSystem};

/// Everything of a [`SparseSystem`] that a later factorisation or solve reads: the
/// values, the simplicial factors with their pivots and patterns, and the counters. A
/// restart from it factors and solves bit for bit as the run it was taken from
/// (the refactorisation on kept pivots depends on the pivots of the last pivoting
/// factorisation, and modified Newton solves with factors kept across steps).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LuState {
    values: Vec<f64>,
    factored: bool,
    valid: bool,
    l_ptr: Vec<usize>,
    l_row: Vec<usize>,
    l_val: Vec<f64>,
    u_ptr: Vec<usize>,
    u_row: Vec<usize>,
    u_val: Vec<f64>,
    u_diag: Vec<f64>,
    row_fwd: Vec<usize>,
    col_fwd: Vec<usize>,
    a_row: Vec<usize>,
    pivoting_factorizations: u64,
}

impl SparseSystem {
    /// The state a restart needs ([`LuState`]).
    pub fn save_state(&self) -> LuState {
        let f = &self.factors;
        LuState {
            values: self.values.clone(),
            factored: self.factored,
            valid: f.valid,
            l_ptr: f.l_ptr.clone(),
            l_row: f.l_row.iter().map(|&r| r as usize).collect(),
            l_val: f.l_val.clone(),
            u_ptr: f.u_ptr.clone(),
            u_row: f.u_row.iter().map(|&r| r as usize).collect(),
            u_val: f.u_val.clone(),
            u_diag: f.u_diag.clone(),
            row_fwd: f.row_fwd.clone(),
            col_fwd: f.col_fwd.clone(),
            a_row: f.a_row.iter().map(|&r| r as usize).collect(),
            pivoting_factorizations: self.pivoting_factorizations,
        }
    }

    /// Restores a [`SparseSystem::save_state`] of a system with the same pattern. The
    /// stored indices are checked (the unchecked indexing of the solves relies on them):
    /// a state of another pattern is refused, never used.
    pub fn restore_state(&mut self, s: LuState) -> Result<(), LinearError> {
        let n = self.n;
        let bad = |what: &str| Err(LinearError::State(what.to_string()));
        if s.values.len() != self.values.len() {
            return bad("the matrix has another number of entries");
        }
        if s.valid {
            let ptr_ok = |p: &[usize], len: usize| {
                p.len() == n + 1 && p[0] == 0 && p[n] == len && p.windows(2).all(|w| w[0] <= w[1])
            };
            let ok = ptr_ok(&s.l_ptr, s.l_row.len())
                && ptr_ok(&s.u_ptr, s.u_row.len())
                && s.l_val.len() == s.l_row.len()
                && s.u_val.len() == s.u_row.len()
                && s.u_diag.len() == n
                && s.row_fwd.len() == n
                && s.col_fwd.len() == n
                && s.a_row.len() == self.row_idx.len()
                && s.l_row
                    .iter()
                    .chain(&s.u_row)
                    .chain(&s.a_row)
                    .all(|&r| r < n)
                && s.row_fwd.iter().chain(&s.col_fwd).all(|&r| r < n)
                && u32::try_from(n).is_ok();
            if !ok {
                return bad("the factors do not fit the matrix");
            }
        } else if s.factored {
            return bad("factored without valid factors");
        }
        self.values = s.values;
        self.factored = s.factored;
        self.pivoting_factorizations = s.pivoting_factorizations;
        let f = &mut self.factors;
        f.valid = s.valid;
        f.l_ptr = s.l_ptr;
        f.l_row = s.l_row.iter().map(|&r| r as u32).collect();
        f.l_val = s.l_val;
        f.u_ptr = s.u_ptr;
        f.u_row = s.u_row.iter().map(|&r| r as u32).collect();
        f.u_val = s.u_val;
        f.u_diag = s.u_diag;
        f.row_fwd = s.row_fwd;
        f.col_fwd = s.col_fwd;
        // `as u32` cannot truncate valid factors (every row < n ≤ u32::MAX, checked above);
        // invalid ones are never read.
        f.a_row = s.a_row.iter().map(|&r| r as u32).collect();
        f.work.clear();
        f.work.resize(n, 0.0);
        f.index_runs();
        Ok(())
    }
}
