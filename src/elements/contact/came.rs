//! CAME: cam–follower contact and shock (Cardona & Géradin 1993; physics.md §5, eq. [16]–[17]).
//!
//! # Kinematics: element-level closest-point projection
//! The paper adds `x_C, x_D, η, ζ` as unknowns tied by the constraints φ1…φ8 (C and D on the
//! profiles, the normal of one profile orthogonal to the tangent of the other, D on the
//! normal through C). Here the same conditions are solved *inside the element* at every
//! evaluation: no extra unknowns, no multipliers, nothing in the global system when the
//! bodies are apart. The converged answer is the same (the constraints define the same
//! points C, D and the same gap), and the projection is exact in closed form for a line, a
//! point and a circle, and Newton-solved for a spline (see [`super::profile`]).
//!
//! One of the two profiles plays the *surface* (a LINE, CIRCLE or SPLINE, with its free
//! side given by its normal `ν`), the other the *roller*: a POINT (radius 0) or a CIRCLE of
//! radius `ρ`, i.e. a point offset by `ρ` along the normal. The cam is the surface when it
//! is a curve and the follower a point or a circle; with a POINT or CIRCLE cam and a LINE or
//! SPLINE follower (e.g. an eccentric disc under a flat follower) the roles swap. CIRCLE on
//! CIRCLE: the cam is the surface. The roller's axis is assumed parallel to the surface's
//! extrusion axis (planar cam mechanisms), so the contact is the in-plane distance.
//!
//! With `p` the roller centre (global) and `ℓ` its coordinates in the surface's profile
//! frame, the projection gives the closest point `γ(η)` and the normal `ν(η)`; then
//! `n = R_s F_s ν` (global), the normal gap `q_n = ν·(ℓ − γ) − ρ`, the contact points
//! `C = p − (q_n + ρ) n` (surface) and `D = p − ρ n` (roller), and the gap rate
//! `q̇_n = n·(ṗ − v_s − ω_s × (p − x_s))`. When the cam is the surface, `n = n_C`; when the
//! roles swap, `n_C = −n` (same gap).
//!
//! # Force law (eq. [17])
//! The compressive normal force (positive, on the roller body along `+n`):
//! `P = −(k q_n + c q̇_n)` while `q_n < 0`, nothing otherwise. With `CLIP ON` (the default)
//! the force is `max(P, 0)`: the dashpot never pulls the bodies together at the end of an
//! impact. The normal force acts along the line through `p` (so through C and D). Coulomb
//! friction, regularised: `f_t = −μ |P| v_t / √(|v_t|² + v_reg²)` with `v_t` the
//! tangential relative velocity of the material points at the contact, applied at the
//! midpoint of C and D (equal and opposite on the two bodies).
//!
//! # Tangent
//! The exact derivative of the nodal forces by forward-mode automatic differentiation
//! (dual numbers, 12 directions `[δx_A, δΘ_A, δx_B, δΘ_B]`, each seeding the positions by
//! `1` and the velocities by `c_v`): the stiffness `k n nᵀ`, the rotation of the normal and
//! the curvature of the profile (through the derivative of the projection), the dashpot's
//! `c_v c n nᵀ` and its dependence on the positions, and the friction terms — all
//! consistent by construction.
//!
//! # Active set and impacts
//! The active set is decided from the state being evaluated. Newton must not chatter
//! between contact and separation: within one step attempt (same `t`, `h`), after
//! [`MAX_FLIPS`] changes of the active flag the flag is frozen, for the rest of that
//! attempt, at its last value.
//! After a converged step, [`Element::max_step`] estimates the contact frequency from the
//! converged state (`ω² = k/m_eff`, `m_eff = P / q̈_n`, the effective mass seen by the
//! contact force), and asks for steps no longer than `π/(ω · impact_steps)`; a step that
//! jumped over a whole impact (approaching at the start, receding at the end, and a free
//! flight that would have gone through the surface) is refused too.
//!
//! When the bodies are apart, evaluation costs one transformation of `p` and a distance
//! check (exact for lines and circles, a bounding circle for closed splines).

use super::profile::Curve;
use crate::elements::BuildError;
use crate::elements::registry::{Kind, node_index, not_mine};
use crate::model::{CameData, ElementId, ElementKind, Profile};
use nalgebra::{Matrix3, Vector3};
use num_dual::DualSVec64;
use std::sync::atomic::AtomicU64;

/// Changes of the active flag tolerated within one step attempt before it is frozen.
pub const MAX_FLIPS: u32 = 4;

/// A step is refused when it is longer than this factor times the impact step limit
/// (slack so that the limit, re-estimated at each step, does not make steps chatter).
pub const LIMIT_SLACK: f64 = 1.5;

/// A step that crosses a separation should end past it by about this fraction of an
/// impact step (and is refused beyond twice that).
pub const LAND: f64 = 0.02;

/// A step that crosses a touch event is refused unless it ends within this fraction of a
/// step of the event (it is then *at* the event: see [`Came::step_limit`]).
pub const EVENT_TOL: f64 = 1e-4;

