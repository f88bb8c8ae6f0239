//! Block Lanczos with full reorthogonalisation, thick-restarted, on a shift-invert operator
//! `T = (K − σM)⁻¹M` (Golub & Underwood 1977; Grimes, Lewis & Simon, SIAM J. Matrix Anal.
//! Appl. 15(1) 1994; Ericsson & Ruhe 1980 for the spectral transformation): the one
//! eigen-solver of the large models' modes (`modes::sparse`, the assembled model through its
//! sparse LU) and of the superelement's fixed-interface modes
//! (`elements::bodies::superelement::sparse`, `K_II⁻¹M_II` through a sparse Cholesky). Below
//! every stage (it knows no model, only the operator), as `lagrange.rs` is; the iteration is
//! described in `modes::sparse`'s docs, where it was first written.

use nalgebra::{DMatrix, SymmetricEigen};
use rand::{Rng, SeedableRng};

/// Why the iteration gave no modes.
#[derive(Debug, Clone, PartialEq)]
pub enum LanczosError {
    /// `T` maps every starting vector to zero: no mass.
    Massless,
    /// Not converged within the budget of solves.
    NoConvergence {
        /// Converged modes.
        converged: usize,
        /// Asked for.
        count: usize,
        /// Solves spent.
        solves: usize,
    },
}

/// Block size: a free body's six rigid motions (a cluster that fills the block doubles it).
pub const BLOCK: usize = 6;
/// Relative residual `‖T φ − θ φ‖_M ≤ TOL |θ|` of a converged Ritz pair. The eigenvalue's
/// error is below the residual's square over the gap (symmetric problem), below the residual
/// itself inside a cluster: 1e-9 keeps frequencies to ~1e-9 even for exact pairs, and the
/// Rayleigh quotient of the shape makes it smaller still.
pub const TOL: f64 = 1e-9;
/// Relative spread under which converged values are one cluster (a multiple eigenvalue).
pub const CLUSTER: f64 = 1e-6;

/// A vector whose norm (in the basis's inner product: `M` for the symmetric path, a scaled
/// Euclidean one for the first-order path) falls below this fraction of its norm before
/// projection is linearly dependent on the basis (after two Gram–Schmidt passes,
/// round-off leaves ~ε).
pub(crate) const DROP: f64 = 1e-10;

/// `aᵀb` with eight partial sums (a sequential sum does not vectorise: the
/// orthogonalisation, bound by these products, ran at a quarter of the speed).
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for ((s, x), y) in acc.iter_mut().zip(x).zip(y) {
            *s += x * y;
        }
    }
    acc.iter().sum::<f64>() + tail
}

/// `y += a x`.
pub(crate) fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    y.iter_mut().zip(x).for_each(|(y, x)| *y += a * x);
}

/// An `M`-orthonormal basis with the mass images of its vectors.
#[derive(Default)]
pub(crate) struct Basis {
    pub(crate) q: Vec<Vec<f64>>,
    pub(crate) mq: Vec<Vec<f64>>,
}

impl Basis {
    /// Projects the block `ws` on the basis twice (block classical Gram–Schmidt, CGS2:
    /// "twice is enough", Giraud, Langou & Rozložník, Comput. Math. Appl. 50, 2005),
    /// returning the summed coefficients `C` (basis × block): `w_j ← w_j − Σ_i c_ij q_i`
    /// with `c_ij = (M q_i)ᵀ w_j`. `mws`, when given, are the `M w_j` and are kept so
    /// (`M q` is stored: no product). The rows are swept in chunks that stay in cache with
    /// the whole block, so that each pass reads the basis once for the whole block (one
    /// vector at a time, the orthogonalisation was bound by memory traffic: 40 % of a
    /// 100,000-dof superelement's reduction).
    pub(crate) fn project_block(
        &self,
        ws: &mut [Vec<f64>],
        mws: Option<&mut [Vec<f64>]>,
    ) -> DMatrix<f64> {
        project_on(&self.q, &self.mq, ws, mws)
    }

