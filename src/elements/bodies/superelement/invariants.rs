//! The inertia invariants of a reduced body in its floating frame.
//!
//! The frame `(x₀, R)` is the frame node's; the FE dofs' velocities seen in it are
//! `w = A(q) ν`, `ν = [V; Ω; q̇]`, `V = Rᵀẋ₀` (Shabana, *Dynamics of Multibody Systems*,
//! 4th ed., §5.3; Cardona & Géradin, *Modeling of superelements in flexible multibody
//! systems*, Comput. Methods Appl. Mech. Eng. 1991):
//!
//! ```text
//!   translational dof of FE node p:  Rᵀẋ₀ + Ω × (s_p + u_p) + u̇_p,   u = Φ q
//!   rotational dof of FE node p:     Ω + θ̇_p,                      θ = Φ q
//! ```
//!
//! (`s_p = X_p − X_frame`; the rotational dofs' `Ω × θ` is of second order in the small
//! rotations and left out, as for solids without rotational dofs it does not arise). So
//! `A(q) = A₀ + Σ_k q_k A₁ₖ`, `A₀ = [A_V, A_Ω, Φ]`, `A₁ₖ` non-zero only in the three `Ω`
//! columns (`e_j × Φ_k` on translational rows), and the kinetic energy of the consistent
//! mass `M` is `T = ½ νᵀ 𝕄(q) ν` with
//!
//! ```text
//!   𝕄(q) = 𝕄₀ + [G(q) in the Ω columns] + [G(q)ᵀ in the Ω rows] + H(q, q) in the ΩΩ block,
//!   𝕄₀ = A₀ᵀ M A₀,   G(q) = Σ_k q_k G_k,  G_k = A₀ᵀ M A₁ₖ,   H(a, b) = Σ_kl a_k b_l A₁ₖᵀ M A₁ₗ.
//! ```
//!
//! `𝕄₀` holds the mass `m`, the first moment, the rotary inertia, the rigid–elastic
//! couplings and the reduced mass `ΦᵀMΦ`; `G` and `H` the first- and second-order
//! changes of the inertia with the deformation — Shabana's invariants, in the
//! form of Exudyn's `ObjectFFRFreducedOrder` (which, for solids, builds the same sums from
//! the mode shapes). Gravity derives from `U = −gᵀ(m x₀ + R c(q))`, `c(q) = c₀ + C₁ q` the
//! first moment (`c₀ = A_Vᵀ M s`, `C₁ = A_Vᵀ M Φ`), the consistent load of uniform gravity.

use super::fe::FeModel;
use super::reduce::Reduction;
use nalgebra::{Cholesky, DMatrix, Matrix3, Vector3};

/// A reduced body: what the element evaluates each iteration (sizes in elastic
/// coordinates `n`, independent of the mesh).
#[derive(Debug, Clone)]
pub struct Body {
    /// Elastic coordinates: 6 per non-frame interface node, then the modal amplitudes.
    pub n: usize,
    /// `𝕄₀`, `(6 + n)²`.
    pub m0: DMatrix<f64>,
    /// `[G_1 … G_n]`, `(6 + n) × 3n`.
    pub g: DMatrix<f64>,
    /// `[A₁ₖᵀ M A₁ₗ]`, `3n × 3n` (symmetric).
    pub h: DMatrix<f64>,
    /// Mass, kg.
    pub mass: f64,
    /// First moment about the frame node at rest, local, kg·m.
    pub c0: Vector3<f64>,
    /// Reduced stiffness `ΦᵀKΦ`, `n × n`.
    pub k: DMatrix<f64>,
    /// Positions of the other interface nodes relative to the frame node at rest, local.
    pub s_iface: Vec<Vector3<f64>>,
    /// The kept fixed-interface modes' `ω²`.
    pub omega2: Vec<f64>,
}

/// The mass matrix is not positive definite on the reduced basis.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the mass matrix is not positive definite on the reduced basis (rigid motions and kept modes): check M.mtx"
)]
pub struct MassNotPositive;

/// A mass matrix as the invariants use it: its products `M X` with tall dense blocks.
pub trait MassProduct {
    /// `M X`.
    fn times(&self, x: &DMatrix<f64>) -> DMatrix<f64>;
}

impl MassProduct for DMatrix<f64> {
    fn times(&self, x: &DMatrix<f64>) -> DMatrix<f64> {
        self * x
    }
}

impl MassProduct for super::mtx::SymMatrix {
    fn times(&self, x: &DMatrix<f64>) -> DMatrix<f64> {
        super::sparse::sym_mul_dense(self, x)
    }
}

