//! The lowest modes of a large damped, gyroscopic or non-symmetric model: shift-invert
//! block Arnoldi on the first-order form of the quadratic problem, through one sparse LU.
//!
//! **The operator.** The quadratic problem `(λ²M + λC + K) x = 0`, `B x = 0`, in first-order
//! form `A z = λ z`, `z = [x; v]`, `A = [0 I; −M⁻¹K −M⁻¹C]` on the constraints' null space
//! (the dense path's form, [`super::dense::state_space`]). With a real shift `σ`,
//! `T = (A − σI)⁻¹` maps `[a; b]` to `[u; a + σu]`, where
//!
//! ```text
//! [ P(σ)  s Bᵀ ] [u]   [ −M b − (C + σM) a ]
//! [ s B    0   ] [ν] = [        0          ],      P(σ) = K + σC + σ²M
//! ```
//!
//! (from `v − σu = a` and `−Ku − Cv − σMv = Mb`, projected on the null space `N` by the
//! bordered rows exactly as the symmetric path's saddle point, [`super::sparse`]). No `M⁻¹`
//! is formed: massless directions are infinite eigenvalues, `μ = 0`. The eigenvalues of `T`
//! are `μ = 1/(λ − σ)`, so `λ = σ + 1/μ` and the modes nearest the shift have the largest
//! `|μ|` (Ericsson & Ruhe 1980; for the quadratic problem Tisseur & Meerbergen, SIAM Rev.
//! 43(2) 2001, §5). Every vector the iteration makes is an image `[u; a + σu]` of a vector
//! with `a = u_prev` in the null space (the start vectors are images of `[0; r]`), so it
//! satisfies the constraints in both halves. `σ > 0` (the unstable half-plane): `P(σ)` has
//! the symmetric part `K_sym + σ C_sym + σ² M`, positive definite for a stable `K`,
//! dashpots (`C_sym ≥ 0`) and gyroscopic terms (`C` skew), whatever the rigid motions.
//!
//! **The iteration.** Block Arnoldi with full reorthogonalisation in real arithmetic
//! (Gram–Schmidt twice) in the coordinates `[dx·x; dv·v]`, `dx = √(|K_ii| + σ²M_ii)`,
//! `dv = √M_ii` (a diagonal estimate of the energy norm, in which an undamped `T` is
//! normal: in plain `[x; v]` spurious Ritz values stalled it), the Rayleigh quotient `H = VᵀTV` kept whole (the images `W = TV`
//! are stored), its eigenvalues `μ` and vectors `s` by faer's dense eigen-decomposition
//! (complex pairs of a real `H`), thick-restarted on the real and imaginary parts of the
//! wanted Ritz vectors (Morgan, Math. Comp. 65 1996: the span of Ritz vectors and the
//! last remainders is again a Krylov space). The block of 6 finds a free body's rigid
//! motions and a symmetric beam's double frequencies.
//!
//! **Which modes, and when converged.** The dense path's order: one mode per conjugate
//! pair (`Im λ ≥ 0`), the lowest `count` by `|λ|`. An eigenvalue with `|λ| ≤ L` has
//! `|λ − σ| ≤ L + σ`, i.e. `|μ| ≥ 1/(L + σ)`: the set is complete when every Ritz value
//! with `|μ| ≥ 1/(L_c + σ)` (`L_c` the `count`-th smallest `|λ|`) has converged and the
//! space holds a Ritz value beyond. Converged means the Krylov residual
//! `‖T y − μ y‖ ≤ TOL_KRYLOV |μ|` (the accuracy of `μ`, as the symmetric path's test) and
//! the residual of the original quadratic problem, `r = (λ²M + λC + K) x + s Bᵀν/μ` with
//! `ν` the multipliers of the solve that made `T y` (for an exact pair `μQ(λ)x + sBᵀν = 0`:
//! `r` is then the constrained problem's residual with its reaction, rows `s B x`
//! included), as a backward error `‖r‖/((|λ|²‖M‖ + |λ|‖C‖ + ‖K‖)‖x‖)` (∞-norms) below
//! [`TOL_QUADRATIC`].

mod ritz;

use super::krylov::{DROP, SparseError, axpy, dot, norm, pattern_mul};
use crate::solver::system::System;
use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use ritz::{Ritz, cdiv, ritz_pairs};

