//! Degrees of freedom nothing acts on: a node's rotations held, its free translations
//! refused.
//!
//! A point mass without rotary inertia on a node that no beam, joint, spring or moment
//! touches (a ball, a massless journal) leaves the node's three rotations with no
//! inertia, no stiffness and no constraint: zero columns of every iteration matrix, a
//! singular system at t = 0. Nothing in the model depends on those rotations, so they are
//! held (as `FIX RX RY RZ` would hold them) and the run says so. A free translation that
//! nothing acts on is a modelling error instead — the node's motion is undetermined — and
//! is refused before the run, naming the node.
//!
//! What "acts on" means comes from the elements: each says for each of its nodes whether
//! its rotation counts ([`Element::rotation_use`]); by default the element's own
//! iteration matrix at the initial state (stiffness, damping, mass and constraint rows,
//! `c_v = c_a = 1`) tells, its column of the node's degree of freedom being zero or not.

use super::system::{FIXED, System};
use crate::elements::{Element, EvalContext, Local, NodeState, RotationUse};
use crate::model::{Model, NodeId, Span};
use nalgebra::Vector3;

/// A node whose free translations nothing acts on: its motion is undetermined.
#[derive(Debug, Clone, PartialEq)]
pub struct UndeterminedNode {
    /// The node.
    pub node: NodeId,
    /// Where the deck defines it.
    pub span: Span,
    /// The free translations (x, y, z) with no inertia, stiffness or constraint.
    pub axes: [bool; 3],
}

impl std::fmt::Display for UndeterminedNode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let axes: Vec<&str> = ["X", "Y", "Z"]
            .iter()
            .zip(self.axes)
            .filter_map(|(n, b)| b.then_some(*n))
            .collect();
        write!(
            f,
            "node {}: its translation along {} has no mass, no stiffness and no joint, so its \
             motion is undetermined (the iteration matrix would be singular); give it a MASS, \
             connect it to an element, or FIX {}",
            self.node.0,
            axes.join(", "),
            axes.join(" ")
        )
    }
}

/// What [`scan`] found.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Idle {
    /// Dense nodes whose free rotations nothing acts on (to be held).
    pub rotations: Vec<usize>,
    /// Nodes with free translations nothing acts on (an error).
    pub undetermined: Vec<UndeterminedNode>,
}

/// The degrees of freedom of `sys` (built from `model`) that no element and no load acts
/// on, from each element's [`Element::rotation_use`] and its iteration matrix at the
/// reference state.
pub fn scan(sys: &System, model: &Model) -> Idle {
    let nodes: Vec<NodeState> = sys.x0.iter().map(|x| NodeState::at_rest(*x)).collect();
    let ctx = EvalContext {
        t: 0.0,
        c_v: 1.0,
        c_a: 1.0,
        dynamic: true,
        gravity: Vector3::zeros(),
        constraint_scale: 1.0,
        penalty: 0.0,
        h: 0.0,
    };
    let mut used = vec![[false; 6]; nodes.len()];
    for el in &sys.elements {
        mark(el.as_ref(), &ctx, &nodes, &mut used);
    }
    for l in &sys.loads {
        // A moment on a node acts on its rotations. (A force alone determines nothing: a
        // loaded node without mass is still singular.)
        if l.moment {
            used[l.node][3..].fill(true);
        }
    }
    let mut idle = Idle::default();
    for (i, d) in sys.node_dofs.iter().enumerate() {
        let free_idle = |c: usize| d[c] != FIXED && !used[i][c];
        if (3..6).any(free_idle) && (3..6).all(|c| d[c] == FIXED || !used[i][c]) {
            idle.rotations.push(i);
        }
        let axes = [free_idle(0), free_idle(1), free_idle(2)];
        if axes.iter().any(|a| *a) {
            let id = sys.node_ids[i];
            idle.undetermined.push(UndeterminedNode {
                node: id,
                span: model.nodes[&id].span,
                axes,
            });
        }
    }
    idle
}

/// Marks the degrees of freedom `el` acts on.
fn mark(el: &dyn Element, ctx: &EvalContext, nodes: &[NodeState], used: &mut [[bool; 6]]) {
    let nn = 6 * el.nodes().len();
    let m = el.multipliers();
    let mut local = Local::new(nn + m);
    el.evaluate(ctx, nodes, &vec![0.0; m], true, &mut local);
    let n = local.n;
    for (a, &node) in el.nodes().iter().enumerate() {
        for comp in 0..6 {
            let col = 6 * a + comp;
            // (`tan` holds the velocity and acceleration parts too: `Local::rate` is a
            // part of it.)
            let evaluated =
                (0..n).any(|i| local.tan_at(i, col) != 0.0 || local.tan_at(col, i) != 0.0);
            let on = if comp < 3 {
                evaluated
            } else {
                match el.rotation_use(a) {
                    RotationUse::AsEvaluated => evaluated,
                    RotationUse::Always => true,
                    RotationUse::Never => false,
                }
            };
            used[node][comp] |= on;
        }
    }
}

/// The model with the rotations of the dense nodes `held` fixed (`FIX RX RY RZ`).
pub fn with_held_rotations(model: &Model, held: &[usize]) -> Model {
    let mut m = model.clone();
    for &i in held {
        if let Some((_, node)) = m.nodes.get_index_mut(i) {
            for c in 3..6 {
                node.fixed[c] = true;
            }
        }
    }
    m
}
