//! The lowest modes of a large conservative model by shift-invert block Lanczos on the
//! project's sparse LU: one factorisation and a few hundred solves, no dense matrix.
//!
//! **The constraints stay a saddle-point block.** The dense path eliminates `B q = 0`
//! through a null-space basis `N` (an `O(n³)` eigen-decomposition of `BᵀB`). Here the
//! shifted operator keeps them as multipliers, as the iteration matrix of a step does:
//!
//! ```text
//! A(σ) = [ K − σM   s Bᵀ ]      A(σ) [x; μ] = [M v; 0]   ⇒   x = T v,
//!        [ s B       0   ]      T = N (Nᵀ(K − σM)N)⁻¹ Nᵀ M
//! ```
//!
//! (`s` the constraint scale of the assembly). The second row gives `B x = 0`, so `x = N y`;
//! the first, projected on `N`, gives `Nᵀ(K − σM)N y = NᵀM v`. For a constrained mode,
//! `NᵀKN z = ω² NᵀMN z`, `φ = N z`: `T φ = φ/(ω² − σ)`. So the eigenpairs of `T` with
//! `θ ≠ 0` are the constrained problem's, `θ = 1/(ω² − σ)`, and the modes nearest the
//! shift have the largest `|θ|` (Ericsson & Ruhe 1980, the spectral transformation;
//! Géradin & Cardona, *Flexible Multibody Dynamics*, §12 for the saddle point). `T` is
//! self-adjoint in the mass inner product `⟨u, w⟩ = uᵀMw` on `range N` (for a symmetric
//! reduced `K`): `wᵀM T v = (Nᵀ M w)ᵀ (Nᵀ(K − σM)N)⁻¹ (NᵀM v)`. Every vector the iteration
//! makes is an image of `T`, so it satisfies the constraints and has no massless part.
//! `A(σ)` is regular when `B` has full row rank (redundant joints make it singular: such
//! models go the dense way) and `σ` is not an eigenvalue.
//!
//! **The iteration** (block Lanczos with full reorthogonalisation, thick-restarted: Golub &
//! Underwood 1977; Grimes, Lewis & Simon, SIAM J. Matrix Anal. Appl. 15(1) 1994): an
//! `M`-orthonormal basis `Q`, grown by the images `T P` of its last block `P`, each
//! projected twice on `Q` (Gram–Schmidt twice: the coefficients are the columns of
//! `H = QᵀM T Q`, and `T Q = Q H + W Eᵀ` with `W` the last block's projected image alone).
//! The Ritz pairs `(θ, Q s)` of `H` have residual `‖W s_P‖_M`; the iteration stops when the
//! `count` largest `|θ|` have residuals below [`TOL`]`·|θ|`, and restarts, when `Q` reaches
//! its maximum size, on the best Ritz vectors (each one's image lies in the span of the
//! Ritz vectors and `W`, so the relation holds across restarts). A block of `b` vectors
//! finds eigenvalues of multiplicity up to `b` (a single vector finds one copy of a double
//! eigenvalue, as a symmetric beam's two bending planes): `b` = [`BLOCK`] covers a free
//! body's six rigid motions; when a cluster of converged values fills the block, the
//! iteration is repeated with twice the block.
//!
//! The shift: `σ = −10⁻⁸ ω²_max` (the dense path's), with `ω²_max` the largest diagonal
//! ratio `K_ii/M_ii`: `K − σM` is regular with free rigid motions, which come out as
//! `θ = 1/|σ|`. `ω² = 1/θ + σ` is exact to `ε|σ|` below `|σ|`; above it the Rayleigh
//! quotient `φᵀKφ/φᵀMφ` is used (its error is quadratic in the shape's).
//!
//! Conservative and undamped only: a nodal `C` above [`super::DAMPED_TOL`] of
//! `√(max|K| max|M|)` sends the model, before any solve, to the quadratic problem's
//! solver ([`super::sparse_damped`]: shift-invert Arnoldi on the first-order form); the
//! reduced `K` and `C` are checked on the final basis (`QᵀKQ` symmetric to
//! [`super::ASYMMETRY_TOL`] of the model's stiffness scale, `QᵀCQ` below
//! [`super::DAMPED_TOL`] of its square root), and a model that fails it is solved again
//! by that solver.

