//! Kinematic joints with Lagrange multipliers: `HINGE`, `UJOINT`, `SPHERICAL`, `CLAMP`,
//! `PRISMATIC` and `RIGID` (Géradin & Cardona 2001, ch. 5–6; Cardona & Géradin 1989).
//!
//! # Constraints (index 3, position level)
//! A joint joins node 1 (position `x₁`, orientation `R₁`) and node 2 (`x₂`, `R₂`). The
//! joint point is node 1's position; node 2 reaches it through the offset `c₂`, constant in
//! node 2's material frame (`c₂ = x₁⁰ − x₂⁰`, zero when the nodes coincide). All frames are
//! the global frame at t = 0 (every node starts with `R = I`), so the axes of the deck are
//! the material axes of both nodes. With `d = x₂ + R₂ c₂ − x₁` (relative translation) and
//! `(p, q, a)` an orthonormal triad built on the joint axis `a`:
//!
//! | joint | equations `Φ = 0` | count |
//! | --- | --- | --- |
//! | `SPHERICAL` | `d = 0` | 3 |
//! | `HINGE` (axis `a`) | `d = 0`, `(R₁p)·(R₂a) = 0`, `(R₁q)·(R₂a) = 0` | 5 |
//! | `UJOINT` (`a₁` on node 1, `a₂` on node 2) | `d = 0`, `(R₁a₁)·(R₂a₂) = 0` | 4 |
//! | `CLAMP` | `d = 0`, `axial(skew(R₁ᵀR₂)) = 0` | 6 |
//! | `PRISMATIC` (axis `a`) | `axial(skew(R₁ᵀR₂)) = 0`, `(R₁p)·d = 0`, `(R₁q)·d = 0` | 5 |
//! | `RIGID` (nodes `n₁ … n_k`) | a `CLAMP` (with offset) of each `nᵢ`, `i ≥ 2`, to `n₁` | 6(k−1) |
//!
//! `axial(skew(Q)) = ½(Q₃₂−Q₂₃, Q₁₃−Q₃₁, Q₂₁−Q₁₂)` is `sin θ n` for a relative rotation of
//! angle θ about `n`: zero exactly at `Q = I` in the neighbourhood of the solution, with
//! the identity as Jacobian there.
//!
//! # Residual and iteration matrix (augmented Lagrangian, paper eq. [14]–[15])
//! With `B = ∂Φ/∂[δx₁, δΘ₁, δx₂, δΘ₂]` (material spins), `s` the constraint scale, `p` the
//! penalty and `λ̂` the element's scaled multipliers (true multipliers `λ = s λ̂`):
//! nodal rows `Bᵀ(s λ̂ + p Φ)`, multiplier rows `s Φ`; iteration matrix
//! `[K_g(μ) + p BᵀB, s Bᵀ; s B, 0]` with `μ = sλ̂ + pΦ` and the geometric stiffness
//! `K_g(μ) = ∂(Bᵀμ)/∂q` at fixed μ. `Bᵀμ` is written out analytically in the material
//! spins (`Joint::grad`, generic in the scalar); `B` and `K_g(μ) + p BᵀB` are its exact
//! derivatives by forward-mode automatic differentiation with the fixed-size
//! [`Dual<12>`](crate::dual::Dual) (seeding `R (I + δΘ̃)`: `∂[B(R exp(ε̃))ᵀμ]/∂ε` is the exact
//! Lie-group second derivative `∂²Φ(R exp(ε̃) exp(η̃))/∂ε∂η`), checked against finite
//! differences in the tests.
//!
//! # Outputs (`element_<N>.csv`, reactions in the global frame)
//! The reaction is the force `F` and moment `M` (about the joint point) that the joint
//! exerts on node 2's body, from the multipliers: `F = −(Bᵀμ)_{x₂}`,
//! `M = R₂(−(Bᵀμ)_{Θ₂}) − (R₂c₂) × F` (node 1's body receives the opposite).
//! - `HINGE`: `angle` (rotation of node 2 relative to node 1 about the axis, rad,
//!   continuous past ±π: whole turns are counted), `fx fy fz mx my mz`.
//! - `UJOINT`: `angle1` (about `a₁`, of the cross relative to node 1), `angle2` (about
//!   `a₂`, of node 2 relative to the cross), `bend` (angle between the two shaft axes
//!   `Rᵢ(a₁×a₂)`, rad; `cos bend = cos angle1 · cos angle2`), `fx … mz`.
//! - `SPHERICAL`, `CLAMP`: `fx … mz`; `PRISMATIC`: `slide` (d·R₁a, m), `fx … mz`;
//!   `RIGID`: `fx … mz` for each node after the first.
//!
//! # The universal joint at 90°
//! The four equations above have a Jacobian of full rank in every configuration (`B_Θ₁ =
//! a₁ × R₁ᵀR₂a₂` vanishes only when `R₂a₂ ∥ R₁a₁`, which violates `Φ = 0`), and the joint's
//! configuration space is the torus `R₁ᵀR₂ = exp(θ₁ã₁) exp(θ₂ã₂)`, so the equations never
//! degenerate. What degenerates at a bend of 90° (the shafts `R₁(a₁×a₂)`, `R₂(a₁×a₂)`
//! perpendicular) is the transmission: the joint can no longer carry a torque about the
//! shaft axes, and a driveline through it loses rank. The joint watches `|cos bend|`: when
//! it falls below [`UJOINT_SINGULAR_COS`] at an accepted step, the element records it
//! (`summary.json`: `singular_passages`, `first_singular_time`, `min_abs_cos_bend`), writes a
//! warning once to standard error, and [`Joint::singularity`] returns the diagnosis (for the
//! solver to append to a failure).

