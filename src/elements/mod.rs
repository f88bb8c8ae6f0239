//! The element library: one file per element type, all behind the [`Element`] trait.
//!
//! # Unknowns and sign conventions
//! Each node carries a position `x` (global frame) and an orientation `R` (rotation matrix,
//! material frame → global). Its velocities are `ẋ` (global) and the **material** angular
//! velocity `Ω` (`Ṙ = R Ω̃`), its accelerations `ẍ` and `Ω̇`. Variations are `δx` (global)
//! and the material spin `δΘ` (`δR = R δΘ̃`): the Lie-group setting of Brüls, Cardona &
//! Arnold (2012) on `(ℝ³ × SO(3))ⁿ`.
//!
//! An element's local vector is laid out node by node, `[δx, δΘ]` per node, followed by
//! its own Lagrange multipliers. Its residual is the out-of-balance force
//! `r = f_inertia + f_internal − f_external + s Bᵀλ` (zero at equilibrium), and, for each
//! multiplier, the scaled constraint `s Φ(q)`; `s` is the constraint scale factor of
//! [`EvalContext::constraint_scale`] (paper eq. [15], factor `k`). Its tangent is the
//! iteration matrix `S = ∂r/∂q + c_v ∂r/∂v + c_a ∂r/∂a` (derivatives with respect to
//! `[δx, δΘ]`, velocities and accelerations), the coefficients coming from the integrator.

pub mod beams;
pub mod bodies;
pub mod contact;
pub mod drive;
pub mod forces;
pub mod joints;
pub mod registry;

pub use beams::beam::{beam_p, rigid_bar, two_node as beam};
pub use bodies::{mass, superelement};
pub use contact::{came, clearance, profile};
pub use forces::{bushing, control, rspring, spring};
pub use joints::prescribed;

use crate::model::{ElementId, Model};
use nalgebra::{Matrix3, Vector3};

/// Errors while turning model elements into solver elements.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BuildError {
    /// Element data the solver cannot use (e.g. a beam of zero length).
    #[error("{element}: {message}")]
    Invalid {
        /// The element.
        element: ElementId,
        /// What is wrong.
        message: String,
    },
}

/// Builds the solver's elements from a validated model, in model order.
pub fn build(model: &Model) -> Result<Vec<Box<dyn Element>>, BuildError> {
    let mut out: Vec<Box<dyn Element>> = Vec::with_capacity(model.elements.len());
    for el in model.elements.values() {
        // Each kind builds its own elements (`crate::kinds`; every kind of `ElementKind`
        // has its builder there: `tests/deck/kinds_registry.rs`).
        let Some(kind) = registry::kind(el.kind.keyword()) else {
            return Err(BuildError::Invalid {
                element: el.id,
                message: format!("no element builder is registered for {}", el.kind.keyword()),
            });
        };
        out.push((kind.build)(model, el)?);
    }
    Ok(out)
}

/// The history variables of an element (what [`Element::commit`] and the attempt
/// memory of [`Element::evaluate`] carry from one step to the next), for checkpoints: an
/// element restored from it evaluates bit for bit as the one it was taken from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ElementState {
    /// An element without history (beams, masses): nothing to keep.
    Stateless,
    /// A cam/follower contact ([`came::Came`]).
    Came(came::CameState),
    /// A joint ([`joints::Joint`]).
    Joint(joints::JointState),
    /// A SPRING's line of action at the last accepted state ([`spring::Spring`]).
    Spring([f64; 3]),
    /// An RSPRING's hinge angle at the last accepted state, rad, whole turns counted
    /// ([`rspring::RSpring`]).
    RSpring(f64),
    /// A revolute joint with clearance ([`clearance::Clearance`]).
    Clearance(clearance::ClearanceState),
    /// A controlled input ([`control::Control`]): its angle sensors' last angles (turns
    /// counted) and a PID's `[I_n, e_n, t_n]`.
    Control {
        /// Angles of the angle sensors, rad.
        angles: Vec<f64>,
        /// The PID's integral, error and time at the last accepted state.
        pid: [f64; 3],
    },
}

/// A saved [`ElementState`] that does not belong to the element it is given to.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{element}: the saved state is of another kind of element")]
pub struct StateMismatch {
    /// The element.
    pub element: ElementId,
}