pub use super::krylov::SparseError;
use super::krylov::dot;
use super::linearise::{self, ElementMatrices};
use crate::elements::NodeState;
pub use crate::lanczos::{BLOCK, ShiftInvert, TOL};
use crate::lanczos::{Outcome, cluster_fills, iterate};
use crate::solver::system::System;
use nalgebra::DMatrix;

/// The smallest shift is `SHIFT_FLOOR · ε ω²_max`: the round-off of the assembled `K`
/// (`ε ω²_max`, [`super::dense::ZERO_FACTOR`]) must not make `K − σM` singular.
const SHIFT_FLOOR: f64 = 1e3;

/// The modes the sparse solve found.
pub struct SparseModes {
    /// `(ω², shape)`, lowest first; the shape on the nodal equations, `φᵀMφ = 1`
    /// (empty when the quadratic problem was solved: [`SparseModes::damped`]).
    pub pairs: Vec<(f64, Vec<f64>)>,
    /// The modes of the quadratic problem, lowest `|λ|` first, when the model is damped,
    /// gyroscopic or non-symmetric ([`super::sparse_damped`]); empty otherwise.
    pub damped: Vec<super::sparse_damped::DampedMode>,
    /// Nodal unknowns less the constraint equations (full row rank: the LU is regular).
    pub free_unknowns: usize,
    /// Constraint equations.
    pub constraints: usize,
    /// Relative asymmetry of `QᵀKQ` on the final basis (of the nodal `K` for a model found
    /// damped before the iteration).
    pub asymmetry: f64,
    /// Per element: its nodal `K` and `M`, for energy shares.
    pub locals: Vec<ElementMatrices>,
    /// Solves (applications of `T`), factorisations, final block size.
    pub solves: usize,
    /// Numeric factorisations of `A(σ)`.
    pub factorisations: usize,
    /// Block size used.
    pub block: usize,
    /// The shift `σ`, 1/s².
    pub shift: f64,
    /// `ε`-scale threshold below which `|ω²|` is a rigid motion (the dense path's rule with
    /// the diagonal estimate of `ω²_max`).
    pub zero: f64,
}

/// The nodal `K`, `M`, `C` on the pattern of the system's iteration matrix.
struct Operator<'a> {
    sys: &'a mut System,
    nn: usize,
    k: &'a [f64],
    m: &'a [f64],
    c: &'a [f64],
    solves: usize,
}

impl Operator<'_> {
    /// `y = A x` on the nodal block of the values `a` of the pattern.
    fn mul(&self, a: &[f64], x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        let mat = &self.sys.matrix;
        for (col, xc) in x.iter().enumerate().take(self.nn) {
            if *xc == 0.0 {
                continue;
            }
            for p in mat.position_range(col) {
                let r = mat.row_of(p);
                if r < self.nn {
                    y[r] += a[p] * xc;
                }
            }
        }
    }

    fn mass(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.nn];
        self.mul(self.m, x, &mut y);
        y
    }

    /// `T v` from `M v`.
    fn apply_mass(&mut self, mv: &[f64]) -> Result<Vec<f64>, SparseError> {
        let mut rhs = vec![0.0; self.sys.n_eq()];
        rhs[..self.nn].copy_from_slice(mv);
        self.sys.matrix.solve(&mut rhs)?;
        self.solves += 1;
        rhs.truncate(self.nn);
        Ok(rhs)
    }
}

impl ShiftInvert for Operator<'_> {
    type Error = SparseError;
    fn dim(&self) -> usize {
        self.nn
    }
    fn free(&self) -> usize {
        self.nn - (self.sys.n_eq() - self.nn)
    }
    fn mass(&self, x: &[f64]) -> Vec<f64> {
        Operator::mass(self, x)
    }
    fn apply_mass(&mut self, mv: &[f64]) -> Result<Vec<f64>, SparseError> {
        Operator::apply_mass(self, mv)
    }
    fn solves(&self) -> usize {
        self.solves
    }
}