/// Block size (as the symmetric path's: six rigid motions of a free body).
pub const BLOCK: usize = 6;
/// Krylov residual `‖T y − μ y‖ ≤ TOL_KRYLOV |μ|` (the symmetric path's `TOL`).
const TOL_KRYLOV: f64 = 1e-9;
/// Backward error of a converged mode for the quadratic problem (module docs): the
/// residual relative to `(|λ|²‖M‖ + |λ|‖C‖ + ‖K‖)‖x‖` (Tisseur, Linear Algebra Appl. 309,
/// 2000). The Krylov test bounds it by about `TOL_KRYLOV·|λ|` (the residual of `T` is
/// measured in the Euclidean norm of `[x; λx]`): measured 1e-15 to 2e-10 when that test
/// passes (a 366-unknown spinning shaft, |λ| up to 1e4 1/s), so 1e-8 checks the original
/// problem without asking what the first-order form's scaling cannot give.
pub const TOL_QUADRATIC: f64 = 1e-8;

/// A mode of the quadratic problem.
#[derive(Debug, Clone)]
pub struct DampedMode {
    /// Eigenvalue `λ = σ + 1/μ` (real, imaginary ≥ 0), 1/s.
    pub s: (f64, f64),
    /// Shape on the nodal equations: the real part of `x` turned so that its largest
    /// component is real (the dense path's convention), unit Euclidean norm.
    pub shape: Vec<f64>,
    /// Backward error of the quadratic problem (module docs, [`TOL_QUADRATIC`]).
    pub residual: f64,
    /// Below [`TOL_QUADRATIC`].
    converged: bool,
}

/// The modes the damped sparse solve found.
pub struct DampedModes {
    /// The lowest `count` by `|λ|`.
    pub modes: Vec<DampedMode>,
    /// Solves (applications of `T`).
    pub solves: usize,
    /// The shift `σ`, 1/s.
    pub shift: f64,
}

/// `T` of the module docs with its LU, and the nodal `K` (with its multiplier rows and
/// columns), `C`, `M` on the pattern.
struct StateOp<'a> {
    sys: &'a mut System,
    nn: usize,
    k: &'a [f64],
    c: &'a [f64],
    m: &'a [f64],
    /// `C + σM`.
    d: Vec<f64>,
    /// ∞-norms of `K` (all rows, its multiplier columns included), `C` and `M`.
    norms: (f64, f64, f64),
    /// The iteration's coordinates are `[dx·x; dv·v]`: `dx = √(|K_ii| + σ²M_ii)`,
    /// `dv = √M_ii` (a diagonal estimate of the energy norm `xᵀ(K + σ²M)x + vᵀMv`, in
    /// which an undamped `T` is normal; in plain `[x; v]` the halves differ by `|λ|` and
    /// the operator's non-normality gave spurious Ritz values of large `|μ|`: no
    /// convergence on the 306-unknown frame).
    dx: Vec<f64>,
    dv: Vec<f64>,
    sigma: f64,
    solves: usize,
}

impl StateOp<'_> {
    /// `T z` and the multipliers `ν` of its solve.
    fn apply(&mut self, z: &[f64]) -> Result<(Vec<f64>, Vec<f64>), SparseError> {
        let nn = self.nn;
        // From the scaled coordinates (the iteration's) to [x; v].
        let a: Vec<f64> = z[..nn].iter().zip(&self.dx).map(|(z, d)| z / d).collect();
        let b: Vec<f64> = z[nn..].iter().zip(&self.dv).map(|(z, d)| z / d).collect();
        let (a, b) = (&a[..], &b[..]);
        let mut rhs = vec![0.0; self.sys.n_eq()];
        let mut t = vec![0.0; nn];
        pattern_mul(&self.sys.matrix, self.m, b, &mut t, nn, false);
        pattern_mul(&self.sys.matrix, &self.d, a, &mut rhs[..nn], nn, false);
        rhs[..nn]
            .iter_mut()
            .zip(&t)
            .for_each(|(r, t)| *r = -(*r + t));
        self.sys.matrix.solve(&mut rhs)?;
        self.solves += 1;
        let nu = rhs.split_off(nn);
        let mut out = Vec::with_capacity(2 * nn);
        out.extend(a.iter().zip(&rhs).map(|(a, u)| a + self.sigma * u));
        // [u; a + σu], scaled.
        let mut z: Vec<f64> = rhs.iter().zip(&self.dx).map(|(u, d)| u * d).collect();
        z.extend(out.iter().zip(&self.dv).map(|(w, d)| w * d));
        Ok((z, nu))
    }
}