/// Kinematic state of one node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeState {
    /// Position, global, m.
    pub x: Vector3<f64>,
    /// Orientation: material frame → global.
    pub r: Matrix3<f64>,
    /// Velocity, global, m/s.
    pub v: Vector3<f64>,
    /// Angular velocity, material frame, rad/s.
    pub w: Vector3<f64>,
    /// Acceleration, global, m/s².
    pub a: Vector3<f64>,
    /// Angular acceleration, material frame, rad/s².
    pub wd: Vector3<f64>,
}

impl NodeState {
    /// A node at rest at `x` with identity orientation.
    pub fn at_rest(x: Vector3<f64>) -> Self {
        NodeState {
            x,
            r: Matrix3::identity(),
            v: Vector3::zeros(),
            w: Vector3::zeros(),
            a: Vector3::zeros(),
            wd: Vector3::zeros(),
        }
    }
}

/// What the integrator asks of an element evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EvalContext {
    /// Time, s.
    pub t: f64,
    /// Coefficient of `∂r/∂v` in the iteration matrix (`γ/(βh)` for HHT; 0 in statics).
    pub c_v: f64,
    /// Coefficient of `∂r/∂a` (`1/((1−α_f)βh²)` for HHT; 0 in statics).
    pub c_a: f64,
    /// Inertia forces are included (dynamics).
    pub dynamic: bool,
    /// Gravity acceleration, m/s² (zero vector when the deck declares none).
    pub gravity: Vector3<f64>,
    /// Scale factor `s` of constraint rows and multipliers (paper eq. [15], factor `k`).
    pub constraint_scale: f64,
    /// Augmented-Lagrangian penalty `p` (paper eq. [14]); 0 = none.
    pub penalty: f64,
    /// Time step, s (0 in statics).
    pub h: f64,
}

/// Element energies at a state.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energies {
    /// Kinetic energy, J.
    pub kinetic: f64,
    /// Strain (or contact-spring) energy, J.
    pub strain: f64,
    /// Potential of gravity, J (zero at the reference configuration).
    pub gravity: f64,
}

impl std::ops::AddAssign for Energies {
    fn add_assign(&mut self, o: Energies) {
        self.kinetic += o.kinetic;
        self.strain += o.strain;
        self.gravity += o.gravity;
    }
}

/// A mesh an element draws beyond the model's nodes (a superelement's FE mesh) for
/// ParaView: its points at the current state, their point data (global frame, SI units, as
/// the nodes': `output::vtk`) and line cells between them (indices into `points`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ElementMesh {
    /// Current places, m.
    pub points: Vec<Vector3<f64>>,
    /// Displacements from the places at rest, m.
    pub displacement: Vec<Vector3<f64>>,
    /// Rotation vectors (log of the rotation), rad.
    pub rotation: Vec<Vector3<f64>>,
    /// Velocities, m/s.
    pub velocity: Vec<Vector3<f64>>,
    /// Spatial angular velocities, rad/s.
    pub angular_velocity: Vec<Vector3<f64>>,
    /// Line cells.
    pub lines: Vec<(usize, usize)>,
}

/// Local residual and tangent buffers of one element (sized once, reused every iteration).
#[derive(Debug, Clone)]
pub struct Local {
    /// Local size `6 × nodes + multipliers`.
    pub n: usize,
    /// Residual.
    pub res: Vec<f64>,
    /// Tangent, column-major `n × n`.
    pub tan: Vec<f64>,
    /// The part of `tan` that comes from velocities and accelerations
    /// (`c_v ∂r/∂v + c_a ∂r/∂a`), written by [`Local::add_rate_block`]. The assembler
    /// multiplies only the rest (the stiffness) by the tangent operator `T(u)` of the
    /// step's rotation increment, which makes the iteration matrix exact.
    pub rate: Vec<f64>,
    /// Whether `rate` holds anything this evaluation.
    pub has_rate: bool,
}

impl Local {
    /// Zeroed buffers of size `n`.
    pub fn new(n: usize) -> Self {
        Local {
            n,
            res: vec![0.0; n],
            tan: vec![0.0; n * n],
            rate: vec![0.0; n * n],
            has_rate: false,
        }
    }

    /// Sets everything to zero.
    pub fn clear(&mut self) {
        self.res.iter_mut().for_each(|v| *v = 0.0);
        self.tan.iter_mut().for_each(|v| *v = 0.0);
        if self.has_rate {
            self.rate.iter_mut().for_each(|v| *v = 0.0);
            self.has_rate = false;
        }
    }