impl Body {
    /// The invariants of `fe` (mass `m`, dense or the reader's sparse one) for the basis `red` about the frame node
    /// `frame_node` with the other interface nodes `iface`.
    pub fn new(
        fe: &FeModel,
        m: &impl MassProduct,
        red: &Reduction,
        frame_node: u32,
        iface: &[u32],
    ) -> Result<Body, MassNotPositive> {
        let nfe = fe.dofs.len();
        let n = red.basis.ncols();
        let x_f = fe.nodes[&frame_node];
        let s = |p: u32| fe.nodes[&p] - x_f;
        // A₀ = [A_V, A_Ω, Φ].
        let mut a0 = DMatrix::zeros(nfe, 6 + n);
        let mut svec = DMatrix::zeros(nfe, 1);
        for (r, &(p, c)) in fe.dofs.iter().enumerate() {
            let c = c as usize;
            if c < 3 {
                a0[(r, c)] = 1.0;
                let sp = s(p);
                svec[(r, 0)] = sp[c];
                for j in 0..3 {
                    a0[(r, 3 + j)] = Vector3::ith(j, 1.0).cross(&sp)[c];
                }
            } else {
                a0[(r, c)] = 1.0;
            }
        }
        a0.view_mut((0, 6), (nfe, n)).copy_from(&red.basis);
        // A₁ = [A₁₁ … A₁ₙ]: column 3k + j is e_j × Φ_k on translational rows.
        let mut a1 = DMatrix::zeros(nfe, 3 * n);
        // Each node's translational rows, found once (a search per node and mode is
        // quadratic in the mesh).
        let mut trans: indexmap::IndexMap<u32, [Option<usize>; 3]> =
            fe.nodes.keys().map(|&p| (p, [None; 3])).collect();
        for (r, &(p, c)) in fe.dofs.iter().enumerate() {
            if c < 3
                && let Some(t) = trans.get_mut(&p)
            {
                t[c as usize] = Some(r);
            }
        }
        for k in 0..n {
            for rows in trans.values() {
                let u = Vector3::from_fn(|c, _| rows[c].map_or(0.0, |r| red.basis[(r, k)]));
                if u == Vector3::zeros() {
                    continue;
                }
                for j in 0..3 {
                    let v = Vector3::ith(j, 1.0).cross(&u);
                    for c in 0..3 {
                        if let Some(r) = rows[c] {
                            a1[(r, 3 * k + j)] = v[c];
                        }
                    }
                }
            }
        }
        let ma0 = m.times(&a0);
        let ma1 = m.times(&a1);
        let sym = |x: DMatrix<f64>| (&x + x.transpose()) * 0.5;
        let m0 = sym(a0.transpose() * &ma0);
        Cholesky::new(m0.clone()).ok_or(MassNotPositive)?;
        let g = a0.transpose() * &ma1;
        let h = sym(a1.transpose() * &ma1);
        let mass = m0[(0, 0)];
        let c0v = ma0.columns(0, 3).transpose() * &svec;
        let c0 = Vector3::new(c0v[0], c0v[1], c0v[2]);
        Ok(Body {
            n,
            m0,
            g,
            h,
            mass,
            c0,
            k: red.k.clone(),
            s_iface: iface.iter().map(|&p| s(p)).collect(),
            omega2: red.omega2.clone(),
        })
    }

    /// The reduced free–free matrices `(𝕄₀, blockdiag(0₆, K))` of the body at rest: their
    /// generalised eigenvalues are the free body's (six zeros first).
    pub fn free_free(&self) -> (DMatrix<f64>, DMatrix<f64>) {
        let mut k = DMatrix::zeros(6 + self.n, 6 + self.n);
        k.view_mut((6, 6), (self.n, self.n)).copy_from(&self.k);
        (self.m0.clone(), k)
    }

    /// The first moment `c(q) = c₀ + C₁ q`, `C₁ = 𝕄₀[V, q]`.
    pub fn first_moment(&self, q: &[f64]) -> Vector3<f64> {
        let mut c = self.c0;
        for (k, qk) in q.iter().enumerate() {
            for i in 0..3 {
                c[i] += self.m0[(i, 6 + k)] * qk;
            }
        }
        c
    }

    /// `H(a, b) = Σ_kl a_k b_l H_kl`.
    pub fn h_of(&self, a: &[f64], b: &[f64]) -> Matrix3<f64> {
        let mut out = Matrix3::zeros();
        for k in 0..self.n {
            for l in 0..self.n {
                let w = a[k] * b[l];
                if w != 0.0 {
                    out += self.h.fixed_view::<3, 3>(3 * k, 3 * l) * w;
                }
            }
        }
        out
    }
}