use super::{BuildError, Element, ElementState, EvalContext, Local, NodeState, StateMismatch};
use crate::dual::{Dual, Real};
use crate::model::{self, ElementId, ElementKind, Model};
use crate::rotation::{self, c, skew};
use crate::rotation::{mm, mtm, mtv, mv};
use nalgebra::{Matrix3, Vector3};

/// `|cos bend|` below which a universal joint is reported singular (bend within ~0.57° of
/// 90°).
pub const UJOINT_SINGULAR_COS: f64 = 1e-2;

/// The constraint type of a joint, with its axes (material frames = global at t = 0).
#[derive(Debug, Clone, PartialEq)]
pub enum JointType {
    /// `d = 0`.
    Spherical,
    /// `d = 0`, `(R₁p)·(R₂a) = (R₁q)·(R₂a) = 0`.
    Hinge {
        /// First normal to the axis.
        p: Vector3<f64>,
        /// Second normal, `q = a × p`.
        q: Vector3<f64>,
        /// Hinge axis (unit).
        a: Vector3<f64>,
    },
    /// `d = 0`, `(R₁a₁)·(R₂a₂) = 0`.
    UJoint {
        /// Axis on node 1.
        a1: Vector3<f64>,
        /// Axis on node 2.
        a2: Vector3<f64>,
        /// `a₁ × a₂` (unit): the shaft direction of both nodes at t = 0.
        b: Vector3<f64>,
    },
    /// `d = 0`, `axial(skew(R₁ᵀR₂)) = 0`.
    Clamp,
    /// `axial(skew(R₁ᵀR₂)) = 0`, `(R₁p)·d = (R₁q)·d = 0`.
    Prismatic {
        /// First normal to the axis.
        p: Vector3<f64>,
        /// Second normal.
        q: Vector3<f64>,
        /// Sliding axis (unit).
        a: Vector3<f64>,
    },
    /// Clamps of every node to the first.
    Rigid,
}

impl JointType {
    /// Equations per node pair.
    pub fn equations(&self) -> usize {
        match self {
            JointType::Spherical => 3,
            JointType::Hinge { .. } | JointType::Prismatic { .. } => 5,
            JointType::UJoint { .. } => 4,
            JointType::Clamp | JointType::Rigid => 6,
        }
    }

    fn keyword(&self) -> &'static str {
        match self {
            JointType::Spherical => "SPHERICAL",
            JointType::Hinge { .. } => "HINGE",
            JointType::UJoint { .. } => "UJOINT",
            JointType::Clamp => "CLAMP",
            JointType::Prismatic { .. } => "PRISMATIC",
            JointType::Rigid => "RIGID",
        }
    }
}

/// One constrained node pair of a joint: local node indices and node 2's offset.
#[derive(Debug, Clone, PartialEq)]
struct Pair {
    a: usize,
    b: usize,
    /// Offset from node `b` to the joint point (node `a`'s position), `b`'s material frame.
    c2: Vector3<f64>,
}

/// History of a joint (angles counted across ±π, universal-joint singularity watch).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
struct History {
    angles: [f64; 2],
    singular_passages: u64,
    first_singular_time: Option<f64>,
    min_abs_cos_bend: Option<f64>,
    in_singular: bool,
}

/// The history of a [`Joint`] (last angles, passages through a universal joint's
/// singular configuration), for checkpoints.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JointState(History);

/// A joint element (any [`JointType`]).
#[derive(Debug, Clone)]
pub struct Joint {
    id: ElementId,
    kind: JointType,
    nodes: Vec<usize>,
    pairs: Vec<Pair>,
    hist: History,
}

