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
    /// Projects `w` on the basis twice (Gram–Schmidt), returning the summed coefficients;
    /// `mw`, when given, is `M w` and is kept so (`M q` is stored: no product).
    pub(crate) fn project(&self, w: &mut [f64], mut mw: Option<&mut [f64]>) -> Vec<f64> {
        let mut coef = vec![0.0; self.q.len()];
        for _ in 0..2 {
            for (i, (q, mq)) in self.q.iter().zip(&self.mq).enumerate() {
                let c = dot(mq, w);
                axpy(w, -c, q);
                if let Some(mw) = mw.as_deref_mut() {
                    axpy(mw, -c, mq);
                }
                coef[i] += c;
            }
        }
        coef
    }

    /// `M`-orthonormalises `ws` (each with its mass image `M w`) against the basis and
    /// each other, appending those that are independent; returns how many were appended.
    pub(crate) fn extend(&mut self, ws: Vec<(Vec<f64>, Vec<f64>)>) -> usize {
        let mut added = 0;
        for (mut w, mut mw) in ws {
            let n0 = dot(&mw, &w).max(0.0).sqrt();
            self.project(&mut w, Some(&mut mw));
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

    /// `Σ_j s_j q_j` over the basis.
    pub(crate) fn combine(vs: &[Vec<f64>], s: impl Iterator<Item = f64>, n: usize) -> Vec<f64> {
        let mut y = vec![0.0; n];
        for (v, sj) in vs.iter().zip(s) {
            if sj != 0.0 {
                axpy(&mut y, sj, v);
            }
        }
        y
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
pub fn largest<O: ShiftInvert>(
    op: &mut O,
    count: usize,
) -> Result<(Vec<f64>, Vec<Vec<f64>>), O::Error> {
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
        let big = theta.iter().any(|&x| {
            theta
                .iter()
                .filter(|&&y| (x - y).abs() <= CLUSTER * x.abs())
                .count()
                >= block
        });
        if big && block < op.free() && block < 4 * BLOCK {
            block *= 2;
            continue;
        }
        return Ok((theta, basis));
    }
}

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
            let mut w = op.apply_mass(&q.mq[j].clone())?;
            let coef = q.project(&mut w, None);
            for (i, cf) in coef.into_iter().enumerate() {
                hn[(i, j)] = cf;
                if i < m_old {
                    hn[(j, i)] = cf;
                }
            }
            ws.push(w);
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
            idx.iter()
                .map(|&i| {
                    let s = eig.eigenvectors.column(i);
                    (
                        Basis::combine(&q.q, s.iter().copied(), nn),
                        Basis::combine(&q.mq, s.iter().copied(), nn),
                    )
                })
                .unzip()
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
