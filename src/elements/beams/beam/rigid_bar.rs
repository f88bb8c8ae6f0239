//! The rigid bar: a `BEAM` card whose section is `RIGID`.
//!
//! The bar keeps its shape: every node of the beam moves with its first node, by the
//! constraint equations of the `RIGID` joint ([`crate::elements::joints`], `Φ = 0` for the relative
//! position in the first node's frame and the relative rotation of each further node).
//! Its inertia is the beam's with zero stiffness: consistent translational mass
//! `∫ ρA Nᵢ Nⱼ ds` and rotary inertia `ρ diag(I₂+I₃, I₂, I₃)` lumped at the nodes
//! (paper eqs. [10]–[11]). Both are exact for a rigid motion: its velocity field
//! `ẋ(s) = V + W × x(s)` is linear along the straight bar, so the Lagrange interpolation of
//! the nodes' velocities reproduces it and the kinetic energy is exactly that of the rigid
//! body of mass `ρAL`, centred at the bar's middle, with the inertia
//! `ρA L³/12 + ρ I L` about the transverse axes and `ρ(I₂+I₃) L` about its own
//! (so a bar with `I₂ = I₃ = 0` has no inertia about its axis: a joint must hold that spin).
//! Gravity: `∫ ρA Nᵢ ds g` on each node, exact for the same reason.

use crate::elements::joints::{Joint, JointType};
use crate::elements::{
    BuildError, Element, ElementState, Energies, EvalContext, Local, NodeState, StateMismatch,
    StepLimit, beam_p,
};
use crate::model::{ElementId, ElementKind, Model};
use nalgebra::Vector3;

/// A rigid bar: the beam's inertia (no stiffness) and a `RIGID` joint on its nodes.
pub struct RigidBar {
    inertia: Box<dyn Element>,
    joint: Joint,
}

impl RigidBar {
    /// The rigid bar of a model's `BEAM` card with a `RIGID` section, on dense `nodes`
    /// (along the axis, as [`beam_p::from_model`] takes them).
    pub fn from_model(
        model: &Model,
        el: &crate::model::Element,
        nodes: Vec<usize>,
    ) -> Result<Self, BuildError> {
        let ElementKind::Beam {
            material, section, ..
        } = &el.kind
        else {
            unreachable!("RigidBar::from_model is called on beams only")
        };
        let (mut props, _) = model.beam_properties(*material, *section);
        props.cn = Vector3::zeros();
        props.cm = Vector3::zeros();
        let x0: Vec<Vector3<f64>> = nodes.iter().map(|&i| model.nodes[i].position).collect();
        let joint = Joint::new(el.id, JointType::Rigid, nodes.clone(), &x0)?;
        let inertia = beam_p::with_properties(model, el, nodes, props, 0.0);
        Ok(RigidBar { inertia, joint })
    }
}

impl Element for RigidBar {
    fn id(&self) -> ElementId {
        self.joint.id()
    }

    fn nodes(&self) -> &[usize] {
        self.joint.nodes()
    }

    fn multipliers(&self) -> usize {
        self.joint.multipliers()
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        self.inertia.evaluate(ctx, nodes, &[], tangent, out);
        self.joint.evaluate(ctx, nodes, lambda, tangent, out);
    }

    fn energies(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> Energies {
        self.inertia.energies(nodes, gravity)
    }

    fn commit(&mut self, ctx: &EvalContext, nodes: &[NodeState], lambda: &[f64]) {
        self.joint.commit(ctx, nodes, lambda);
    }

    fn output_header(&self) -> Vec<String> {
        self.joint.output_header()
    }

    fn write_output_row(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        self.joint.write_output_row(ctx, nodes, lambda, row);
    }

    fn constraint_violation(&self, nodes: &[NodeState]) -> f64 {
        self.joint.constraint_violation(nodes)
    }

    fn constraint_rates(&self, nodes: &[NodeState], out: &mut [f64]) -> bool {
        self.joint.constraint_rates(nodes, out)
    }

    fn force_scale(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> f64 {
        self.inertia
            .force_scale(nodes, gravity)
            .max(self.joint.force_scale(nodes, gravity))
    }

    fn diagnose(&self, nodes: &[NodeState]) -> Option<String> {
        self.joint.diagnose(nodes)
    }

    fn summary(&self) -> Option<serde_json::Value> {
        self.joint.summary()
    }

    fn save_state(&self) -> ElementState {
        self.joint.save_state()
    }

    fn restore_state(&mut self, state: &ElementState) -> Result<(), StateMismatch> {
        self.joint.restore_state(state)
    }

    fn restart(&self) -> bool {
        self.joint.restart()
    }

    fn step_limit(
        &self,
        ctx: &EvalContext,
        old: &[NodeState],
        new: &[NodeState],
    ) -> Option<StepLimit> {
        self.joint.step_limit(ctx, old, new)
    }
}