/// An orthonormal basis `V`, the images `W = T V` of its first `w.len()` vectors with
/// their multipliers, and `H = VᵀW` (`h[(i, j)] = v_i · w_j`).
#[derive(Default)]
struct Space {
    v: Vec<Vec<f64>>,
    w: Vec<Vec<f64>>,
    nu: Vec<Vec<f64>>,
    h: Vec<Vec<f64>>,
}

impl Space {
    /// Orthonormalises `vs` against `V` and each other (twice), appends the independent
    /// ones with their rows of `H`; returns how many.
    fn extend(&mut self, vs: Vec<Vec<f64>>) -> usize {
        let mut added = 0;
        for mut x in vs {
            let n0 = norm(&x);
            for _ in 0..2 {
                for q in &self.v {
                    let c = dot(q, &x);
                    axpy(&mut x, -c, q);
                }
            }
            let n1 = norm(&x);
            if n1 <= DROP * n0 || n1 == 0.0 {
                continue;
            }
            x.iter_mut().for_each(|v| *v /= n1);
            let row: Vec<f64> = self.w.iter().map(|w| dot(&x, w)).collect();
            self.h.push(row);
            self.v.push(x);
            added += 1;
        }
        added
    }

    /// Adds the image of `v_j` (`j = w.len()`): its column of `H`; returns its remainder
    /// `(I − VVᵀ) w`.
    fn add_image(&mut self, w: Vec<f64>, nu: Vec<f64>) -> Vec<f64> {
        let mut f = w.clone();
        let mut coef = vec![0.0; self.v.len()];
        for _ in 0..2 {
            for (i, q) in self.v.iter().enumerate() {
                let c = dot(q, &f);
                axpy(&mut f, -c, q);
                coef[i] += c;
            }
        }
        for (row, c) in self.h.iter_mut().zip(coef) {
            row.push(c);
        }
        self.w.push(w);
        self.nu.push(nu);
        f
    }

    fn h_matrix(&self) -> DMatrix<f64> {
        let m = self.w.len();
        DMatrix::from_fn(m, m, |i, j| self.h[i][j])
    }

    /// The space spanned by `V S` (`S` with orthonormal columns): `V S`, `W S`, `ν S`
    /// and `SᵀHS`.
    fn restrict(&self, s: &DMatrix<f64>) -> Space {
        let comb = |vs: &[Vec<f64>], col: usize| -> Vec<f64> {
            let mut y = vec![0.0; vs[0].len()];
            for (j, v) in vs.iter().enumerate() {
                let c = s[(j, col)];
                if c != 0.0 {
                    axpy(&mut y, c, v);
                }
            }
            y
        };
        let k = s.ncols();
        let hs = s.transpose() * self.h_matrix() * s;
        Space {
            v: (0..k).map(|c| comb(&self.v, c)).collect(),
            w: (0..k).map(|c| comb(&self.w, c)).collect(),
            nu: (0..k).map(|c| comb(&self.nu, c)).collect(),
            h: (0..k)
                .map(|i| (0..k).map(|j| hs[(i, j)]).collect())
                .collect(),
        }
    }
}

