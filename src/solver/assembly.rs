//! Assembly: initial positions and rotations moved onto the constraints before the first
//! step.
//!
//! A loop closed by eye (node coordinates to three digits, a hinge axis rounded) violates
//! its joints by millimetres; the first step would then correct it with forces of order
//! `Φ/(βh²)`, a spurious impact. Instead the initial configuration `q` is projected onto
//! the constraint manifold `Φ(q, 0) = 0` by Gauss–Newton steps of least change,
//!
//! `min ½ Δᵀ W Δ  subject to  Φ(q) − B Δ = 0`, i.e. `[W  Bᵀ; B  0] [Δ; μ] = [0; Φ]`,
//! `q ← q ⊖ Δ` (`x ← x − Δx`, `R ← R exp(−ΔΘ̃)`),
//!
//! with `W = diag(1, L²)` on translations and (material) rotations, `L` the model's
//! reference length, so that a rotation weighs as the motion it gives at the model's
//! scale. The minimum-change projection is the usual assembly of multibody codes
//! (Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, 1989, § 4.4;
//! Géradin & Cardona 2001, § 11.5); near a solution it converges quadratically. Drivers'
//! equations at t = 0 are constraints like the others, so a driven joint starts where its
//! law says. Removed (redundant) equations are not imposed: the kept ones imply them.

use super::linear::SparseSystem;
use super::notice::Notice;
use super::system::{FIXED, System};
use crate::elements::{EvalContext, NodeState};
use crate::rotation;
use nalgebra::Vector3;

/// Gauss–Newton iterations before the assembly gives up.
const MAX_ITERATIONS: u32 = 50;

/// Why the constraints could not be met at the start.
#[derive(Debug, Clone, PartialEq)]
pub struct AssemblyFailure {
    /// Iterations made.
    pub iterations: u32,
    /// The largest violation left, m or rad.
    pub violation: f64,
    /// The equation that holds it, e.g. `element 7 constraint 2`.
    pub worst: String,
    /// How far the nodes moved (largest), m.
    pub moved: f64,
}

impl std::fmt::Display for AssemblyFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the initial positions cannot be moved onto the constraints (assembly): after {} Gauss–Newton iterations {} is still violated by {:.3e} (m or rad), the nodes having moved by up to {:.3e} m. The loop cannot close with these dimensions (check the lengths and the joints' axes), or its nodes are too far from a closed position for the assembly to find it",
            self.iterations, self.worst, self.violation, self.moved
        )
    }
}

fn max_violation(sys: &System) -> (f64, usize) {
    let nn = sys.n_node_eq;
    sys.rhs[nn..]
        .iter()
        .enumerate()
        .fold((0.0f64, nn), |(m, k), (i, v)| {
            let a = if v.is_finite() {
                v.abs()
            } else {
                f64::INFINITY
            };
            if a > m { (a, nn + i) } else { (m, k) }
        })
}

/// Moves `nodes` onto the constraints of `sys` at time `t` (module docs) when they
/// violate them by more than `tol` (m or rad); `None` when they did not.
pub fn assemble_positions(
    sys: &mut System,
    nodes: &mut [NodeState],
    t: f64,
    tol: f64,
) -> Result<Option<Notice>, AssemblyFailure> {
    let nn = sys.n_node_eq;
    let n = sys.n_eq();
    if n == nn {
        return Ok(None);
    }
    let ctx = EvalContext {
        t,
        c_v: 0.0,
        c_a: 0.0,
        dynamic: false,
        gravity: Vector3::zeros(),
        constraint_scale: 1.0,
        penalty: 0.0,
        h: 0.0,
    };
    let zero = vec![0.0; n];
    sys.assemble(&ctx, nodes, &zero, false);
    let (violation0, _) = max_violation(sys);
    if violation0 <= tol {
        return Ok(None);
    }
    let start: Vec<NodeState> = nodes.to_vec();
    let l = sys.ref_length;
    // A separate matrix: the run's keeps its pivots for the run's matrices.
    let mut lin = match SparseSystem::new(&sys.matrix.columns()) {
        Ok(m) => m,
        Err(e) => {
            return Err(AssemblyFailure {
                iterations: 0,
                violation: violation0,
                worst: format!("the matrix ({e})"),
                moved: 0.0,
            });
        }
    };
    let mut rhs = vec![0.0; n];
    let mut iterations = 0;
    loop {
        sys.assemble(&ctx, nodes, &zero, true);
        let (violation, worst) = max_violation(sys);
        let moved = moves(&start, nodes).0;
        if violation <= 0.1 * tol {
            break;
        }
        if iterations == MAX_ITERATIONS || !violation.is_finite() {
            return Err(AssemblyFailure {
                iterations,
                violation,
                worst: sys.describe(worst),
                moved,
            });
        }
        lin.values.copy_from_slice(&sys.matrix.values);
        for col in 0..nn {
            let w = match sys.owners[col] {
                super::system::DofOwner::Node { comp, .. } if comp >= 3 => l * l,
                _ => 1.0,
            };
            for p in lin.position_range(col) {
                let row = lin.row_of(p);
                if row < nn {
                    lin.values[p] = if row == col { w } else { 0.0 };
                }
            }
        }
        rhs[..nn].fill(0.0);
        rhs[nn..].copy_from_slice(&sys.rhs[nn..]);
        if lin.factor().is_err() || lin.solve(&mut rhs).is_err() {
            return Err(AssemblyFailure {
                iterations,
                violation,
                worst: format!(
                    "{} (the constraint Jacobian is singular there: the joints block fewer motions than their equations)",
                    sys.describe(worst)
                ),
                moved,
            });
        }
        // A step longer than half the model is no correction of a loop closed by eye:
        // shortened, so that a far start goes on towards the manifold.
        let (mut dx, mut dr) = (0.0f64, 0.0f64);
        for d in &sys.node_dofs {
            for c in 0..6 {
                if d[c] != FIXED {
                    if c < 3 {
                        dx = dx.max(rhs[d[c]].abs());
                    } else {
                        dr = dr.max(rhs[d[c]].abs());
                    }
                }
            }
        }
        let cut = (0.5 * l / dx.max(1e-300))
            .min(0.5 / dr.max(1e-300))
            .min(1.0);
        for (i, d) in sys.node_dofs.iter().enumerate() {
            let comp = |c: usize| {
                if d[c] == FIXED { 0.0 } else { cut * rhs[d[c]] }
            };
            let s = &mut nodes[i];
            s.x -= Vector3::new(comp(0), comp(1), comp(2));
            s.r *= rotation::exp(&-Vector3::new(comp(3), comp(4), comp(5)));
        }
        iterations += 1;
    }
    let (moved, node, turned, turned_node) = moves(&start, nodes);
    Ok(Some(Notice::Assembled {
        moved,
        node: sys.node_ids[node],
        turned,
        turned_node: sys.node_ids[turned_node],
        violation: violation0,
        iterations,
    }))
}

/// The largest translation and rotation of a node from `a` to `b`, with the nodes.
fn moves(a: &[NodeState], b: &[NodeState]) -> (f64, usize, f64, usize) {
    let mut out = (0.0f64, 0, 0.0f64, 0);
    for (i, (s, t)) in a.iter().zip(b).enumerate() {
        let dx = (t.x - s.x).norm();
        let dr = rotation::log(&(s.r.transpose() * t.r)).norm();
        if dx > out.0 {
            out.0 = dx;
            out.1 = i;
        }
        if dr > out.2 {
            out.2 = dr;
            out.3 = i;
        }
    }
    out
}