/// An orthonormal pair `(p, q)` with `(p, q, a)` right-handed.
pub fn normals(a: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let a = a.normalize();
    let k = if a.x.abs() <= a.y.abs() && a.x.abs() <= a.z.abs() {
        Vector3::x()
    } else if a.y.abs() <= a.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let p = (k - a * a.dot(&k)).normalize();
    (p, a.cross(&p))
}

/// Wraps an angle to (−π, π].
fn wrap(x: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let mut y = x % t;
    if y > std::f64::consts::PI {
        y -= t;
    } else if y <= -std::f64::consts::PI {
        y += t;
    }
    y
}

/// Is this element kind a joint built by this module?
pub fn is_joint(kind: &ElementKind) -> bool {
    matches!(
        kind,
        ElementKind::Hinge { .. }
            | ElementKind::UJoint { .. }
            | ElementKind::Spherical
            | ElementKind::Clamp
            | ElementKind::Prismatic { .. }
            | ElementKind::Rigid
    )
}

type D12 = Dual<12>;

/// `a·b`, unrolled.
#[inline(always)]
fn dot<S: Real>(a: &Vector3<S>, b: &Vector3<S>) -> S {
    a.x * b.x + a.y * b.y + a.z * b.z
}

impl Joint {
    /// A joint of type `kind` on dense nodes `nodes` with reference positions `x0`.
    pub fn new(
        id: ElementId,
        kind: JointType,
        nodes: Vec<usize>,
        x0: &[Vector3<f64>],
    ) -> Result<Self, BuildError> {
        let invalid = |message: String| BuildError::Invalid {
            element: id,
            message,
        };
        if nodes.len() < 2 || x0.len() != nodes.len() {
            return Err(invalid(format!("{} needs two nodes", kind.keyword())));
        }
        if !matches!(kind, JointType::Rigid) && nodes.len() != 2 {
            return Err(invalid(format!(
                "{} joins exactly two nodes",
                kind.keyword()
            )));
        }
        for i in 0..nodes.len() {
            for j in 0..i {
                if nodes[i] == nodes[j] {
                    return Err(invalid(format!(
                        "{} joins a node to itself",
                        kind.keyword()
                    )));
                }
            }
        }
        let pairs = (1..nodes.len())
            .map(|k| Pair {
                a: 0,
                b: k,
                c2: x0[0] - x0[k],
            })
            .collect();
        Ok(Joint {
            id,
            kind,
            nodes,
            pairs,
            hist: History::default(),
        })
    }

    /// Builds the joint of a model element.
    pub fn from_model(model: &Model, el: &model::Element) -> Result<Self, BuildError> {
        let idx: Vec<usize> = el
            .nodes
            .iter()
            .map(|id| {
                model
                    .nodes
                    .get_index_of(id)
                    .expect("validated model: nodes exist")
            })
            .collect();
        let x0: Vec<Vector3<f64>> = idx.iter().map(|&i| model.nodes[i].position).collect();
        let bad_axis = |v: &Vector3<f64>| !(v.norm() > 0.0 && v.iter().all(|c| c.is_finite()));
        let invalid = |m: &str| BuildError::Invalid {
            element: el.id,
            message: m.to_string(),
        };
        let kind = match &el.kind {
            ElementKind::Hinge { axis } | ElementKind::Prismatic { axis } => {
                if bad_axis(axis) {
                    return Err(invalid("the axis must be non-zero and finite"));
                }
                let a = axis.normalize();
                let (p, q) = normals(&a);
                if matches!(el.kind, ElementKind::Hinge { .. }) {
                    JointType::Hinge { p, q, a }
                } else {
                    JointType::Prismatic { p, q, a }
                }
            }
            ElementKind::UJoint { axis1, axis2 } => {
                if bad_axis(axis1) || bad_axis(axis2) {
                    return Err(invalid("the axes must be non-zero and finite"));
                }
                let (a1, a2) = (axis1.normalize(), axis2.normalize());
                if a1.dot(&a2).abs() > 1e-6 {
                    return Err(invalid("AXIS1 and AXIS2 must be perpendicular"));
                }
                // Exactly perpendicular (remove the tolerated residue from a2).
                let a2 = (a2 - a1 * a1.dot(&a2)).normalize();
                JointType::UJoint {
                    a1,
                    a2,
                    b: a1.cross(&a2),
                }
            }
            ElementKind::Spherical => JointType::Spherical,
            ElementKind::Clamp => JointType::Clamp,
            ElementKind::Rigid => JointType::Rigid,
            other => return Err(invalid(&format!("{} is not a joint", other.keyword()))),
        };
        Joint::new(el.id, kind, idx, &x0)
    }

    /// The joint type.
    pub fn kind(&self) -> &JointType {
        &self.kind
    }

    fn m_pair(&self) -> usize {
        self.kind.equations()
    }