/// The lowest `count` modes by `|λ|` of the quadratic problem at the assembled `k`
/// (with its multiplier rows), `c`, `m` on `sys`'s pattern (module docs); `w2max` the
/// diagonal estimate of the largest `ω²`. `sys`'s iteration matrix is overwritten.
pub(super) fn lowest(
    sys: &mut System,
    k: &[f64],
    c: &[f64],
    m: &[f64],
    w2max: f64,
    count: usize,
) -> Result<DampedModes, SparseError> {
    let nn = sys.n_node_eq;
    let free = nn - (sys.n_eq() - nn);
    // σ² = 1e-12 ω²_max: 4500 times the round-off of K (ε ω²_max), about the symmetric
    // path's shift floor. A larger σ costs more modes: every eigenvalue within L + σ of σ
    // must converge (module docs); at σ = 1e-4 ω_max = 748 1/s the 50,004-unknown
    // cantilever's 20 modes (|λ| ≤ 1050 1/s) did not in 1800 solves.
    let sigma = 1e-6 * w2max.sqrt();
    for (p, a) in sys.matrix.values.iter_mut().enumerate() {
        *a = k[p] + sigma * c[p] + sigma * sigma * m[p];
    }
    sys.matrix.factor()?;
    let d: Vec<f64> = c.iter().zip(m).map(|(c, m)| c + sigma * m).collect();
    let norm_inf = |a: &[f64]| {
        let mut rows = vec![0.0f64; sys.n_eq()];
        for col in 0..sys.n_eq() {
            for p in sys.matrix.position_range(col) {
                rows[sys.matrix.row_of(p)] += a[p].abs();
            }
        }
        rows.into_iter().fold(0.0f64, f64::max)
    };
    let norms = (norm_inf(k), norm_inf(c), norm_inf(m));
    let diag = |a: &[f64], i: usize| sys.matrix.position(i, i).map_or(0.0, |p| a[p].abs());
    let mmax = (0..nn).map(|i| diag(m, i)).fold(0.0f64, f64::max);
    let floor = 1e-12 * mmax.max(f64::MIN_POSITIVE);
    let dx: Vec<f64> = (0..nn)
        .map(|i| {
            (diag(k, i) + sigma * sigma * diag(m, i))
                .max(sigma * sigma * floor)
                .sqrt()
        })
        .collect();
    let dv: Vec<f64> = (0..nn).map(|i| diag(m, i).max(floor).sqrt()).collect();
    let mut op = StateOp {
        sys,
        nn,
        k,
        c,
        m,
        d,
        norms,
        dx,
        dv,
        sigma,
        solves: 0,
    };
    let trace = std::env::var_os("MECANO_MODES_TRACE").is_some();
    let block = BLOCK.min(count.max(1));
    // A complex mode takes two real vectors (its pair's real and imaginary parts): the
    // restart keeps 2·count + block, and the space holds about as many again (with
    // 2·count + 4 blocks it restarted every 2 blocks: 582–1164 solves for 12 modes of a
    // 306-unknown frame).
    let max_dim = (4 * count + 4 * block).max(40).min(2 * free);
    let budget = 60 * count + 600;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(24);
    let mut random_block = |op: &mut StateOp, b: usize| -> Result<Vec<Vec<f64>>, SparseError> {
        (0..b)
            .map(|_| {
                let mut z = vec![0.0; 2 * nn];
                z[nn..]
                    .iter_mut()
                    .for_each(|v| *v = rng.random::<f64>() - 0.5);
                op.apply(&z).map(|r| r.0)
            })
            .collect()
    };
    let mut sp = Space::default();
    let start = random_block(&mut op, block)?;
    sp.extend(start);
    if sp.v.is_empty() {
        return Err(SparseError::Massless);
    }
    loop {
        let first = sp.w.len();
        let mut rem = Vec::new();
        for j in first..sp.v.len() {
            let (w, nu) = op.apply(&sp.v[j].clone())?;
            rem.push(sp.add_image(w, nu));
        }
        let h = sp.h_matrix();
        let ritz = ritz_pairs(&h)?;
        // Krylov residuals ‖R s‖: the remainders of the block just expanded.
        let g = DMatrix::from_fn(rem.len(), rem.len(), |a, b| dot(&rem[a], &rem[b]));
        let kres = |r: &Ritz| -> f64 {
            let q = |x: &[f64]| {
                let xp = DMatrix::from_fn(rem.len(), 1, |a, _| x[first + a]);
                (xp.transpose() * &g * &xp)[(0, 0)]
            };
            (q(&r.s.0) + q(&r.s.1)).max(0.0).sqrt()
        };
        let mut order: Vec<usize> = (0..ritz.len()).collect();
        let amu = |r: &Ritz| r.mu.0.hypot(r.mu.1);
        order.sort_by(|&a, &b| amu(&ritz[b]).total_cmp(&amu(&ritz[a])));
        let lam = |r: &Ritz| {
            let inv = cdiv((1.0, 0.0), r.mu);
            (sigma + inv.0, inv.1)
        };
        let done = wanted(&ritz, &order, count, sigma, &lam, &|r| {
            kres(r) <= TOL_KRYLOV * amu(r)
        });
        if trace {
            let worst = order[..(2 * count).min(order.len())]
                .iter()
                .map(|&i| kres(&ritz[i]) / amu(&ritz[i]))
                .fold(0.0f64, f64::max);
            eprintln!(
                "arnoldi: {} solves, basis {}, largest relative Krylov residual of the first {}: {worst:.2e}, complete {}",
                op.solves,
                sp.v.len(),
                2 * count,
                done.is_some()
            );
        }
        if let Some(sel) = done {
            let modes: Vec<DampedMode> = sel
                .iter()
                .map(|&i| mode_of(&op, &sp, &ritz[i], lam(&ritz[i])))
                .collect();
            if trace {
                let eta: Vec<String> = modes
                    .iter()
                    .map(|m| format!("{:.1e}", m.residual))
                    .collect();
                eprintln!("arnoldi: backward errors {}", eta.join(" "));
            }
            if modes.iter().all(|md| md.converged) {
                let mut modes = modes;
                modes.sort_by(|a, b| a.s.0.hypot(a.s.1).total_cmp(&b.s.0.hypot(b.s.1)));
                return Ok(DampedModes {
                    modes,
                    solves: op.solves,
                    shift: sigma,
                });
            }
        }
        if op.solves >= budget || sp.v.len() >= 2 * free {
            return Err(SparseError::NoConvergence {
                converged: 0,
                count,
                solves: op.solves,
            });
        }
        if sp.v.len() + rem.len() > max_dim {
            let keep = (2 * count + block).min(ritz.len());
            let mut cols: Vec<Vec<f64>> = Vec::new();
            // The real and imaginary parts of one member of a pair span both.
            for &i in order.iter().take(keep) {
                let r = &ritz[i];
                cols.push(r.s.0.clone());
                if r.mu.1 != 0.0 {
                    cols.push(r.s.1.clone());
                }
            }
            let s = orthonormal_columns(cols, sp.v.len());
            sp = sp.restrict(&s);
        }
        if sp.extend(rem) == 0 {
            let fresh = random_block(&mut op, block)?;
            if sp.extend(fresh) == 0 {
                return Err(SparseError::NoConvergence {
                    converged: 0,
                    count,
                    solves: op.solves,
                });
            }
        }
    }
}

