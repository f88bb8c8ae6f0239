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

use super::registry::Kind;
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
    /// The driver of a driven HINGE or PRISMATIC (`DRIVE`): a sixth equation `Φ₆ =
    /// θ − a f(t)` or `σ − a f(t)` (joints/drive.rs).
    drive: Option<super::drive::TimeLaw>,
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

/// The element halves of the joint kinds (`crate::kinds`): every one a [`Joint`].
const fn joint_kind(types: &'static [&'static str]) -> Kind {
    Kind {
        types,
        build: |model, el| Ok(Box::new(Joint::from_model(model, el)?)),
    }
}

/// `HINGE`, `PRISMATIC`.
pub mod hinge {
    /// Their element half.
    pub const KIND: super::Kind = super::joint_kind(&["HINGE", "PRISMATIC"]);
}

/// `UJOINT`.
pub mod ujoint {
    /// Its element half.
    pub const KIND: super::Kind = super::joint_kind(&["UJOINT"]);
}

/// `SPHERICAL`, `CLAMP`.
pub mod spherical {
    /// Their element half.
    pub const KIND: super::Kind = super::joint_kind(&["SPHERICAL", "CLAMP"]);
}

/// `RIGID` (a rigid body: constraints only; a `BEAM` of `RIGID` section is a
/// `crate::elements::rigid_bar::RigidBar`).
pub mod rigid {
    /// Its element half.
    pub const KIND: super::Kind = super::joint_kind(&["RIGID"]);
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
            drive: None,
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
        let mut joint = Joint::new(el.id, kind, idx, &x0)?;
        if let Some(d) = model.drives.get(&el.id) {
            joint = joint.with_drive(super::drive::TimeLaw::from_model(model, d))?;
        }
        Ok(joint)
    }

    /// The joint type.
    pub fn kind(&self) -> &JointType {
        &self.kind
    }

    fn m_pair(&self) -> usize {
        self.kind.equations() + usize::from(self.drive.is_some())
    }
}

mod constraints;
mod drive;
mod element;
mod outputs;
pub mod prescribed;
#[cfg(test)]
mod tests;