/// Assembles the nodal `K`, `M`, `C` on the iteration matrix's pattern, element by element
/// as the dense path does ([`linearise::element_parts`]); `K` keeps its multiplier rows
/// and columns (`s B`, `s Bᵀ`).
fn assemble(
    sys: &mut System,
    nodes: &[NodeState],
    lambda: &[f64],
    scale: f64,
    t: f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<ElementMatrices>) {
    let nn = sys.n_node_eq;
    let nnz = sys.matrix.nnz();
    let (mut k, mut m, mut c) = (vec![0.0; nnz], vec![0.0; nnz], vec![0.0; nnz]);
    let base = linearise::base_context(sys, scale, t);
    let mut locals = Vec::with_capacity(sys.elements.len());
    for e in 0..sys.elements.len() {
        let p = linearise::element_parts(sys, e, nodes, lambda, &base);
        let size = p.rows.len();
        for j in 0..size {
            let Some(gj) = p.rows[j] else { continue };
            for i in 0..size {
                let Some(gi) = p.rows[i] else { continue };
                let Some(pos) = sys.matrix.position(gi, gj) else {
                    continue;
                };
                let q = j * size + i;
                k[pos] += p.k[q];
                if gi < nn && gj < nn {
                    m[pos] += p.m[q];
                    c[pos] += p.c[q];
                }
            }
        }
        locals.push(p.local_matrices());
    }
    for (i, j, v) in linearise::moment_stiffness(sys, nodes, t) {
        if let Some(pos) = sys.matrix.position(i, j) {
            k[pos] += v;
        }
    }
    (k, m, c, locals)
}

/// The lowest `count` modes (nearest the shift) of the conservative model at the state,
/// by shift-invert block Lanczos on the system's sparse LU (module docs). `sys`'s
/// iteration matrix is overwritten.
pub fn lowest(
    sys: &mut System,
    nodes: &[NodeState],
    lambda: &[f64],
    scale: f64,
    t: f64,
    count: usize,
) -> Result<SparseModes, SparseError> {
    let nn = sys.n_node_eq;
    let constraints = sys.n_eq() - nn;
    let (k, m, c, locals) = assemble(sys, nodes, lambda, scale, t);
    // ω²_max estimate: the largest diagonal ratio (a lower bound of the largest eigenvalue).
    let mut w2max: f64 = 0.0;
    for i in 0..nn {
        if let Some(p) = sys.matrix.position(i, i)
            && m[p] > 0.0
        {
            w2max = w2max.max(k[p].abs() / m[p]);
        }
    }
    if w2max == 0.0 {
        return Err(SparseError::Massless);
    }
    let zero = super::dense::ZERO_FACTOR * f64::EPSILON * w2max;
    // Damped or gyroscopic on the nodal equations (the dense path's test on NᵀCN, here
    // before any solve): the quadratic problem's solver.
    let nodal_max = |a: &[f64]| {
        let mut mx = 0.0f64;
        for col in 0..nn {
            for p in sys.matrix.position_range(col) {
                if sys.matrix.row_of(p) < nn {
                    mx = mx.max(a[p].abs());
                }
            }
        }
        mx
    };
    let damped = nodal_max(&c) > super::DAMPED_TOL * (nodal_max(&k) * nodal_max(&m)).sqrt();
    let state_space = |sys: &mut System, asymmetry: f64| -> Result<SparseModes, SparseError> {
        let before = sys.matrix.pivoting_factorizations();
        let found = super::sparse_damped::lowest(sys, &k, &c, &m, w2max, count)?;
        Ok(SparseModes {
            pairs: Vec::new(),
            damped: found.modes,
            free_unknowns: nn - constraints,
            constraints,
            asymmetry,
            locals: Vec::new(),
            solves: found.solves,
            factorisations: (sys.matrix.pivoting_factorizations() - before) as usize,
            block: super::sparse_damped::BLOCK,
            shift: found.shift,
            zero,
        })
    };
    if damped {
        // The nodal stiffness's relative asymmetry (the constrained one is not formed).
        let mut asym = 0.0f64;
        for col in 0..nn {
            for p in sys.matrix.position_range(col) {
                let r = sys.matrix.row_of(p);
                if r < nn {
                    let t = sys.matrix.position(col, r).map_or(0.0, |q| k[q]);
                    asym = asym.max((k[p] - t).abs());
                }
            }
        }
        let kn = nodal_max(&k).max(f64::MIN_POSITIVE);
        let mut out = state_space(sys, asym / kn)?;
        out.locals = locals;
        return Ok(out);
    }
    let mut sigma = -1e-8 * w2max;
    let shift = |sys: &mut System, sigma: f64| -> Result<(), SparseError> {
        for (a, (kv, mv)) in sys.matrix.values.iter_mut().zip(k.iter().zip(&m)) {
            *a = kv - sigma * mv;
        }
        Ok(sys.matrix.factor()?)
    };
    shift(sys, sigma)?;
    let mut op = Operator {
        sys,
        nn,
        k: &k,
        m: &m,
        c: &c,
        solves: 0,
    };
    let mut block = BLOCK.min(count.max(1));
    let mut probe = Some((sigma, SHIFT_FLOOR * f64::EPSILON * w2max));
    let result = loop {
        let (theta, basis) = match iterate(&mut op, count, block, probe)? {
            Outcome::Converged(theta, basis) => (theta, basis),
            Outcome::Probe(target) => {
                probe = None;
                sigma = target;
                shift(op.sys, sigma)?;
                continue;
            }
        };
        // A cluster of converged values as large as the block may hide more copies.
        let big = cluster_fills(&theta, block);
        if big && block < nn - constraints && block < 4 * BLOCK {
            block *= 2;
            continue;
        }
        break finish(&op, theta, basis, sigma, w2max, constraints, block);
    };
    match result {
        Ok(mut out) => {
            out.locals = locals;
            Ok(out)
        }
        // Non-symmetric on the constrained motions (follower loads, a rotating state):
        // the quadratic problem's solver.
        Err(SparseError::NotConservative { asymmetry, .. }) => {
            let mut out = state_space(op.sys, asymmetry)?;
            out.locals = locals;
            Ok(out)
        }
        Err(e) => Err(e),
    }
}