    /// The constraint functions of one pair, generic in the scalar.
    fn phi<S: Real>(
        &self,
        pair: &Pair,
        x1: &Vector3<S>,
        r1: &Matrix3<S>,
        x2: &Vector3<S>,
        r2: &Matrix3<S>,
    ) -> [S; 6] {
        let v = |w: &Vector3<f64>| -> Vector3<S> { w.map(c) };
        let d = x2 + mv(r2, &v(&pair.c2)) - x1;
        let z = S::zero();
        let rot = || rotation::axial(&mtm(r1, r2));
        match &self.kind {
            JointType::Spherical => [d.x, d.y, d.z, z, z, z],
            JointType::Hinge { p, q, a } => {
                let ra = mv(r2, &v(a));
                [
                    d.x,
                    d.y,
                    d.z,
                    dot(&mv(r1, &v(p)), &ra),
                    dot(&mv(r1, &v(q)), &ra),
                    z,
                ]
            }
            JointType::UJoint { a1, a2, .. } => {
                [d.x, d.y, d.z, dot(&mv(r1, &v(a1)), &mv(r2, &v(a2))), z, z]
            }
            JointType::Clamp | JointType::Rigid => {
                let w = rot();
                [d.x, d.y, d.z, w.x, w.y, w.z]
            }
            JointType::Prismatic { p, q, .. } => {
                let w = rot();
                [
                    w.x,
                    w.y,
                    w.z,
                    dot(&mv(r1, &v(p)), &d),
                    dot(&mv(r1, &v(q)), &d),
                    z,
                ]
            }
        }
    }

    fn phi_f64(&self, pair: &Pair, s1: &NodeState, s2: &NodeState) -> [f64; 6] {
        self.phi(pair, &s1.x, &s1.r, &s2.x, &s2.r)
    }

    /// The generalized constraint force `Bᵀμ` of one pair, `[x₁, Θ₁, x₂, Θ₂]` (material
    /// spins), written out analytically and generic in the scalar. With `Q = R₁ᵀR₂` and the
    /// variations `δx`, `δR = R δΘ̃`:
    /// - `d = x₂ + R₂c₂ − x₁`: `δd = δx₂ − δx₁ − R₂ c̃₂ δΘ₂`, so `μ_d` gives
    ///   `(−μ_d, 0, μ_d, c₂ × R₂ᵀμ_d)`;
    /// - `(R₁u)·(R₂v)`: `δΘ₁·(u × Qv) + δΘ₂·(v × Qᵀu)`;
    /// - `(R₁u)·d`: `δΘ₁·(u × R₁ᵀd) + (R₁u)·δd`;
    /// - `w = axial(skew Q)`: `δQ = −δΘ̃₁Q + QδΘ̃₂` and `axial(ω̃A + Aᵀω̃) = (tr A I − A)ω`
    ///   give `δw = ½(tr Q I − Qᵀ)δΘ₂ − ½(tr Q I − Q)δΘ₁`.
    #[allow(clippy::too_many_arguments)]
    fn grad<S: Real>(
        &self,
        pair: &Pair,
        x1: &Vector3<S>,
        r1: &Matrix3<S>,
        x2: &Vector3<S>,
        r2: &Matrix3<S>,
        mu: &[S; 6],
    ) -> [S; 12] {
        let v = |w: &Vector3<f64>| -> Vector3<S> { w.map(c) };
        let c2 = v(&pair.c2);
        let q = mtm(r1, r2);
        let zero = Vector3::<S>::zeros();
        // Multipliers of `d` (global) and of `axial(skew Q)`, and the dot-product terms.
        let first = Vector3::new(mu[0], mu[1], mu[2]);
        let (md, mw, mut gt1, mut gt2) = match &self.kind {
            JointType::Spherical => (first, None, zero, zero),
            JointType::Hinge { p, q: qq, a } => {
                let u = v(p) * mu[3] + v(qq) * mu[4];
                let a = v(a);
                (first, None, u.cross(&mv(&q, &a)), a.cross(&mtv(&q, &u)))
            }
            JointType::UJoint { a1, a2, .. } => {
                let (u, w) = (v(a1) * mu[3], v(a2));
                (first, None, u.cross(&mv(&q, &w)), w.cross(&mtv(&q, &u)))
            }
            JointType::Clamp | JointType::Rigid => {
                (first, Some(Vector3::new(mu[3], mu[4], mu[5])), zero, zero)
            }
            JointType::Prismatic { p, q: qq, .. } => {
                let u = v(p) * mu[3] + v(qq) * mu[4];
                let d = x2 + mv(r2, &c2) - x1;
                (mv(r1, &u), Some(first), u.cross(&mtv(r1, &d)), zero)
            }
        };
        if let Some(mw) = mw {
            let tr = q[(0, 0)] + q[(1, 1)] + q[(2, 2)];
            let h = c::<S>(0.5);
            gt1 -= (mw * tr - mtv(&q, &mw)) * h;
            gt2 += (mw * tr - mv(&q, &mw)) * h;
        }
        gt2 += c2.cross(&mtv(r2, &md));
        let (gx1, gx2) = (-md, md);
        [
            gx1.x, gx1.y, gx1.z, gt1.x, gt1.y, gt1.z, gx2.x, gx2.y, gx2.z, gt2.x, gt2.y, gt2.z,
        ]
    }

