//! The consistent linearisation of the project's own residual at a state, in dense form.
//!
//! Each element's iteration matrix is `S = ∂r/∂q + c_v ∂r/∂v + c_a ∂r/∂a`
//! ([`crate::elements::EvalContext`]); the part that multiplies `c_v` and `c_a` comes back
//! separately in [`Local::rate`]. Three evaluations at the state isolate the matrices:
//! `(c_v, c_a) = (0, 0)` gives the tangent stiffness `K = ∂r/∂q` (material, geometric —
//! the multipliers' `s Bᵀλ` and the beams' stresses — centrifugal and inertial parts at the
//! state's velocities and accelerations), `(0, c)` less it `c M` (`M = ∂r/∂a`), `(c, 0)`
//! less it `c C` (`C = ∂r/∂v`, damping and gyroscopic). A global applied moment adds its follower
//! stiffness `−(Rᵀm)~` on the node's spin (as [`crate::solver::system::System`] does).
//! The multiplier rows of `K` hold `s B`, the constraint Jacobian: the free motions are
//! its null space `q = N y` ([`null_space`]), and the reduced matrices are `NᵀKN`, `NᵀCN`,
//! `NᵀMN` (Géradin & Cardona, *Flexible Multibody Dynamics*, ch. 12).

use crate::elements::{EvalContext, Local, NodeState};
use crate::rotation::skew;
use crate::solver::system::{FIXED, System};
use nalgebra::{DMatrix, SymmetricEigen};

/// The dense matrices of a linearisation, on the nodal equations of a [`System`].
#[derive(Debug, Clone)]
pub struct Linearised {
    /// Tangent stiffness `∂r/∂q` on the nodal equations.
    pub k: DMatrix<f64>,
    /// Damping and gyroscopic matrix `∂r/∂v`.
    pub c: DMatrix<f64>,
    /// Mass matrix `∂r/∂a`.
    pub m: DMatrix<f64>,
    /// Constraint Jacobian `B` (rows: multiplier equations; columns: nodal equations).
    pub b: DMatrix<f64>,
    /// `∂r/∂λ̂` on the nodal equations (columns: the scaled multipliers), `s Bᵀ` for the
    /// joints: the Newton matrix of a relative equilibrium ([`super::rotating`]) needs it.
    pub kl: DMatrix<f64>,
    /// Per element: its local-to-nodal-equation map (`None` = fixed or multiplier) and its
    /// local stiffness and mass (column-major, size `6·nodes`), for energy shares.
    pub locals: Vec<ElementMatrices>,
}

/// One element's local stiffness and mass at the state, with its equation map.
#[derive(Debug, Clone)]
pub struct ElementMatrices {
    /// Nodal equation of each local node dof (`None` = fixed).
    pub rows: Vec<Option<usize>>,
    /// Local stiffness `6n × 6n`, column-major.
    pub k: Vec<f64>,
    /// Local mass `6n × 6n`, column-major.
    pub m: Vec<f64>,
}