#[allow(clippy::too_many_arguments)]
fn finish(
    op: &Operator,
    theta: Vec<f64>,
    basis: Vec<Vec<f64>>,
    sigma: f64,
    w2max: f64,
    constraints: usize,
    block: usize,
) -> Result<SparseModes, SparseError> {
    let nn = op.nn;
    let n = basis.len();
    let mut kq = Vec::with_capacity(n);
    let mut cq = Vec::with_capacity(n);
    for phi in &basis {
        let mut y = vec![0.0; nn];
        op.mul(op.k, phi, &mut y);
        kq.push(y);
        let mut y = vec![0.0; nn];
        op.mul(op.c, phi, &mut y);
        cq.push(y);
    }
    let kr = DMatrix::from_fn(n, n, |i, j| dot(&basis[i], &kq[j]));
    let cr = DMatrix::from_fn(n, n, |i, j| dot(&basis[i], &cq[j]));
    let max_abs = |a: &DMatrix<f64>| a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // Against the model's stiffness scale, as the dense path (max|NᵀKN| ~ ω²_max): the
    // assembled K carries ε ω²_max of round-off, which on the low modes' QᵀKQ alone
    // reached 1.06e-8 of it at 50,004 unknowns.
    let kn = max_abs(&kr).max(w2max).max(f64::MIN_POSITIVE);
    let asymmetry = max_abs(&(&kr - kr.transpose())) / kn;
    let damping = max_abs(&cr) / kn.sqrt();
    if asymmetry > super::ASYMMETRY_TOL || damping > super::DAMPED_TOL {
        return Err(SparseError::NotConservative { asymmetry, damping });
    }
    let mut pairs: Vec<(f64, Vec<f64>)> = theta
        .iter()
        .zip(basis)
        .enumerate()
        .map(|(i, (&th, phi))| {
            // ω² = 1/θ + σ, exact to ε|σ| below |σ|; above it the Rayleigh quotient
            // (φᵀMφ = 1).
            let mut w2 = 1.0 / th + sigma;
            if w2 > -sigma {
                w2 = kr[(i, i)];
            }
            (w2, phi)
        })
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(SparseModes {
        pairs,
        damped: Vec::new(),
        free_unknowns: nn - constraints,
        constraints,
        asymmetry,
        locals: Vec::new(),
        solves: op.solves,
        factorisations: op.sys.matrix.pivoting_factorizations() as usize,
        block,
        shift: sigma,
        zero: super::dense::ZERO_FACTOR * f64::EPSILON * w2max,
    })
}