    /// Adds a 3×3 block of the velocity/acceleration part of the iteration matrix
    /// (`c_v ∂r/∂v + c_a ∂r/∂a`) at local (row `i`, column `j`): to `tan` and to `rate`.
    #[inline]
    pub fn add_rate_block(&mut self, i: usize, j: usize, m: &Matrix3<f64>) {
        self.has_rate = true;
        for c in 0..3 {
            for r in 0..3 {
                self.tan[(j + c) * self.n + i + r] += m[(r, c)];
                self.rate[(j + c) * self.n + i + r] += m[(r, c)];
            }
        }
    }

    /// Adds `v` to the residual at local row `i`.
    #[inline]
    pub fn add_res(&mut self, i: usize, v: &Vector3<f64>) {
        self.res[i] += v.x;
        self.res[i + 1] += v.y;
        self.res[i + 2] += v.z;
    }

    /// Adds a two-node element's residual computed in 12-component dual numbers (seeded on
    /// `[δx₁, δΘ₁, δx₂, δΘ₂]`): the values to the residual, their derivatives to the first
    /// 12 columns of the tangent (CAME and CLEARANCE).
    pub fn add_dual12(&mut self, res: &[Vector3<num_dual::DualSVec64<12>>; 4]) {
        for (blk, v) in res.iter().enumerate() {
            for comp in 0..3 {
                let row = 3 * blk + comp;
                self.res[row] += v[comp].re;
                if let Some(eps) = &v[comp].eps.0 {
                    for col in 0..12 {
                        self.tan[col * self.n + row] += eps[col];
                    }
                }
            }
        }
    }

    /// Adds a 3×3 block at local (row `i`, column `j`).
    #[inline]
    pub fn add_block(&mut self, i: usize, j: usize, m: &Matrix3<f64>) {
        for c in 0..3 {
            for r in 0..3 {
                self.tan[(j + c) * self.n + i + r] += m[(r, c)];
            }
        }
    }

    /// Entry (row `i`, column `j`) of the tangent.
    #[inline]
    pub fn tan_at(&self, i: usize, j: usize) -> f64 {
        self.tan[j * self.n + i]
    }

    /// Adds `v` at entry (row `i`, column `j`) of the tangent.
    #[inline]
    pub fn add_tan(&mut self, i: usize, j: usize, v: f64) {
        self.tan[j * self.n + i] += v;
    }
}

/// One element of the model, as the solver sees it.
///
/// Implementations live one per file in this module. An element computes its own
/// contribution from the states of its nodes; it never knows the integrator (the
/// coefficients come in [`EvalContext`]).
pub trait Element: Send + Sync {
    /// The user's element number.
    fn id(&self) -> ElementId;

    /// Dense indices of the connected nodes (into the solver's node array).
    fn nodes(&self) -> &[usize];

    /// Number of Lagrange multipliers the element owns.
    fn multipliers(&self) -> usize {
        0
    }