/// Orthonormal columns spanning `cols` (Gram–Schmidt twice, dependent ones dropped).
fn orthonormal_columns(cols: Vec<Vec<f64>>, m: usize) -> DMatrix<f64> {
    let mut out: Vec<Vec<f64>> = Vec::new();
    for mut x in cols {
        let n0 = norm(&x);
        for _ in 0..2 {
            for q in &out {
                let c = dot(q, &x);
                axpy(&mut x, -c, q);
            }
        }
        let n1 = norm(&x);
        if n1 > 1e-8 * n0 && n1 > 0.0 {
            x.iter_mut().for_each(|v| *v /= n1);
            out.push(x);
        }
    }
    DMatrix::from_fn(m, out.len(), |i, j| out[j][i])
}

/// The indices of the `count` wanted modes (`Im λ ≥ 0`, lowest `|λ|`) when the set is
/// complete and converged (module docs), else `None`.
fn wanted(
    ritz: &[Ritz],
    order: &[usize],
    count: usize,
    sigma: f64,
    lam: &dyn Fn(&Ritz) -> (f64, f64),
    converged: &dyn Fn(&Ritz) -> bool,
) -> Option<Vec<usize>> {
    // Modes: one per conjugate pair, Im λ ≥ 0 ⇔ Im μ ≤ 0.
    let mut modes: Vec<usize> = order
        .iter()
        .copied()
        .filter(|&i| ritz[i].mu.1 <= 0.0)
        .collect();
    if modes.len() <= count {
        return None;
    }
    let abs = |i: usize| {
        let l = lam(&ritz[i]);
        l.0.hypot(l.1)
    };
    modes.sort_by(|&a, &b| abs(a).total_cmp(&abs(b)));
    let sel: Vec<usize> = modes[..count].to_vec();
    let lc = abs(sel[count - 1]);
    let reach = 1.0 / (lc + sigma);
    let amu = |i: usize| ritz[i].mu.0.hypot(ritz[i].mu.1);
    let inside: Vec<usize> = order.iter().copied().filter(|&i| amu(i) >= reach).collect();
    if inside.len() >= order.len() {
        return None;
    }
    inside.iter().all(|&i| converged(&ritz[i])).then_some(sel)
}