    /// `M`-orthonormalises `ws` (each with its mass image `M w`) against the basis and
    /// each other, appending those that are independent; returns how many were appended.
    /// The block is projected on the basis at once ([`Basis::project_block`]), then each
    /// vector on those of the block appended before it.
    pub(crate) fn extend(&mut self, ws: Vec<(Vec<f64>, Vec<f64>)>) -> usize {
        let (mut w, mut mw): (Vec<Vec<f64>>, Vec<Vec<f64>>) = ws.into_iter().unzip();
        let n0: Vec<f64> = w
            .iter()
            .zip(&mw)
            .map(|(w, mw)| dot(mw, w).max(0.0).sqrt())
            .collect();
        self.project_block(&mut w, Some(&mut mw));
        let start = self.q.len();
        let mut added = 0;
        for ((mut w, mut mw), n0) in w.into_iter().zip(mw).zip(n0) {
            project_on(
                &self.q[start..],
                &self.mq[start..],
                std::slice::from_mut(&mut w),
                Some(std::slice::from_mut(&mut mw)),
            );
            let n1 = dot(&mw, &w).max(0.0).sqrt();
            if n1 <= DROP * n0 || n1 == 0.0 {
                continue;
            }
            w.iter_mut().for_each(|v| *v /= n1);
            self.mq.push(mw.into_iter().map(|v| v / n1).collect());
            self.q.push(w);
            added += 1;
        }
        added
    }

    /// `Y = V S`: column `k` of `Y` is `Σ_j s_jk v_j` (`S`: `vs.len()` × k). Swept in row
    /// chunks that stay in cache, as [`Basis::project_block`] (one combination at a time,
    /// a restart read the whole basis once per Ritz vector).
    pub(crate) fn combine(vs: &[Vec<f64>], s: &DMatrix<f64>, n: usize) -> Vec<Vec<f64>> {
        const CHUNK: usize = 2048;
        let mut ys = vec![vec![0.0; n]; s.ncols()];
        for r0 in (0..n).step_by(CHUNK) {
            let r1 = (r0 + CHUNK).min(n);
            for (j, v) in vs.iter().enumerate() {
                for (k, y) in ys.iter_mut().enumerate() {
                    let c = s[(j, k)];
                    if c != 0.0 {
                        axpy(&mut y[r0..r1], c, &v[r0..r1]);
                    }
                }
            }
        }
        ys
    }
}

/// A shift-invert operator `T = (K − σM)⁻¹ M` (on whatever constraints the factorisation
/// carries) that the block Lanczos of this module iterates on: the assembled model's
/// (`modes::sparse::lowest`) or a superelement's interior `K_II⁻¹ M_II` (`σ = 0`, its `θ = 1/ω²`).
pub trait ShiftInvert {
    /// The factorisation's errors, and the iteration's.
    type Error: From<LanczosError>;
    /// Length of the vectors.
    fn dim(&self) -> usize;
    /// Dimension of the space `T` acts on (the vectors' length less the constraints).
    fn free(&self) -> usize;
    /// `M x`.
    fn mass(&self, x: &[f64]) -> Vec<f64>;
    /// `T v` from `M v`.
    fn apply_mass(&mut self, mv: &[f64]) -> Result<Vec<f64>, Self::Error>;
    /// Applications of `T` so far.
    fn solves(&self) -> usize;
    /// `T v`.
    fn apply(&mut self, v: &[f64]) -> Result<Vec<f64>, Self::Error> {
        let mv = self.mass(v);
        self.apply_mass(&mv)
    }
}

/// The `count` eigenpairs of largest `|θ|` of `T` (`θ`, `M`-orthonormal vectors), by the
/// block Lanczos of this module at a fixed shift, the block doubled while a cluster of
/// converged values fills it (module docs).
pub fn largest<O: ShiftInvert>(op: &mut O, count: usize) -> Result<Eigenpairs, O::Error> {
    let mut block = BLOCK.min(count.max(1));
    loop {
        let (theta, basis) = match iterate(op, count, block, None)? {
            Outcome::Converged(theta, basis) => (theta, basis),
            Outcome::Probe(_) => {
                return Err(LanczosError::NoConvergence {
                    converged: 0,
                    count,
                    solves: op.solves(),
                }
                .into());
            }
        };
        let big = cluster_fills(&theta, block);
        if big && block < op.free() && block < 4 * BLOCK {
            block *= 2;
            continue;
        }
        return Ok((theta, basis));
    }
}