    /// `Φ` and `Bᵀμ` of one pair at the nodes' state, `μ = s λ̂ + p Φ`.
    fn forces_f64(
        &self,
        pair: &Pair,
        s1: &NodeState,
        s2: &NodeState,
        ctx: &EvalContext,
        lam: &[f64],
    ) -> ([f64; 6], [f64; 12]) {
        let phi = self.phi_f64(pair, s1, s2);
        let mut mu = [0.0; 6];
        for (i, m) in mu.iter_mut().enumerate().take(self.m_pair()) {
            *m = ctx.constraint_scale * lam.get(i).copied().unwrap_or(0.0) + ctx.penalty * phi[i];
        }
        (phi, self.grad(pair, &s1.x, &s1.r, &s2.x, &s2.r, &mu))
    }

    /// `Φ` and `Bᵀμ` of one pair with their exact derivatives along `[δx₁, δΘ₁, δx₂, δΘ₂]`
    /// (12 dual directions, seeding `R (I + δΘ̃)`): `Φ.eps = B`, and, since `μ = sλ̂ + pΦ`
    /// is itself dual, `(Bᵀμ).eps = K_g(μ) + p BᵀB`.
    fn forces_dual(
        &self,
        pair: &Pair,
        s1: &NodeState,
        s2: &NodeState,
        ctx: &EvalContext,
        lam: &[f64],
    ) -> ([D12; 6], [D12; 12]) {
        let xs = |x: &Vector3<f64>, base: usize| {
            Vector3::new(
                D12::var(x.x, base),
                D12::var(x.y, base + 1),
                D12::var(x.z, base + 2),
            )
        };
        let rs = |r: &Matrix3<f64>, base: usize| {
            // R (I + δΘ̃): exact to first order, which is all a dual number carries.
            let dth = Vector3::new(
                D12::var(0.0, base),
                D12::var(0.0, base + 1),
                D12::var(0.0, base + 2),
            );
            let rr: Matrix3<D12> = r.map(D12::constant);
            rr + mm(&rr, &skew(&dth))
        };
        let (x1, r1, x2, r2) = (xs(&s1.x, 0), rs(&s1.r, 3), xs(&s2.x, 6), rs(&s2.r, 9));
        let phi = self.phi(pair, &x1, &r1, &x2, &r2);
        let mut mu = [D12::constant(0.0); 6];
        for (i, m) in mu.iter_mut().enumerate().take(self.m_pair()) {
            *m = phi[i] * D12::constant(ctx.penalty) + D12::constant(ctx.constraint_scale * lam[i]);
        }
        (phi, self.grad(pair, &x1, &r1, &x2, &r2, &mu))
    }

    /// Local index of entry `j` (0..12) of a pair's `[x₁, Θ₁, x₂, Θ₂]` vector.
    fn local(pair: &Pair, j: usize) -> usize {
        if j < 6 {
            6 * pair.a + j
        } else {
            6 * pair.b + j - 6
        }
    }

