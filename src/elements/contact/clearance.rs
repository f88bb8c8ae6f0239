//! CLEARANCE: a revolute joint with radial clearance — a journal (second node) free to
//! move inside a bearing (first node) until it hits the bearing's wall (Flores & Ambrósio
//! 2004, Computers & Structures 82: 1359–1369, §2–3; Lankarani & Nikravesh 1990, J. Mech.
//! Des. 112: 369–376).
//!
//! # Kinematics (planar clearance)
//! The bearing's axis `a = R_b a₀` is fixed to the bearing node (`a₀` the deck's `AXIS`,
//! global at t = 0, when every node's orientation is the identity). With `d = x_j − x_b`
//! the journal centre relative to the bearing centre, the **eccentricity** is its part in
//! the plane normal to the axis, `e = d − a (a·d)` (Flores & Ambrósio eq. 1), the normal
//! `n = e/|e|` (from the bearing centre towards the journal's side), and the
//! **penetration** `δ = |e| − c` (eq. 4), `c = R_b − R_j` the radial clearance; contact
//! when `δ > 0`. Its rate is `δ̇ = n·(ḋ − ω_b × d)` (`ω_b` the bearing's angular velocity,
//! global): the exact `d|e|/dt` (the terms of the turning axis reduce to this because
//! `n·a = 0` and `n·(ω_b × e) = 0`).
//!
//! Only the in-plane eccentricity is a contact: the axial offset `a·d` and the tilt of the
//! journal are left free. This is the classical planar clearance joint of Flores &
//! Ambrósio and Lankarani & Nikravesh, and in a planar mechanism the other joints already
//! hold the out-of-plane motion (the connecting rod of a slider-crank is held by its crank
//! hinge): ideal axial or tilt constraints added here would repeat theirs — redundant
//! equations and a singular iteration matrix. A spatial mechanism that needs them adds a
//! joint of its own.
//!
//! # Force laws ([`crate::model::ContactLaw`])
//! The normal force `F ≥ 0` (compressive) acts on the journal along `−n` through its
//! centre, and on the bearing along `+n` on the same line (no net moment: the pair
//! conserves angular momentum):
//! - Kelvin–Voigt, the seed's law (Sampaio & Barrientos eq. [17], as CAME):
//!   `F = max(k δ + c δ̇, 0)`;
//! - Lankarani–Nikravesh (1990, eq. 23; Flores & Ambrósio eq. 9), hysteresis damping on
//!   a Hertz law: `F = max(K δⁿ (1 + 3(1 − e²)/4 · δ̇/δ̇⁻), 0)`, `δ̇⁻` the approach speed
//!   of the impact (recorded at the touch event, floored at `VMIN`), `n` the Hertz
//!   exponent (1.5), `e` the restitution coefficient the law is built to give for
//!   `e → 1` (its effective restitution differs from `e` at lower values: tests/clearance.rs).
//!
//! Friction (optional), regularised Coulomb as CAME's: the circumferential slip
//! `v_t = (I − n nᵀ − a aᵀ)(v_j(p) − v_b(p))` of the two bodies' material points at the
//! journal's contact point `p = x_j + R_j n`, force `−μ F v_t/√(|v_t|² + v_reg²)` on the
//! journal at `p`, the opposite on the bearing at the same point.
//!
//! # Events, tangent, history
//! As CAME (see [`super::came`]): the dashpot acts from a landed touch event on (steps
//! from a state apart use the spring alone), touch located by the cubic Hermite root of
//! the gap, separation landed just past, impacts resolved by `IMPACT_STEPS` steps of the
//! contact frequency `ω = √(k_t/m_eff)` (`k_t = ∂F/∂δ`, `m_eff = F/n·(ẍ_j − ẍ_b)`), the
//! anti-chatter memory of the active set shared with CAME. The tangent is exact: the
//! kernel is generic in the scalar and differentiated by dual numbers in 12 directions.

use crate::elements::BuildError;
use crate::elements::came::law::ActiveSetMemory;
use crate::elements::registry::{Kind, node_index, not_mine};
use crate::model::{ClearanceData, ContactLaw, ElementId, ElementKind};
use nalgebra::Vector3;
use std::sync::atomic::AtomicU64;

/// The element half of `CLEARANCE` (`crate::kinds`).
pub const KIND: Kind = Kind {
    types: &["CLEARANCE"],
    build: |model, el| {
        let ElementKind::Clearance(data) = &el.kind else {
            return Err(not_mine(el, "CLEARANCE"));
        };
        let nodes = [
            node_index(model, &el.nodes[0]),
            node_index(model, &el.nodes[1]),
        ];
        let c = Clearance::new(el.id, nodes, data).map_err(|message| BuildError::Invalid {
            element: el.id,
            message,
        })?;
        Ok(Box::new(c))
    },
};