/// Whether a cluster of `theta` (values within [`CLUSTER`]) is as large as the block: it
/// may hide more copies, and the block is doubled.
pub(crate) fn cluster_fills(theta: &[f64], block: usize) -> bool {
    theta.iter().any(|&x| {
        theta
            .iter()
            .filter(|&&y| (x - y).abs() <= CLUSTER * x.abs())
            .count()
            >= block
    })
}

/// Ritz values and their `M`-orthonormal vectors.
pub type Eigenpairs = (Vec<f64>, Vec<Vec<f64>>);

/// What [`iterate`] ends with.
pub enum Outcome {
    /// The `count` Ritz values of largest `|θ|` and their vectors (`M`-orthonormal).
    Converged(Vec<f64>, Vec<Vec<f64>>),
    /// Asked to probe: the basis filled once without convergence, and the wanted modes
    /// lie far below the shift; the better shift.
    Probe(f64),
}

/// Block Lanczos (the module docs of `modes::sparse`) until the `count` Ritz values of largest `|θ|` converge,
/// or, with `probe = Some((σ, floor))`, until the basis first fills if the wanted modes
/// then lie far below the shift `σ` (more than 10 times closer to 0).
pub fn iterate<O: ShiftInvert>(
    op: &mut O,
    count: usize,
    block: usize,
    probe: Option<(f64, f64)>,
) -> Result<Outcome, O::Error> {
    let nn = op.dim();
    let free = op.free();
    let max_dim = (3 * count).max(count + 3 * block).max(30).min(free);
    let budget = op.solves() + 40 * count + 400;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(24);
    type Pairs = Vec<(Vec<f64>, Vec<f64>)>;
    let mut random_block = |op: &mut O, b: usize| -> Result<Pairs, O::Error> {
        (0..b)
            .map(|_| {
                let r: Vec<f64> = (0..nn).map(|_| rng.random::<f64>() - 0.5).collect();
                let w = op.apply(&r)?;
                let mw = op.mass(&w);
                Ok((w, mw))
            })
            .collect()
    };
    let mut q = Basis::default();
    let start = random_block(op, block)?;
    q.extend(start);
    if q.q.is_empty() {
        return Err(LanczosError::Massless.into());
    }
    // H on the expanded vectors (the first `h.nrows()` of the basis).
    let mut h = DMatrix::<f64>::zeros(0, 0);
    loop {
        let m_all = q.q.len();
        let m_old = h.nrows();
        let pending: Vec<usize> = (m_old..m_all).collect();
        let mut ws = Vec::with_capacity(pending.len());
        let mut hn = DMatrix::<f64>::zeros(m_all, m_all);
        hn.view_mut((0, 0), (m_old, m_old)).copy_from(&h);
        for &j in &pending {
            ws.push(op.apply_mass(&q.mq[j].clone())?);
        }
        let coef = q.project_block(&mut ws, None);
        for (a, &j) in pending.iter().enumerate() {
            for i in 0..m_all {
                hn[(i, j)] = coef[(i, a)];
                if i < m_old {
                    hn[(j, i)] = coef[(i, a)];
                }
            }
        }
        let h_sym = (&hn + hn.transpose()) * 0.5;
        h = h_sym.clone();
        // Gram matrix of the remainders, for the residuals (their mass images serve the
        // next extension too).
        let mws: Vec<Vec<f64>> = ws.iter().map(|w| op.mass(w)).collect();
        let g = DMatrix::from_fn(ws.len(), ws.len(), |a, b| dot(&mws[a], &ws[b]));
        let eig = SymmetricEigen::new(h_sym);
        let mut order: Vec<usize> = (0..m_all).collect();
        order.sort_by(|&a, &b| {
            eig.eigenvalues[b]
                .abs()
                .total_cmp(&eig.eigenvalues[a].abs())
        });
        let wanted = count.min(m_all);
        let converged = order[..wanted]
            .iter()
            .filter(|&&i| {
                let s = eig.eigenvectors.column(i);
                let sp = DMatrix::from_fn(pending.len(), 1, |a, _| s[pending[a]]);
                let r2 = (sp.transpose() * &g * &sp)[(0, 0)].max(0.0);
                r2.sqrt() <= TOL * eig.eigenvalues[i].abs()
            })
            .count();
        let ritz = |idx: &[usize]| -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
            let sel = DMatrix::from_fn(m_all, idx.len(), |j, k| eig.eigenvectors[(j, idx[k])]);
            (
                Basis::combine(&q.q, &sel, nn),
                Basis::combine(&q.mq, &sel, nn),
            )
        };
        if converged == count {
            let theta = order[..count].iter().map(|&i| eig.eigenvalues[i]).collect();
            return Ok(Outcome::Converged(theta, ritz(&order[..count]).0));
        }
        if op.solves() >= budget || m_all >= free {
            return Err(LanczosError::NoConvergence {
                converged,
                count,
                solves: op.solves(),
            }
            .into());
        }
        // Restart on the best Ritz vectors when the next block would not fit.
        if m_all + pending.len() > max_dim {
            // (With fewer Ritz values than modes asked for there is no count-th one to
            // bound with: the fuzzer's case 19:16501 indexed past them and panicked.)
            if let Some((sigma, floor)) = probe.filter(|_| m_all >= count) {
                // The count-th Ritz value bounds the count-th mode: θ_c(Ritz) ≤ θ_c, so
                // ω²_c ≤ 1/θ_c(Ritz) + σ (Cauchy interlacing). When the wanted modes lie
                // far below |σ|, their θ crowd at 1/|σ| and separate slowly: shift to
                // half that bound, kept above the round-off of K (`floor`).
                let bound = 1.0 / eig.eigenvalues[order[count - 1]] + sigma;
                let target = -(0.5 * bound).max(floor);
                if target > 0.1 * sigma {
                    return Ok(Outcome::Probe(target));
                }
            }
            let keep: Vec<usize> = order[..(count + block).min(m_all)].to_vec();
            let (vq, vmq) = ritz(&keep);
            q = Basis { q: vq, mq: vmq };
            h = DMatrix::from_fn(keep.len(), keep.len(), |a, b| {
                if a == b {
                    eig.eigenvalues[keep[a]]
                } else {
                    0.0
                }
            });
        }
        let added = q.extend(ws.into_iter().zip(mws).collect());
        if added == 0 {
            // An invariant subspace: continue from fresh random vectors.
            let fresh = random_block(op, block)?;
            if q.extend(fresh) == 0 {
                return Err(LanczosError::NoConvergence {
                    converged,
                    count,
                    solves: op.solves(),
                }
                .into());
            }
        }
    }
}