    /// `(F, M)`: reaction force and moment (about the joint point, global) exerted on node
    /// `b` of each pair, from the multipliers (`μ = s λ̂ + p Φ`).
    pub fn reactions(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
    ) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        (0..self.pairs.len())
            .map(|k| self.reaction(k, ctx, nodes, lambda))
            .collect()
    }

    /// The reaction of pair `k` (see [`Self::reactions`]).
    fn reaction(
        &self,
        k: usize,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
    ) -> (Vector3<f64>, Vector3<f64>) {
        let m = self.m_pair();
        let pair = &self.pairs[k];
        let (s1, s2) = (&nodes[self.nodes[pair.a]], &nodes[self.nodes[pair.b]]);
        let lam = lambda.get(k * m..(k + 1) * m).unwrap_or(&[]);
        let (_, g) = self.forces_f64(pair, s1, s2, ctx, lam);
        let f = -Vector3::new(g[6], g[7], g[8]);
        let mom = s2.r * -Vector3::new(g[9], g[10], g[11]) - (s2.r * pair.c2).cross(&f);
        (f, mom)
    }

    /// Joint angles: HINGE relative angle in (−π, π]; UJOINT `(θ₁, θ₂, cos bend)`.
    fn raw_angles(&self, nodes: &[NodeState]) -> [f64; 3] {
        let (s1, s2) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let q = s1.r.transpose() * s2.r;
        match &self.kind {
            JointType::Hinge { p, q: qq, .. } => {
                let rp = q * p;
                [qq.dot(&rp).atan2(p.dot(&rp)), 0.0, 0.0]
            }
            JointType::UJoint { a1, a2, b } => {
                let qa2 = q * a2;
                let qta1 = q.transpose() * a1;
                let t1 = b.dot(&qa2).atan2(a2.dot(&qa2));
                let t2 = b.dot(&qta1).atan2(a1.dot(&qta1));
                [t1, t2, b.dot(&(q * b))]
            }
            _ => [0.0; 3],
        }
    }

    /// Angles unwrapped against the last committed ones.
    fn angles(&self, nodes: &[NodeState]) -> [f64; 3] {
        let r = self.raw_angles(nodes);
        let a = &self.hist.angles;
        [a[0] + wrap(r[0] - a[0]), a[1] + wrap(r[1] - a[1]), r[2]]
    }

    /// The diagnosis of a universal joint near its singular configuration (bend within
    /// `acos(UJOINT_SINGULAR_COS)` of 90°) at this state, or `None`.
    pub fn singularity(&self, nodes: &[NodeState]) -> Option<String> {
        if !matches!(self.kind, JointType::UJoint { .. }) {
            return None;
        }
        let [t1, t2, cb] = self.raw_angles(nodes);
        (cb.abs() < UJOINT_SINGULAR_COS).then(|| {
            format!(
                "{} (UJOINT) is at its singular configuration: the shafts are perpendicular (bend {:.2}°, \
                 joint angles {:.2}°, {:.2}°); the joint cannot transmit a torque about the shaft axes \
                 and a driveline through it loses a degree of freedom",
                self.id,
                cb.clamp(-1.0, 1.0).acos().to_degrees(),
                t1.to_degrees(),
                t2.to_degrees()
            )
        })
    }
}