    /// Residual and, when `tangent` is true, iteration matrix, into `out` (already
    /// cleared). `lambda` holds the element's (scaled) multipliers.
    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    );

    /// Kinetic, strain and gravity energies at the current state.
    fn energies(&self, _nodes: &[NodeState], _gravity: &Vector3<f64>) -> Energies {
        Energies::default()
    }

    /// Called once a step is accepted (to update history variables, e.g. contact state).
    fn commit(&mut self, _ctx: &EvalContext, _nodes: &[NodeState], _lambda: &[f64]) {}

    /// Column names of this element's output file (after `t`).
    fn output_header(&self) -> Vec<String> {
        Vec::new()
    }

    /// Appends the values of this element's output row, matching
    /// [`Element::output_header`], to `row` (the output writer reuses one buffer: no
    /// allocation per row).
    fn write_output_row(
        &self,
        _ctx: &EvalContext,
        _nodes: &[NodeState],
        _lambda: &[f64],
        _row: &mut Vec<f64>,
    ) {
    }

    /// This element's output row as a new vector (see [`Element::write_output_row`]).
    fn output_row(&self, ctx: &EvalContext, nodes: &[NodeState], lambda: &[f64]) -> Vec<f64> {
        let mut row = Vec::new();
        self.write_output_row(ctx, nodes, lambda, &mut row);
        row
    }

    /// Largest constraint violation (position m, angle rad) at the state; 0 for elements
    /// without constraints.
    fn constraint_violation(&self, _nodes: &[NodeState]) -> f64 {
        0.0
    }

    /// Magnitude of the separate terms of the element's forces (N or N·m), e.g.
    /// `max(|m ẍ|, |J Ω̇|, |Ω × JΩ|, |m g|)`: terms that cancel in the residual at
    /// equilibrium but set the scale Newton's residual is measured against. Default 0.
    fn force_scale(&self, _nodes: &[NodeState], _gravity: &Vector3<f64>) -> f64 {
        0.0
    }

    /// A diagnosis of the element at a state, for the message of a failed step (e.g. a
    /// universal joint at its singular configuration); `None` = nothing to say (default).
    fn diagnose(&self, _nodes: &[NodeState]) -> Option<String> {
        None
    }

    /// Element facts for `summary.json` (e.g. number of impacts of a contact).
    fn summary(&self) -> Option<serde_json::Value> {
        None
    }

    /// The frequencies (Hz, ascending) of the modes the element carries as its own
    /// coordinates — a reduced body's kept fixed-interface modes — which `--check` and
    /// `modes` list with what the deck's step resolves of them. `None` for an element
    /// without such modes.
    fn own_modes_hz(&self) -> Option<Vec<f64>> {
        None
    }

    /// The mesh the element draws at a state beyond the model's nodes (ParaView output,
    /// `OUTPUT … VTK`): a superelement's deformed FE mesh. `None` by default.
    fn mesh(&self, _nodes: &[NodeState]) -> Option<ElementMesh> {
        None
    }

    /// Time derivatives `[∂Φ_k/∂t, ∂²Φ_k/∂t²]` of the element's `k`-th constraint
    /// (unscaled) at time `t`: zero for a scleronomic joint (the default), `[−a ḟ, −a f̈]`
    /// for a driver's `g(q) − a f(t)` ([`drive::TimeLaw`]). The integrator's start imposes
    /// `B v + Φ_t = 0` and `B v̇ + Ḃ v + Φ_tt = 0` with them.
    fn constraint_time_derivatives(&self, _t: f64, _k: usize) -> [f64; 2] {
        [0.0; 2]
    }

    /// `B(q) v` of each of the element's multiplier rows, unscaled (`∂Φ_k/∂t` left out),
    /// into `out` (`multipliers()` long): the derivative of `Φ` along the nodes' velocities,
    /// `x + εv`, `R exp(εΩ̃)` (material `Ω`). `false` when the element does not give it
    /// (the default): the solver then takes `s B` from the constraint rows of its tangent,
    /// exact too but a whole tangent's cost. The ESDIRK stages' velocity-level rows and the
    /// index-1 reactions' `Ḃv` use it (`solver/integrator/multipliers.rs`).
    fn constraint_rates(&self, _nodes: &[NodeState], _out: &mut [f64]) -> bool {
        false
    }

    /// Whether the element's forces on its nodes' translations turn with the nodes' frames
    /// and its moments are material: `f_x(Qx, QR) = Q f_x(x, R)`, `m(Qx, QR) = m(x, R)` for
    /// a rigid turn `Q` of its nodes (a deformable body: beams). Modified Newton applies a
    /// kept matrix in such nodes' co-rotated frames (`solver/integrator/corotated.rs`).
    /// Default: no (a joint's rows and a rigid body's are exact in the global frame).
    fn turns_with_its_nodes(&self) -> bool {
        false
    }

    /// Whether a constraint of the element depends on time (a driver). Default: no.
    fn rheonomic(&self) -> bool {
        false
    }

    /// Whether the element delivers work through [`Element::input_power`]: a driver
    /// (rheonomic, the default) or a controlled input ([`control::Control`]).
    fn does_work(&self) -> bool {
        self.rheonomic()
    }

    /// Power the element's drivers deliver to the system at the state, W: for a driver
    /// row `Φ = g(q) − a f(t)` with multiplier `μ = sλ̂ + pΦ`, the constraint force `−Bᵀμ`
    /// does `−μ B v = −μ a ḟ` (on the constraint); the energy balance integrates it as
    /// external work. Default 0.
    fn input_power(&self, _ctx: &EvalContext, _nodes: &[NodeState], _lambda: &[f64]) -> f64 {
        0.0
    }

    /// Dissipated power of element damping (contact dashpot, material damping), W, at the
    /// current state: for the energy balance.
    fn dissipated_power(&self, _nodes: &[NodeState]) -> f64 {
        0.0
    }

    /// A driver's time law (a driven HINGE/PRISMATIC, a PRESCRIBED), for a program that
    /// sets its value between steps ([`drive::TimeLaw::set_value`]). Default: none.
    fn drive_law_mut(&mut self) -> Option<&mut drive::TimeLaw> {
        None
    }

    /// Whether the last [`Element::commit`] switched the element's force law
    /// discontinuously (a contact's dashpot acting from a touch event on): the integrator
    /// then recomputes consistent accelerations at the committed state, as at `t = 0`,
    /// so that no step straddles the jump. Default: never.
    fn restart(&self) -> bool {
        false
    }

    /// Its history variables, for a checkpoint (default: none). **An element that keeps
    /// anything from one evaluation or step to the next** (what [`Element::commit`]
    /// updates, interior-mutable attempt memory) must return all of it here and take it
    /// back in [`Element::restore_state`]: a restart is bit for bit only if it does
    /// (`tests/restart_state.rs` checks the elements with a history).
    fn save_state(&self) -> ElementState {
        ElementState::Stateless
    }

    /// Restores what [`Element::save_state`] returned; a state of another kind of element
    /// is refused.
    fn restore_state(&mut self, state: &ElementState) -> Result<(), StateMismatch> {
        match state {
            ElementState::Stateless => Ok(()),
            _ => Err(StateMismatch { element: self.id() }),
        }
    }

    /// Whether the element acts on the rotation of its `k`-th node (in
    /// [`Element::nodes`]) at any time of a run: a node whose rotations no element acts on
    /// (a point mass alone, a bouncing ball) has them held by the solver, which would
    /// otherwise face a singular matrix ([`crate::solver::idle`]). The default,
    /// [`RotationUse::AsEvaluated`], reads it from the element's iteration matrix at the
    /// initial state, right for every element whose coupling does not switch on later;
    /// elements whose forces appear only at events (contacts) say it themselves.
    fn rotation_use(&self, _k: usize) -> RotationUse {
        RotationUse::AsEvaluated
    }

    /// Whether its forces come and go with events (a contact: touch and release), so that
    /// the linearised model about one state says nothing of the run after the next event:
    /// the adaptive steps' drift filter leaves such elements out
    /// (`solver::integrator::drift`). Default: no.
    fn intermittent(&self) -> bool {
        false
    }

    /// Event (impact) control of a converged trial step from `old` to `new` (step
    /// `ctx.h`), asked before the step is committed. `None` = no opinion (the default).
    /// The integrator refuses the step when `ctx.h > accept_up_to` (and retries with
    /// `retry`), and otherwise caps the next step at `next`.
    fn step_limit(
        &self,
        _ctx: &EvalContext,
        _old: &[NodeState],
        _new: &[NodeState],
    ) -> Option<StepLimit> {
        None
    }
}