impl ElementMatrices {
    /// `φᵀ A φ` of the local matrix `a` (`k` or `m`) for a nodal-equation vector `phi`.
    pub fn quadratic(&self, a: &[f64], phi: &[f64]) -> f64 {
        let n = self.rows.len();
        let v: Vec<f64> = self
            .rows
            .iter()
            .map(|r| r.map_or(0.0, |i| phi[i]))
            .collect();
        let mut s = 0.0;
        for j in 0..n {
            if v[j] == 0.0 {
                continue;
            }
            for i in 0..n {
                s += v[i] * a[j * n + i] * v[j];
            }
        }
        s
    }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Assembles `K`, `C`, `M` and `B` at the state (`nodes`, scaled multipliers `lambda`
/// indexed by global equation, constraint scale `scale`, time `t`).
pub fn linearise(
    sys: &System,
    nodes: &[NodeState],
    lambda: &[f64],
    scale: f64,
    t: f64,
) -> Linearised {
    let nn = sys.n_node_eq;
    let n = sys.n_eq();
    let mut full_k = DMatrix::<f64>::zeros(n, n);
    let mut c = DMatrix::<f64>::zeros(nn, nn);
    let mut m = DMatrix::<f64>::zeros(nn, nn);
    let base = base_context(sys, scale, t);
    let mut locals = Vec::with_capacity(sys.elements.len());
    for e in 0..sys.elements.len() {
        let p = element_parts(sys, e, nodes, lambda, &base);
        let size = p.rows.len();
        for j in 0..size {
            for i in 0..size {
                let (Some(gi), Some(gj)) = (p.rows[i], p.rows[j]) else {
                    continue;
                };
                let q = j * size + i;
                full_k[(gi, gj)] += p.k[q];
                if gi < nn && gj < nn {
                    m[(gi, gj)] += p.m[q];
                    c[(gi, gj)] += p.c[q];
                }
            }
        }
        locals.push(p.local_matrices());
    }
    // Applied moments: −Rᵀm enters the material equations, its spin derivative −(Rᵀm)~.
    for (i, j, v) in moment_stiffness(sys, nodes, t) {
        full_k[(i, j)] += v;
    }
    let k = full_k.view((0, 0), (nn, nn)).into_owned();
    let b = full_k.view((nn, 0), (n - nn, nn)).into_owned() / scale;
    let kl = full_k.view((0, nn), (nn, n - nn)).into_owned();
    Linearised {
        k,
        c,
        m,
        b,
        kl,
        locals,
    }
}

/// One element's linearisation at the state: its equation map (nodal dofs, then its
/// multipliers; `None` = fixed) and its `K`, `M`, `C` on it (column-major, `size × size`,
/// `size = rows.len()`; `K`'s multiplier rows and columns hold `s B` and `s Bᵀ`).
pub struct ElementParts {
    /// Global equation of each local row.
    pub rows: Vec<Option<usize>>,
    /// Local nodal unknowns (`6·nodes`); the multipliers follow.
    pub nloc: usize,
    /// `∂r/∂q`.
    pub k: Vec<f64>,
    /// `∂r/∂a`.
    pub m: Vec<f64>,
    /// `∂r/∂v`.
    pub c: Vec<f64>,
}

impl ElementParts {
    /// The nodal blocks of `K` and `M`, for energy shares.
    pub fn local_matrices(&self) -> ElementMatrices {
        let (size, nloc) = (self.rows.len(), self.nloc);
        let block = |a: &[f64]| -> Vec<f64> {
            (0..nloc)
                .flat_map(|j| a[j * size..j * size + nloc].to_vec())
                .collect()
        };
        ElementMatrices {
            rows: self.rows[..nloc].to_vec(),
            k: block(&self.k),
            m: block(&self.m),
        }
    }
}

/// Element `e`'s [`ElementParts`] at the state (`base`: `c_v = c_a = 0`).
pub fn element_parts(
    sys: &System,
    e: usize,
    nodes: &[NodeState],
    lambda: &[f64],
    base: &EvalContext,
) -> ElementParts {
    let el = &sys.elements[e];
    let nm = el.multipliers();
    let nloc = 6 * el.nodes().len();
    let size = nloc + nm;
    let rows: Vec<Option<usize>> = el
        .nodes()
        .iter()
        .flat_map(|&node| sys.node_dofs[node].map(|d| (d != FIXED).then_some(d)))
        .chain((0..nm).map(|k| Some(sys.mult_offset[e] + k)))
        .collect();
    let lam = sys.element_lambda(e, lambda);
    let eval = |cv: f64, ca: f64| {
        let mut l = Local::new(size);
        let ctx = EvalContext {
            c_v: cv,
            c_a: ca,
            ..*base
        };
        el.evaluate(&ctx, nodes, lam, true, &mut l);
        l
    };
    // K = S(0, 0); M and C as differences S(0, c) − S(0, 0) over c, with c the
    // ratio of the element's stiffness to its mass (damping) entries, so that the
    // difference keeps full precision when K ≫ M (stiff bars). (`Local::rate` holds
    // only the parts the rotation tangent needs: a point mass's translational mass
    // is in `tan` alone.)
    let lk = eval(0.0, 0.0);
    let kmax = max_abs(&lk.tan);
    let rate_part = |cv: f64, ca: f64| -> Vec<f64> {
        let probe = eval(cv, ca);
        let est = probe
            .tan
            .iter()
            .zip(&lk.tan)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        let c = if est > 0.0 {
            (kmax / est).max(1.0)
        } else {
            1.0
        };
        let l = if c == 1.0 {
            probe
        } else {
            eval(cv * c, ca * c)
        };
        l.tan
            .iter()
            .zip(&lk.tan)
            .map(|(a, b)| (a - b) / c)
            .collect()
    };
    let m = rate_part(0.0, 1.0);
    let c = rate_part(1.0, 0.0);
    ElementParts {
        rows,
        nloc,
        k: lk.tan,
        m,
        c,
    }
}

/// The base context of a linearisation at time `t` (`c_v = c_a = 0`).
pub fn base_context(sys: &System, scale: f64, t: f64) -> EvalContext {
    EvalContext {
        t,
        c_v: 0.0,
        c_a: 0.0,
        dynamic: true,
        gravity: sys.gravity,
        constraint_scale: scale,
        penalty: 0.0,
        h: 0.0,
    }
}

/// The follower stiffness `−(Rᵀm)~` of the global applied moments at `t`, as
/// (spin row, spin column, value) on nodal equations.
pub fn moment_stiffness(sys: &System, nodes: &[NodeState], t: f64) -> Vec<(usize, usize, f64)> {
    let mut out = Vec::new();
    for l in sys.loads.iter().filter(|l| l.moment) {
        let mm = nodes[l.node].r.transpose() * l.at(t);
        let kk = -skew(&mm);
        let d = &sys.node_dofs[l.node];
        for a in 0..3 {
            for b in 0..3 {
                if d[3 + a] != FIXED && d[3 + b] != FIXED {
                    out.push((d[3 + a], d[3 + b], kk[(a, b)]));
                }
            }
        }
    }
    out
}

/// Relative threshold on the singular values of the (row-equilibrated) constraint
/// Jacobian below which a direction is free. Joint Jacobian rows have entries of order 1
/// (unit vectors) and lever arms; a redundant row is a combination of others to round-off,
/// `ε·rows`, so its singular value is ~1e-15; squaring (`BᵀB`) leaves ε on `σ²` (~1e-8
/// on σ): 1e-6 sits between those and any honest constraint.
const NULL_SPACE_TOL: f64 = 1e-6;

/// Whether the constraint Jacobian `b` constrains nothing (no rows, or only zeros):
/// [`null_space`] is then the identity.
pub fn unconstrained(b: &DMatrix<f64>) -> bool {
    b.nrows() == 0 || b.iter().all(|v| *v == 0.0)
}

/// An orthonormal basis `N` (columns) of the null space of `b` (`n` columns): the free
/// motions the constraints allow. Rank-revealing (redundant rows, as a four-bar's
/// hinges, cost nothing): the eigenvectors of `BᵀB` (rows scaled to unit norm) whose
/// eigenvalue is below `NULL_SPACE_TOL²` of the largest.
pub fn null_space(b: &DMatrix<f64>, n: usize) -> DMatrix<f64> {
    let mut rows = b.clone();
    for mut r in rows.row_iter_mut() {
        let norm = r.norm();
        if norm > 0.0 {
            r /= norm;
        }
    }
    if unconstrained(&rows) {
        return DMatrix::identity(n, n);
    }
    let btb = rows.transpose() * &rows;
    let eig = SymmetricEigen::new(btb);
    let max = eig.eigenvalues.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let keep: Vec<usize> = (0..n)
        .filter(|&i| eig.eigenvalues[i] <= NULL_SPACE_TOL * NULL_SPACE_TOL * max)
        .collect();
    DMatrix::from_fn(n, keep.len(), |r, c| eig.eigenvectors[(r, keep[c])])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn null_space_of_redundant_rows() {
        // Two equal rows and a third that is their multiple: rank 1 in ℝ³ → 2 free directions.
        let b = DMatrix::from_row_slice(3, 3, &[1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 2.0, 2.0, 0.0]);
        let n = null_space(&b, 3);
        assert_eq!(n.ncols(), 2);
        assert!((&b * &n).norm() < 1e-14);
        assert!((n.transpose() * &n - DMatrix::identity(2, 2)).norm() < 1e-14);
    }
}