impl Element for Joint {
    fn id(&self) -> ElementId {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn multipliers(&self) -> usize {
        self.m_pair() * self.pairs.len()
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        let s = ctx.constraint_scale;
        let m = self.m_pair();
        let nn = 6 * self.nodes.len();
        for (k, pair) in self.pairs.iter().enumerate() {
            let (s1, s2) = (&nodes[self.nodes[pair.a]], &nodes[self.nodes[pair.b]]);
            let lam = &lambda[k * m..(k + 1) * m];
            let lrow = nn + k * m;
            if !tangent {
                let (phi, g) = self.forces_f64(pair, s1, s2, ctx, lam);
                for (j, gj) in g.iter().enumerate() {
                    out.res[Self::local(pair, j)] += gj;
                }
                for (i, v) in phi.iter().take(m).enumerate() {
                    out.res[lrow + i] += s * v;
                }
                continue;
            }
            let (phi, g) = self.forces_dual(pair, s1, s2, ctx, lam);
            for (row, gr) in g.iter().enumerate() {
                let lr = Self::local(pair, row);
                out.res[lr] += gr.re;
                for (col, e) in gr.eps.iter().enumerate() {
                    out.add_tan(lr, Self::local(pair, col), *e);
                }
            }
            for (i, v) in phi.iter().take(m).enumerate() {
                out.res[lrow + i] += s * v.re;
                for (col, e) in v.eps.iter().enumerate() {
                    let lc = Self::local(pair, col);
                    out.add_tan(lc, lrow + i, s * e);
                    out.add_tan(lrow + i, lc, s * e);
                }
            }
        }
    }

    fn save_state(&self) -> ElementState {
        ElementState::Joint(JointState(self.hist.clone()))
    }

    fn restore_state(&mut self, state: &ElementState) -> Result<(), StateMismatch> {
        let ElementState::Joint(JointState(h)) = state else {
            return Err(StateMismatch { element: self.id });
        };
        self.hist = h.clone();
        Ok(())
    }

    fn commit(&mut self, ctx: &EvalContext, nodes: &[NodeState], _lambda: &[f64]) {
        let a = self.angles(nodes);
        self.hist.angles = [a[0], a[1]];
        if matches!(self.kind, JointType::UJoint { .. }) {
            let cb = a[2].abs();
            self.hist.min_abs_cos_bend = Some(self.hist.min_abs_cos_bend.map_or(cb, |m| m.min(cb)));
            let singular = cb < UJOINT_SINGULAR_COS;
            if singular && !self.hist.in_singular {
                self.hist.singular_passages += 1;
                if self.hist.first_singular_time.is_none() {
                    self.hist.first_singular_time = Some(ctx.t);
                    if let Some(msg) = self.singularity(nodes) {
                        eprintln!("warning: t = {:.6e} s: {msg}", ctx.t);
                    }
                }
            }
            self.hist.in_singular = singular;
        }
    }

    fn output_header(&self) -> Vec<String> {
        let mut h: Vec<&str> = match &self.kind {
            JointType::Hinge { .. } => vec!["angle"],
            JointType::UJoint { .. } => vec!["angle1", "angle2", "bend"],
            JointType::Prismatic { .. } => vec!["slide"],
            _ => vec![],
        };
        let r = ["fx", "fy", "fz", "mx", "my", "mz"];
        if self.pairs.len() == 1 {
            h.extend(r);
            h.iter().map(|s| s.to_string()).collect()
        } else {
            let mut out: Vec<String> = h.iter().map(|s| s.to_string()).collect();
            for pair in &self.pairs {
                out.extend(r.iter().map(|c| format!("{c}_{}", pair.b + 1)));
            }
            out
        }
    }

    fn write_output_row(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        let a = self.angles(nodes);
        match &self.kind {
            JointType::Hinge { .. } => row.push(a[0]),
            JointType::UJoint { .. } => {
                row.extend_from_slice(&[a[0], a[1], a[2].clamp(-1.0, 1.0).acos()]);
            }
            JointType::Prismatic { a: ax, .. } => {
                let (s1, s2) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
                let d = s2.x + s2.r * self.pairs[0].c2 - s1.x;
                row.push(d.dot(&(s1.r * ax)));
            }
            _ => {}
        }
        for k in 0..self.pairs.len() {
            let (f, m) = self.reaction(k, ctx, nodes, lambda);
            row.extend_from_slice(f.as_slice());
            row.extend_from_slice(m.as_slice());
        }
    }

    fn constraint_violation(&self, nodes: &[NodeState]) -> f64 {
        let m = self.m_pair();
        self.pairs
            .iter()
            .map(|pair| {
                let phi =
                    self.phi_f64(pair, &nodes[self.nodes[pair.a]], &nodes[self.nodes[pair.b]]);
                phi[..m].iter().fold(0.0f64, |x, v| x.max(v.abs()))
            })
            .fold(0.0, f64::max)
    }

    fn diagnose(&self, nodes: &[NodeState]) -> Option<String> {
        self.singularity(nodes)
    }

    fn summary(&self) -> Option<serde_json::Value> {
        if !matches!(self.kind, JointType::UJoint { .. }) {
            return None;
        }
        Some(serde_json::json!({
            "type": "UJOINT",
            "singular_passages": self.hist.singular_passages,
            "first_singular_time": self.hist.first_singular_time,
            "min_abs_cos_bend": self.hist.min_abs_cos_bend,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::*;

    fn all_types() -> Vec<JointType> {
        let a = Vector3::new(0.3, -0.5, 0.8).normalize();
        let (p, q) = normals(&a);
        vec![
            JointType::Spherical,
            JointType::Hinge { p, q, a },
            JointType::UJoint {
                a1: a,
                a2: p,
                b: a.cross(&p),
            },
            JointType::Clamp,
            JointType::Prismatic { p, q, a },
            JointType::Rigid,
        ]
    }

    fn ctx() -> EvalContext {
        EvalContext {
            constraint_scale: 3.7,
            penalty: 11.0,
            ..dyn_ctx()
        }
    }

    #[test]
    fn tangent_matches_finite_differences_at_large_rotations() {
        for kind in all_types() {
            // Node 2 offset from node 1 (joint point at node 1), a third node for RIGID.
            let x0 = [
                Vector3::new(0.1, 0.2, -0.1),
                Vector3::new(0.4, -0.1, 0.3),
                Vector3::new(-0.2, 0.5, 0.1),
            ];
            let n = if matches!(kind, JointType::Rigid) {
                3
            } else {
                2
            };
            let j = Joint::new(ElementId(7), kind.clone(), (0..n).collect(), &x0[..n]).unwrap();
            for seed in 1..4 {
                // Rotations up to ~2.6 rad per node, displacements of 0.3 m.
                let st = random_states(&x0[..n], 0.3, 1.5, seed);
                let mut g = Lcg(seed + 100);
                let lam: Vec<f64> = (0..j.multipliers()).map(|_| g.next() * 5.0).collect();
                check_tangent(&j, &ctx(), &st, &lam, 1e-7);
                check_tangent(&j, &static_ctx(), &st, &lam, 1e-7);
            }
        }
    }

    #[test]
    fn reference_configuration_satisfies_the_constraints() {
        let x0 = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(0.5, 0.1, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
        ];
        for kind in all_types() {
            let n = if matches!(kind, JointType::Rigid) {
                3
            } else {
                2
            };
            let j = Joint::new(ElementId(1), kind, (0..n).collect(), &x0[..n]).unwrap();
            let st: Vec<NodeState> = x0[..n].iter().map(|x| NodeState::at_rest(*x)).collect();
            assert!(j.constraint_violation(&st) < 1e-15);
        }
    }

    #[test]
    fn hinge_allows_rotation_about_its_axis_only_and_counts_turns() {
        let a = Vector3::new(0.0, 0.0, 1.0);
        let (p, q) = normals(&a);
        let x0 = [Vector3::zeros(), Vector3::zeros()];
        let mut j =
            Joint::new(ElementId(1), JointType::Hinge { p, q, a }, vec![0, 1], &x0).unwrap();
        let base = rotation::exp(&Vector3::new(0.4, -1.1, 0.7));
        let mut st = [NodeState::at_rest(x0[0]), NodeState::at_rest(x0[1])];
        st[0].r = base;
        let c = dyn_ctx();
        // Turn node 2 about the hinge axis by 3.5 turns in steps of 0.5 rad.
        let mut theta = 0.0;
        while theta < 7.0 * std::f64::consts::PI {
            theta += 0.5;
            st[1].r = base * rotation::exp(&(a * theta));
            assert!(j.constraint_violation(&st) < 1e-14);
            j.commit(&c, &st, &[0.0; 5]);
            let row = j.output_row(&c, &st, &[0.0; 5]);
            assert!((row[0] - theta).abs() < 1e-12, "{} vs {theta}", row[0]);
        }
        // A rotation about a normal violates it by sin(angle).
        st[1].r = base * rotation::exp(&(p * 0.1));
        assert!((j.constraint_violation(&st) - 0.1f64.sin()).abs() < 1e-14);
    }

    #[test]
    fn hinge_reaction_is_the_multiplier_force_and_has_no_moment_about_the_axis() {
        let a = Vector3::new(0.0, 0.0, 1.0);
        let (p, q) = normals(&a);
        let x0 = [Vector3::zeros(), Vector3::zeros()];
        let j = Joint::new(ElementId(1), JointType::Hinge { p, q, a }, vec![0, 1], &x0).unwrap();
        let mut st = random_states(&x0, 0.0, 0.0, 1);
        st[1].r = rotation::exp(&(a * 0.8));
        st[0].r = Matrix3::identity();
        let c = EvalContext {
            constraint_scale: 2.0,
            ..static_ctx()
        };
        let lam = [1.0, -2.0, 0.5, 0.3, -0.7];
        let (f, m) = j.reactions(&c, &st, &lam)[0];
        assert!((f - Vector3::new(-2.0, 4.0, -1.0)).norm() < 1e-12, "{f}");
        assert!(m.dot(&(st[1].r * a)).abs() < 1e-12, "{m}");
        assert!(m.norm() > 0.1);
    }

    #[test]
    fn ujoint_angles_and_singularity() {
        let (a1, a2) = (Vector3::z(), Vector3::y());
        let x0 = [Vector3::zeros(), Vector3::zeros()];
        let mut j = Joint::new(
            ElementId(12),
            JointType::UJoint {
                a1,
                a2,
                b: a1.cross(&a2),
            },
            vec![0, 1],
            &x0,
        )
        .unwrap();
        let c = dyn_ctx();
        let base = rotation::exp(&Vector3::new(-0.3, 0.9, 0.2));
        let mut st = [NodeState::at_rest(x0[0]), NodeState::at_rest(x0[1])];
        st[0].r = base;
        for (t1, t2) in [(0.3, -0.2), (1.2, 0.4), (-2.5, 1.0)] {
            st[1].r = base * rotation::exp(&(a1 * t1)) * rotation::exp(&(a2 * t2));
            assert!(j.constraint_violation(&st) < 1e-14);
            let row = j.output_row(&c, &st, &[0.0; 4]);
            assert!(
                (row[0] - t1).abs() < 1e-12 && (row[1] - t2).abs() < 1e-12,
                "{row:?}"
            );
            assert!((row[2].cos() - t1.cos() * t2.cos()).abs() < 1e-12);
            assert!(j.singularity(&st).is_none());
        }
        // Bend of 90°: the shafts are perpendicular.
        st[1].r =
            base * rotation::exp(&(a1 * 0.3)) * rotation::exp(&(a2 * std::f64::consts::FRAC_PI_2));
        let msg = j.singularity(&st).expect("singular");
        assert!(msg.contains("UJOINT") && msg.contains("singular"), "{msg}");
        j.commit(&c, &st, &[0.0; 4]);
        let s = j.summary().unwrap();
        assert_eq!(s["singular_passages"], 1);
    }
}