/// How an element acts on one of its nodes' rotations over a run
/// ([`Element::rotation_use`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RotationUse {
    /// As its iteration matrix (stiffness, damping, mass, constraint rows) at the initial
    /// state shows: an all-zero rotational column means never.
    AsEvaluated,
    /// It may act on them (a contact's moment), whatever the initial state shows.
    Always,
    /// It never does.
    Never,
}

/// An element's verdict on a converged step (see [`Element::step_limit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepLimit {
    /// Refuse the step if it was longer than this, s.
    pub accept_up_to: f64,
    /// The step to retry with when refused, s.
    pub retry: f64,
    /// The largest next step when accepted, s.
    pub next: f64,
    /// A refusal because the step cannot resolve the event at all (longer than the
    /// impact's resolution `π/(ω · IMPACT_STEPS)` times the slack, or it jumped over a
    /// whole impact), not merely to land an event time more precisely. At the run's
    /// smallest step the integrator accepts a landing refusal (the event is then timed
    /// within that step) but stops on an unresolved one
    /// ([`crate::solver::FailureReason::EventUnresolved`]).
    pub unresolved: bool,
}

/// Index of node `k`'s translational block in a local vector.
#[inline]
pub fn tx(k: usize) -> usize {
    6 * k
}

/// Index of node `k`'s rotational block in a local vector.
#[inline]
pub fn rx(k: usize) -> usize {
    6 * k + 3
}

/// Generic checks stamped on every element (fenris-style): the iteration matrix equals a
/// central finite difference of the residual, and a rigid motion rotates the forces.
#[cfg(test)]
pub(crate) mod testing;