/// [`Basis::project_block`] on the basis `(q, mq)`.
fn project_on(
    q: &[Vec<f64>],
    mq: &[Vec<f64>],
    ws: &mut [Vec<f64>],
    mut mws: Option<&mut [Vec<f64>]>,
) -> DMatrix<f64> {
    const CHUNK: usize = 2048;
    let (m, b) = (q.len(), ws.len());
    let n = ws.first().map_or(0, Vec::len);
    let mut total = DMatrix::zeros(m, b);
    if m == 0 || b == 0 {
        return total;
    }
    for _ in 0..2 {
        let mut c = DMatrix::<f64>::zeros(m, b);
        for r0 in (0..n).step_by(CHUNK) {
            let r1 = (r0 + CHUNK).min(n);
            for (i, mq) in mq.iter().enumerate() {
                for (j, w) in ws.iter().enumerate() {
                    c[(i, j)] += dot(&mq[r0..r1], &w[r0..r1]);
                }
            }
        }
        for r0 in (0..n).step_by(CHUNK) {
            let r1 = (r0 + CHUNK).min(n);
            for i in 0..m {
                for (j, w) in ws.iter_mut().enumerate() {
                    axpy(&mut w[r0..r1], -c[(i, j)], &q[i][r0..r1]);
                }
                if let Some(mws) = mws.as_deref_mut() {
                    for (j, mw) in mws.iter_mut().enumerate() {
                        axpy(&mut mw[r0..r1], -c[(i, j)], &mq[i][r0..r1]);
                    }
                }
            }
        }
        total += c;
    }
    total
}