/// The mode of Ritz pair `r` (`λ = lam`) with its quadratic residual relative to its
/// tolerance (≤ 1: converged).
fn mode_of(op: &StateOp, sp: &Space, r: &Ritz, lam: (f64, f64)) -> DampedMode {
    let nn = op.nn;
    let neq = op.sys.n_eq();
    let comb = |vs: &[Vec<f64>], s: &[f64], len: usize| {
        let mut y = vec![0.0; len];
        for (v, c) in vs.iter().zip(s) {
            if *c != 0.0 {
                axpy(&mut y, *c, &v[..len]);
            }
        }
        y
    };
    let unscale = |x: Vec<f64>| -> Vec<f64> { x.iter().zip(&op.dx).map(|(x, d)| x / d).collect() };
    let (xr, xi) = (
        unscale(comb(&sp.v, &r.s.0, nn)),
        unscale(comb(&sp.v, &r.s.1, nn)),
    );
    let nc = neq - nn;
    let (nr, ni) = if nc > 0 {
        (comb(&sp.nu, &r.s.0, nc), comb(&sp.nu, &r.s.1, nc))
    } else {
        (Vec::new(), Vec::new())
    };
    // Reaction ν/μ.
    let inv = cdiv((1.0, 0.0), r.mu);
    let react: (Vec<f64>, Vec<f64>) = (
        nr.iter()
            .zip(&ni)
            .map(|(a, b)| a * inv.0 - b * inv.1)
            .collect(),
        nr.iter()
            .zip(&ni)
            .map(|(a, b)| a * inv.1 + b * inv.0)
            .collect(),
    );
    let mat = &op.sys.matrix;
    // K [x; ν/μ] on all rows; C x, M x on nodal rows.
    let full = |x: &[f64], nu: &[f64], abs: bool| {
        let mut z = x.to_vec();
        z.extend_from_slice(nu);
        let mut y = vec![0.0; neq];
        pattern_mul(mat, op.k, &z, &mut y, neq, abs);
        y
    };
    let nodal = |a: &[f64], x: &[f64], abs: bool| {
        let mut y = vec![0.0; nn];
        pattern_mul(mat, a, &x[..nn], &mut y, nn, abs);
        y
    };
    let (kr, ki) = (full(&xr, &react.0, false), full(&xi, &react.1, false));
    let (cr, ci) = (nodal(op.c, &xr, false), nodal(op.c, &xi, false));
    let (mr, mi) = (nodal(op.m, &xr, false), nodal(op.m, &xi, false));
    let l2 = (lam.0 * lam.0 - lam.1 * lam.1, 2.0 * lam.0 * lam.1);
    let mut res2 = 0.0;
    for i in 0..neq {
        let (mut re, mut im) = (kr[i], ki[i]);
        if i < nn {
            re += lam.0 * cr[i] - lam.1 * ci[i] + l2.0 * mr[i] - l2.1 * mi[i];
            im += lam.0 * ci[i] + lam.1 * cr[i] + l2.0 * mi[i] + l2.1 * mr[i];
        }
        res2 += re * re + im * im;
    }
    let al = lam.0.hypot(lam.1);
    let xn = (dot(&xr, &xr) + dot(&xi, &xi)).sqrt();
    let (nk, nc, nm) = op.norms;
    let scale = (al * al * nm + al * nc + nk) * xn;
    let eta = if scale > 0.0 {
        res2.sqrt() / scale
    } else {
        0.0
    };
    // The shape: x turned so that its largest component is real.
    let (mut best, mut big) = (0, 0.0);
    for i in 0..nn {
        let v = xr[i].hypot(xi[i]);
        if v > big {
            (best, big) = (i, v);
        }
    }
    let rot = if big > 0.0 {
        (xr[best] / big, -xi[best] / big)
    } else {
        (1.0, 0.0)
    };
    let mut shape: Vec<f64> = (0..nn).map(|i| xr[i] * rot.0 - xi[i] * rot.1).collect();
    let sn = norm(&shape);
    if sn > 0.0 {
        shape.iter_mut().for_each(|v| *v /= sn);
    }
    DampedMode {
        s: lam,
        shape,
        residual: eta,
        converged: eta <= TOL_QUADRATIC,
    }
}