/// The kinematic and force quantities of a contact at a state.
#[derive(Debug, Clone, Copy)]
pub struct ContactState<S> {
    /// Normal gap `q_n`, m (negative = penetration).
    pub gap: S,
    /// Gap rate `q̇_n`, m/s.
    pub gap_rate: S,
    /// Raw compressive normal force `−(k q_n + c q̇_n)`, N (before clipping).
    pub force: S,
    /// Unit normal of the surface (global, towards its free side).
    pub normal: Vector3<S>,
    /// Contact point on the surface.
    pub on_surface: Vector3<S>,
    /// Contact point on the roller.
    pub on_roller: Vector3<S>,
    /// Curvilinear coordinate on the surface.
    pub eta: S,
    /// Tangential relative velocity (roller material point minus surface material point).
    pub slip: Vector3<S>,
    /// Residual blocks `[x_A, Θ_A, x_B, Θ_B]` (cam node first).
    pub res: [Vector3<S>; 4],
    /// Friction force on the roller body.
    pub friction: Vector3<S>,
}

/// The element half of `CAME` (`crate::kinds`).
pub const KIND: Kind = Kind {
    types: &["CAME"],
    build: |model, el| {
        let ElementKind::Came(data) = &el.kind else {
            return Err(not_mine(el, "CAME"));
        };
        let nodes = [
            node_index(model, &el.nodes[0]),
            node_index(model, &el.nodes[1]),
        ];
        match Came::new(el.id, nodes, data) {
            Ok(c) => Ok(Box::new(c)),
            Err(message) => Err(BuildError::Invalid {
                element: el.id,
                message,
            }),
        }
    },
};

/// The CAME element.
#[derive(Debug)]
pub struct Came {
    id: ElementId,
    nodes: [usize; 2],
    k: f64,
    c: f64,
    mu: f64,
    vreg: f64,
    clip: bool,
    impact_steps: u32,
    curve: Curve,
    /// Local index (0 = cam, 1 = follower) of the surface's node.
    s: usize,
    /// Surface profile: offset (node frame) and frame.
    o_s: Vector3<f64>,
    f_s: Matrix3<f64>,
    /// Roller centre offset (node frame), radius, and its profile frame (for ζ).
    o_p: Vector3<f64>,
    rho: f64,
    f_p: Matrix3<f64>,
    // Committed history.
    active: bool,
    /// The committed state is in contact or exactly at a touch event: the next step uses
    /// the full law (spring and dashpot). Steps from a state apart use the spring alone,
    /// so the step that lands on a touch does not feel the dashpot's jump `c q̇_n`.
    touching: bool,
    /// Gap (≥ 0) up to which a `touching` contact still counts as closed: the landing
    /// tolerance of the touch event.
    touch_tol: f64,
    /// The last commit switched `touching` on: the integrator restarts its accelerations.
    restart: bool,
    impacts: u64,
    max_penetration: f64,
    dissipated: f64,
    last_power: f64,
    omega: f64,
    /// ω estimated at the last trial state (bits of an f64).
    omega_trial: AtomicU64,
    // Per-attempt active-set memory (interior mutability: `evaluate` takes `&self`).
    memory: law::ActiveSetMemory,
}

/// The history of a [`Came`] (committed contact state, counters, and the attempt memory
/// of the active set), for checkpoints.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CameState {
    active: bool,
    touching: bool,
    touch_tol: f64,
    restart: bool,
    impacts: u64,
    max_penetration: f64,
    dissipated: f64,
    last_power: f64,
    omega: f64,
    omega_trial: u64,
    attempt: u64,
    flips: u32,
    last_flag: bool,
}

type D12 = DualSVec64<12>;

impl Came {
    /// Builds the element on dense nodes `[cam, follower]`.
    pub fn new(id: ElementId, nodes: [usize; 2], d: &CameData) -> Result<Self, String> {
        let cam = Curve::from_profile(&d.cam.profile)?;
        let fol = Curve::from_profile(&d.follower.profile)?;
        let radius = |p: &Profile| match p {
            Profile::Circle { radius } => Some(*radius),
            Profile::Point => Some(0.0),
            _ => None,
        };
        // Which profile is the surface.
        let (s, curve) = match (&d.cam.profile, &d.follower.profile) {
            (Profile::Point, Profile::Point) => {
                return Err("a POINT cam and a POINT follower never touch: give one of them as a LINE, CIRCLE or SPLINE".into());
            }
            (_, Profile::Point | Profile::Circle { .. }) if cam.is_some() => {
                (0, cam.expect("curve"))
            }
            (Profile::Point | Profile::Circle { .. }, _) => (1, fol.expect("curve")),
            _ => {
                return Err("CAME needs a POINT or a CIRCLE on one side (curve against curve is not supported): make the follower a POINT or a CIRCLE (roller)".into());
            }
        };
        let (surf, roll) = if s == 0 {
            (&d.cam, &d.follower)
        } else {
            (&d.follower, &d.cam)
        };
        Ok(Came {
            id,
            nodes,
            k: d.stiffness,
            c: d.damping,
            mu: d.friction,
            vreg: d.friction_speed.max(1e-300),
            clip: d.clip_tension,
            impact_steps: d.impact_steps.max(1),
            curve,
            s,
            o_s: surf.offset,
            f_s: surf.frame,
            o_p: roll.offset,
            rho: radius(&roll.profile).unwrap_or(0.0),
            f_p: roll.frame,
            active: false,
            touching: false,
            touch_tol: 0.0,
            restart: false,
            impacts: 0,
            max_penetration: 0.0,
            dissipated: 0.0,
            last_power: 0.0,
            omega: 0.0,
            omega_trial: AtomicU64::new(0),
            memory: law::ActiveSetMemory::new(),
        })
    }
}

mod element;
pub(crate) mod events;
mod geometry;
pub(crate) mod law;
#[cfg(test)]
mod tests;