/// The CLEARANCE element (nodes: bearing, journal).
#[derive(Debug)]
pub struct Clearance {
    id: ElementId,
    nodes: [usize; 2],
    /// Bearing axis in the bearing node's material frame.
    a0: Vector3<f64>,
    /// Radial clearance `c`, m.
    c: f64,
    /// Journal radius `R_j = R_b − c`, m.
    r_j: f64,
    law: ContactLaw,
    mu: f64,
    vreg: f64,
    vmin: f64,
    impact_steps: u32,
    // Committed history.
    /// Closed (or landed on a touch event): the next step uses the full (damped) law.
    touching: bool,
    /// Gap (≥ 0) up to which a `touching` contact still counts as closed.
    touch_tol: f64,
    /// The last commit switched `touching`: the integrator restarts its accelerations.
    restart: bool,
    /// The force was non-zero at the last commit.
    active: bool,
    /// Approach speed `δ̇⁻` of the current impact (Lankarani–Nikravesh), m/s.
    approach: f64,
    impacts: u64,
    /// Steps accepted in contact though longer than the impact resolution asks (the run
    /// could not cut them: MINSTEP), reported in the summary.
    unresolved: u64,
    max_penetration: f64,
    max_force: f64,
    dissipated: f64,
    last_power: f64,
    omega: f64,
    /// ω estimated at the last trial state (bits of an f64).
    omega_trial: AtomicU64,
    memory: ActiveSetMemory,
}

/// The history of a [`Clearance`], for checkpoints.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClearanceState {
    touching: bool,
    touch_tol: f64,
    restart: bool,
    active: bool,
    approach: f64,
    impacts: u64,
    unresolved: u64,
    max_penetration: f64,
    max_force: f64,
    dissipated: f64,
    last_power: f64,
    omega: f64,
    omega_trial: u64,
    memory: (u64, u32, bool),
}

/// The kinematic and force quantities of the joint at a state.
#[derive(Debug, Clone, Copy)]
pub struct JointState<S> {
    /// Eccentricity vector `e` (global), m.
    pub ecc: Vector3<S>,
    /// Penetration `δ = |e| − c`, m (negative = apart).
    pub pen: S,
    /// Penetration rate `δ̇`, m/s.
    pub pen_rate: S,
    /// Raw normal force of the law (before clipping; spring alone when undamped), N.
    pub force: S,
    /// Elastic part of the force (`k δ` or `K δⁿ`), N.
    pub elastic: S,
    /// Unit normal `n` (global).
    pub normal: Vector3<S>,
    /// Circumferential slip velocity at the contact point, m/s.
    pub slip: Vector3<S>,
    /// Friction force on the journal, N.
    pub friction: Vector3<S>,
    /// Residual blocks `[x_b, Θ_b, x_j, Θ_j]`.
    pub res: [Vector3<S>; 4],
}

impl Clearance {
    /// Builds the element on dense nodes `[bearing, journal]`.
    pub fn new(id: ElementId, nodes: [usize; 2], d: &ClearanceData) -> Result<Self, String> {
        if !(d.clearance > 0.0 && d.clearance < d.radius) {
            return Err(format!(
                "the clearance {} must be positive and less than the bearing radius {}",
                d.clearance, d.radius
            ));
        }
        let a0 = d
            .axis
            .try_normalize(0.0)
            .ok_or("the axis must be non-zero")?;
        Ok(Clearance {
            id,
            nodes,
            a0,
            c: d.clearance,
            r_j: d.radius - d.clearance,
            law: d.law,
            mu: d.friction,
            vreg: d.friction_speed.max(1e-300),
            vmin: d.min_approach.max(1e-300),
            impact_steps: d.impact_steps.max(1),
            touching: false,
            touch_tol: 0.0,
            restart: false,
            active: false,
            approach: d.min_approach.max(1e-300),
            impacts: 0,
            unresolved: 0,
            max_penetration: 0.0,
            max_force: 0.0,
            dissipated: 0.0,
            last_power: 0.0,
            omega: 0.0,
            omega_trial: AtomicU64::new(0),
            memory: ActiveSetMemory::new(),
        })
    }
}

mod element;
mod events;
mod kernel;
#[cfg(test)]
mod tests;
