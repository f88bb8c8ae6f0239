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

use super::profile::{Curve, Projection, c};
use super::{
    Element, ElementState, Energies, EvalContext, Local, NodeState, StateMismatch, StepLimit,
};
use crate::model::{CameData, ElementId, Profile};
use nalgebra::{Matrix3, RealField, SVector, Vector2, Vector3};
use num_dual::{Derivative, DualSVec64};
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};

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
    attempt: AtomicU64,
    flips: AtomicU32,
    last_flag: AtomicBool,
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
            attempt: AtomicU64::new(u64::MAX),
            flips: AtomicU32::new(0),
            last_flag: AtomicBool::new(false),
        })
    }

    /// In-plane coordinates of the roller centre in the surface's profile frame (f64).
    fn local_point(&self, nodes: &[NodeState]) -> Vector3<f64> {
        let (ss, sp) = (&nodes[self.nodes[self.s]], &nodes[self.nodes[1 - self.s]]);
        let p = sp.x + sp.r * self.o_p;
        self.f_s.transpose() * (ss.r.transpose() * (p - ss.x) - self.o_s)
    }

    /// The parameter of the closest point, or `None` when the bodies are certainly apart.
    fn candidate(&self, nodes: &[NodeState]) -> Option<f64> {
        let l = self.local_point(nodes);
        let l2 = Vector2::new(l.x, l.y);
        if self
            .curve
            .quick_distance(&l2)
            .is_some_and(|d| d - self.rho >= 0.0)
        {
            return None;
        }
        Some(self.curve.closest_parameter(&l2))
    }

    /// [`Came::kernel`] in f64 at the element's two node states.
    fn kernel_at(
        &self,
        nodes: &[NodeState],
        eta0: f64,
        force_on: bool,
        damped: bool,
    ) -> ContactState<f64> {
        let (a, b) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        self.kernel(
            [a.x, b.x],
            [a.r, b.r],
            [a.v, b.v],
            [a.w, b.w],
            eta0,
            force_on,
            damped,
        )
    }

    /// The contact kernel, generic in the scalar: gap, rate, force and nodal residual
    /// (computed as if in contact with the raw force `P`; `force_on` false gives zero
    /// forces).
    #[allow(clippy::too_many_arguments)]
    fn kernel<S: RealField + Copy>(
        &self,
        x: [Vector3<S>; 2],
        r: [Matrix3<S>; 2],
        v: [Vector3<S>; 2],
        w: [Vector3<S>; 2],
        eta0: f64,
        force_on: bool,
        damped: bool,
    ) -> ContactState<S> {
        let (si, pi) = (self.s, 1 - self.s);
        let (xs, rs, vs, ws) = (x[si], r[si], v[si], r[si] * w[si]);
        let (xp, rp, vp, wp) = (x[pi], r[pi], v[pi], r[pi] * w[pi]);
        let o_p: Vector3<S> = self.o_p.map(c);
        let o_s: Vector3<S> = self.o_s.map(c);
        let f_s: Matrix3<S> = self.f_s.map(c);
        let rho = c::<S>(self.rho);
        let arm_p = rp * o_p;
        let p = xp + arm_p;
        let l = f_s.transpose() * (rs.transpose() * (p - xs) - o_s);
        let pr: Projection<S> = self.curve.project(&Vector2::new(l.x, l.y), eta0);
        let n = rs * (f_s * Vector3::new(pr.normal.x, pr.normal.y, S::zero()));
        let gap = pr.normal.dot(&(Vector2::new(l.x, l.y) - pr.point)) - rho;
        let pdot = vp + wp.cross(&arm_p);
        let gap_rate = n.dot(&(pdot - vs - ws.cross(&(p - xs))));
        let c_n = if damped { self.c } else { 0.0 };
        let force = -(c::<S>(self.k) * gap + c::<S>(c_n) * gap_rate);
        let on_surface = p - n * (gap + rho);
        let on_roller = p - n * rho;
        let mid = (on_surface + on_roller) * c::<S>(0.5);
        let vr = vp + wp.cross(&(on_roller - xp)) - vs - ws.cross(&(on_surface - xs));
        let slip = vr - n * n.dot(&vr);
        let zero = Vector3::zeros();
        let mut res = [zero; 4];
        let mut friction = zero;
        if force_on {
            let fn_ = n * force;
            if self.mu > 0.0 {
                let reg = (slip.dot(&slip) + c::<S>(self.vreg * self.vreg)).sqrt();
                friction = slip * (-(c::<S>(self.mu) * force.abs()) / reg);
            }
            let f = fn_ + friction;
            // Roller body: force f; moments of the normal part about x_p through p, of the
            // friction at the midpoint.
            let mp = arm_p.cross(&fn_) + (mid - xp).cross(&friction);
            let ms = (p - xs).cross(&fn_) + (mid - xs).cross(&friction);
            res[2 * pi] = -f;
            res[2 * pi + 1] = -(rp.transpose() * mp);
            res[2 * si] = f;
            res[2 * si + 1] = rs.transpose() * ms;
        }
        ContactState {
            gap,
            gap_rate,
            force,
            normal: n,
            on_surface,
            on_roller,
            eta: pr.eta,
            slip,
            res,
            friction,
        }
    }

    /// The contact state at `nodes` in f64 (`None` when certainly apart), with the force
    /// law of the step that starts from the committed state (see `touching`).
    pub fn state(&self, nodes: &[NodeState]) -> Option<ContactState<f64>> {
        let eta0 = match self.candidate(nodes) {
            Some(e) => e,
            None if self.touching => {
                let l = self.local_point(nodes);
                self.curve.closest_parameter(&Vector2::new(l.x, l.y))
            }
            None => return None,
        };
        Some(self.kernel_at(nodes, eta0, false, self.touching))
    }

    /// The contact state at `nodes` in f64, computed even when the bodies are apart.
    pub fn full_state(&self, nodes: &[NodeState]) -> ContactState<f64> {
        let l = self.local_point(nodes);
        let eta0 = self.curve.closest_parameter(&Vector2::new(l.x, l.y));
        self.kernel_at(nodes, eta0, false, true)
    }

    /// Whether the contact is closed at a state: penetrating, or within the landing
    /// tolerance of a touch event the committed state sits on.
    fn closed(&self, st: &ContactState<f64>) -> bool {
        st.gap < 0.0 || (self.touching && st.gap <= self.touch_tol)
    }

    /// Gap tolerance of a touch event: the event time is met within [`EVENT_TOL`] of the
    /// step `h` (or of the impact step if shorter), i.e. `EVENT_TOL · h · |q̇_n|`.
    fn touch_tolerance(&self, h: f64, gap_rate: f64) -> f64 {
        let h_imp = if self.omega > 0.0 {
            std::f64::consts::PI / (self.omega * f64::from(self.impact_steps))
        } else {
            f64::INFINITY
        };
        EVENT_TOL * h.min(h_imp) * gap_rate.abs()
    }

    /// The normal force actually applied (compressive, N) for a contact state.
    fn applied(&self, st: &ContactState<f64>) -> f64 {
        if !self.closed(st) {
            0.0
        } else if self.clip {
            st.force.max(0.0)
        } else {
            st.force
        }
    }

    /// Active flag with the per-attempt anti-chatter memory.
    fn active_flag(&self, ctx: &EvalContext, raw: bool) -> bool {
        if !ctx.dynamic || ctx.h <= 0.0 {
            return raw;
        }
        let key = ctx.t.to_bits() ^ ctx.h.to_bits().rotate_left(17);
        if self.attempt.swap(key, Ordering::Relaxed) != key {
            self.flips.store(0, Ordering::Relaxed);
            self.last_flag.store(raw, Ordering::Relaxed);
            return raw;
        }
        let last = self.last_flag.load(Ordering::Relaxed);
        if raw == last {
            return raw;
        }
        if self.flips.fetch_add(1, Ordering::Relaxed) + 1 > MAX_FLIPS {
            return last;
        }
        self.last_flag.store(raw, Ordering::Relaxed);
        raw
    }

    /// Dissipated power (dashpot, clipped spring energy, friction) at a contact state.
    fn power(&self, st: &ContactState<f64>) -> f64 {
        if !self.closed(st) {
            return 0.0;
        }
        let p = self.applied(st);
        // −(power of the contact force on the bodies) − d/dt(½ k q_n²).
        let normal = -(p + self.k * st.gap) * st.gap_rate;
        let fric = if self.mu > 0.0 {
            self.mu * p.abs() * st.slip.norm_squared()
                / (st.slip.norm_squared() + self.vreg * self.vreg).sqrt()
        } else {
            0.0
        };
        normal + fric
    }

    /// Relative normal acceleration of the roller centre (curvature terms neglected).
    fn gap_acceleration(&self, nodes: &[NodeState], n: &Vector3<f64>) -> f64 {
        let (ss, sp) = (&nodes[self.nodes[self.s]], &nodes[self.nodes[1 - self.s]]);
        let ap = sp.a + sp.r * (sp.wd.cross(&self.o_p));
        n.dot(&(ap - ss.a))
    }

    /// Curvilinear coordinate on the roller (ζ = ρ × angle of the roller point in the
    /// roller's profile plane; 0 for a point).
    fn roller_coordinate(&self, nodes: &[NodeState], n: &Vector3<f64>) -> f64 {
        if self.rho == 0.0 {
            return 0.0;
        }
        let sp = &nodes[self.nodes[1 - self.s]];
        let d = self.f_p.transpose() * (sp.r.transpose() * (-n));
        self.rho * d.y.atan2(d.x)
    }
}

impl Element for Came {
    fn id(&self) -> ElementId {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        let eta0 = match self.candidate(nodes) {
            Some(e) => e,
            // Apart: nothing to compute, unless the active set is frozen in contact.
            None if !self.touching && !self.active_flag(ctx, false) => return,
            None => {
                let l = self.local_point(nodes);
                self.curve.closest_parameter(&Vector2::new(l.x, l.y))
            }
        };
        let (a, b) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let damped = self.touching;
        let st = self.kernel_at(nodes, eta0, false, damped);
        let closed = st.gap < 0.0 || (self.touching && st.gap <= self.touch_tol);
        let active = self.active_flag(ctx, closed);
        let force_on = active && (!self.clip || st.force > 0.0);
        if !force_on {
            return;
        }
        if !tangent {
            let st = self.kernel_at(nodes, eta0, true, damped);
            for (blk, v) in st.res.iter().enumerate() {
                out.add_res(3 * blk, v);
            }
            return;
        }
        let seed = |k: usize| {
            D12::new(
                0.0,
                Derivative::derivative_generic(nalgebra::Const::<12>, nalgebra::U1, k),
            )
        };
        let lift = |v: f64| D12::new(v, Derivative::none());
        let cv = lift(ctx.c_v);
        let xs = |x: &Vector3<f64>, base: usize| {
            Vector3::new(
                lift(x.x) + seed(base),
                lift(x.y) + seed(base + 1),
                lift(x.z) + seed(base + 2),
            )
        };
        let vs = |x: &Vector3<f64>, base: usize| {
            Vector3::new(
                lift(x.x) + seed(base) * cv,
                lift(x.y) + seed(base + 1) * cv,
                lift(x.z) + seed(base + 2) * cv,
            )
        };
        let rs = |r: &Matrix3<f64>, base: usize| {
            let dth = Vector3::new(seed(base), seed(base + 1), seed(base + 2));
            let rr: Matrix3<D12> = r.map(lift);
            rr + rr
                * Matrix3::new(
                    lift(0.0),
                    -dth.z,
                    dth.y,
                    dth.z,
                    lift(0.0),
                    -dth.x,
                    -dth.y,
                    dth.x,
                    lift(0.0),
                )
        };
        let st = self.kernel(
            [xs(&a.x, 0), xs(&b.x, 6)],
            [rs(&a.r, 3), rs(&b.r, 9)],
            [vs(&a.v, 0), vs(&b.v, 6)],
            [vs(&a.w, 3), vs(&b.w, 9)],
            eta0,
            true,
            damped,
        );
        let n = out.n;
        for (blk, v) in st.res.iter().enumerate() {
            for comp in 0..3 {
                let row = 3 * blk + comp;
                out.res[row] += v[comp].re;
                if let Some(eps) = &v[comp].eps.0 {
                    let eps: &SVector<f64, 12> = eps;
                    for col in 0..12 {
                        out.tan[col * n + row] += eps[col];
                    }
                }
            }
        }
    }

    fn energies(&self, nodes: &[NodeState], _gravity: &Vector3<f64>) -> Energies {
        let strain = match self.state(nodes) {
            Some(st) if st.gap < 0.0 => 0.5 * self.k * st.gap * st.gap,
            _ => 0.0,
        };
        Energies {
            strain,
            ..Energies::default()
        }
    }

    fn commit(&mut self, ctx: &EvalContext, nodes: &[NodeState], _lambda: &[f64]) {
        // Dissipation over the step, with the law the step used.
        let power = self.state(nodes).map_or(0.0, |st| self.power(&st));
        self.dissipated += 0.5 * (self.last_power + power) * ctx.h;
        // Touch event: a state apart within the landing tolerance of the surface and
        // approaching it is *at* the event; from there the full law acts, and the
        // integrator restarts its accelerations with it (one-sided limits of the force).
        let was = self.touching;
        if ctx.dynamic {
            let fs = self.full_state(nodes);
            let tol = self.touch_tolerance(ctx.h, fs.gap_rate);
            self.touching = fs.gap < 0.0 || (fs.gap <= tol && fs.gap_rate < 0.0);
            self.touch_tol = if self.touching { tol } else { 0.0 };
        } else {
            self.touching = self.state(nodes).is_some_and(|st| st.gap < 0.0);
            self.touch_tol = 0.0;
        }
        self.restart = ctx.dynamic && self.touching != was;
        let st = self.state(nodes);
        let active = st
            .as_ref()
            .is_some_and(|st| self.closed(st) && self.applied(st) != 0.0);
        if active && !self.active {
            self.impacts += 1;
        }
        self.active = active;
        if let Some(st) = st.as_ref().filter(|s| s.gap < 0.0) {
            self.max_penetration = self.max_penetration.max(-st.gap);
            if let Some(w) = self.omega_estimate(nodes, st) {
                self.omega = w;
            }
        }
        self.last_power = if self.restart && self.touching {
            st.map_or(0.0, |st| self.power(&st))
        } else {
            power
        };
    }

    fn restart(&self) -> bool {
        self.restart
    }

    fn save_state(&self) -> ElementState {
        ElementState::Came(CameState {
            active: self.active,
            touching: self.touching,
            touch_tol: self.touch_tol,
            restart: self.restart,
            impacts: self.impacts,
            max_penetration: self.max_penetration,
            dissipated: self.dissipated,
            last_power: self.last_power,
            omega: self.omega,
            omega_trial: self.omega_trial.load(Ordering::Relaxed),
            attempt: self.attempt.load(Ordering::Relaxed),
            flips: self.flips.load(Ordering::Relaxed),
            last_flag: self.last_flag.load(Ordering::Relaxed),
        })
    }

    fn restore_state(&mut self, state: &ElementState) -> Result<(), StateMismatch> {
        let ElementState::Came(s) = state else {
            return Err(StateMismatch { element: self.id });
        };
        self.active = s.active;
        self.touching = s.touching;
        self.touch_tol = s.touch_tol;
        self.restart = s.restart;
        self.impacts = s.impacts;
        self.max_penetration = s.max_penetration;
        self.dissipated = s.dissipated;
        self.last_power = s.last_power;
        self.omega = s.omega;
        self.omega_trial.store(s.omega_trial, Ordering::Relaxed);
        self.attempt.store(s.attempt, Ordering::Relaxed);
        self.flips.store(s.flips, Ordering::Relaxed);
        self.last_flag.store(s.last_flag, Ordering::Relaxed);
        Ok(())
    }

    fn output_header(&self) -> Vec<String> {
        [
            "active",
            "gap",
            "gap_rate",
            "normal_force",
            "friction_force",
            "xc",
            "yc",
            "zc",
            "eta",
            "zeta",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    }

    fn write_output_row(
        &self,
        _ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        let Some(st) = self.state(nodes) else {
            // Apart: the gap still, from a projection (output only, once per step).
            return self.row(nodes, &self.full_state(nodes), 0.0, 0.0, row);
        };
        let p = self.applied(&st);
        let ft = if self.mu > 0.0 && p != 0.0 {
            self.mu * p.abs() * st.slip.norm()
                / (st.slip.norm_squared() + self.vreg * self.vreg).sqrt()
        } else {
            0.0
        };
        self.row(nodes, &st, p, ft, row);
    }

    fn summary(&self) -> Option<serde_json::Value> {
        Some(serde_json::json!({
            "impacts": self.impacts,
            "max_penetration": self.max_penetration,
            "dissipated_energy": self.dissipated,
        }))
    }

    fn dissipated_power(&self, nodes: &[NodeState]) -> f64 {
        self.state(nodes).map_or(0.0, |st| self.power(&st))
    }

    /// Event control. **Touch** (apart at the start, penetrating at the end): the step is
    /// refused unless it ends within the landing tolerance of the event
    /// ([`EVENT_TOL`] of a step), and retried with the event time found by cubic Hermite
    /// interpolation of the gap between the two ends (the end state is computed with the
    /// spring alone, so it is close to the free flight). A step that lands is *at* the
    /// event: the dashpot's force jump acts from the next step on, after the integrator
    /// restarted its accelerations ([`Element::restart`]) — the step never straddles the
    /// jump, and the impact is resolved at the order of the scheme. **In contact**: steps
    /// no longer than `π/(ω · impact_steps)`. **Separation**: the step ends just past it.
    /// A step that jumped over a whole impact is refused.
    fn step_limit(
        &self,
        ctx: &EvalContext,
        old: &[NodeState],
        new: &[NodeState],
    ) -> Option<StepLimit> {
        let h = ctx.h;
        let (st0, st1) = (self.full_state(old), self.full_state(new));
        let in0 = self.touching;
        let in1 = self.closed(&st1);
        if let Some(w) = Some(st1)
            .filter(|_| in1)
            .and_then(|s| self.omega_estimate(new, &s))
        {
            self.omega_trial.store(w.to_bits(), Ordering::Relaxed);
        }
        let omega = match f64::from_bits(self.omega_trial.load(Ordering::Relaxed)) {
            w if in1 && w > 0.0 => w,
            _ => self.omega,
        };
        // Steps per impact: π/ω split in `impact_steps`; unknown before the first contact.
        let h_imp = if omega > 0.0 {
            std::f64::consts::PI / (omega * f64::from(self.impact_steps))
        } else {
            f64::INFINITY
        };
        let land = if h_imp.is_finite() { LAND * h_imp } else { 0.0 };
        // Estimates of the time to the next event (contact or separation) from a state.
        let time_to_event = |st: &ContactState<f64>, nodes: &[NodeState]| -> Option<f64> {
            if st.gap >= 0.0 {
                // Quadratic in time with the gap acceleration (gravity bends the approach).
                let acc = self.gap_acceleration(nodes, &st.normal);
                return first_root(st.gap, st.gap_rate, acc);
            }
            let mut t = (st.gap_rate > 0.0).then(|| -st.gap / st.gap_rate + land.max(0.0));
            if self.clip {
                let p = -(self.k * st.gap + self.c * st.gap_rate);
                let pdot =
                    -(self.k * st.gap_rate + self.c * self.gap_acceleration(nodes, &st.normal));
                if p > 0.0 && pdot < 0.0 {
                    t = Some(t.map_or(p / -pdot, |t: f64| t.min(p / -pdot)));
                }
            }
            t
        };
        let refuse = |retry: f64| {
            Some(StepLimit {
                accept_up_to: 0.0,
                retry,
                next: retry,
            })
        };
        if !in0 && st1.gap < 0.0 {
            // Touch inside the step: land on it, or retry at its interpolated time.
            let tol = self.touch_tolerance(h, st1.gap_rate);
            if -st1.gap > tol {
                let tau = hermite_root(st0.gap, st0.gap_rate, st1.gap, st1.gap_rate, h);
                return refuse(tau.unwrap_or(0.5 * h).min(h_imp));
            }
        } else if in0 && !in1 && !self.clip {
            // Separation inside the step without clipping: the dashpot's pull `c q̇_n` drops
            // to zero there, a jump like the touch's: land on it (within the tolerance
            // the touch was landed with) or retry at its interpolated time.
            let tau = hermite_root(-st0.gap.min(0.0), -st0.gap_rate, -st1.gap, -st1.gap_rate, h);
            return refuse(tau.unwrap_or(0.5 * h).min(h_imp));
        } else if in0 && !in1 {
            // Separation inside the step (the clipped force is already zero there, only its
            // slope jumps): land just past it.
            let past = if st1.gap_rate == 0.0 {
                0.0
            } else {
                (st1.gap / st1.gap_rate).abs()
            };
            if h_imp.is_finite() && past > 2.0 * LAND * h_imp + 1e-12 {
                let retry = match time_to_event(&st0, old) {
                    Some(t) if t < h => t,
                    _ => h / 4.0,
                };
                return refuse(retry.min(h_imp));
            }
        } else if !in0 && !in1 {
            // Apart at both ends: did the step jump over a whole impact?
            if st0.gap_rate < 0.0 && st1.gap_rate > 0.0 && st0.gap + st0.gap_rate * h < 0.0 {
                let retry = match time_to_event(&st0, old) {
                    Some(t) if t < h => t,
                    _ => h / 4.0,
                };
                return refuse(retry.min(h_imp));
            }
        } else if h > LIMIT_SLACK * h_imp {
            return refuse(h_imp);
        }
        // Accepted: cap the next step at the impact resolution and at the next event.
        let closed_next = in1 || st1.gap < 0.0;
        let mut next = if closed_next { h_imp } else { f64::INFINITY };
        if let Some(t) = time_to_event(&st1, new) {
            next = next.min(t);
        }
        next.is_finite().then_some(StepLimit {
            accept_up_to: f64::INFINITY,
            retry: next,
            next,
        })
    }
}

/// Smallest positive root of `g + ġ τ + ½ g̈ τ²` (the time a gap closes), if any.
fn first_root(g: f64, gd: f64, gdd: f64) -> Option<f64> {
    let (a, b, c) = (0.5 * gdd, gd, g);
    if a == 0.0 {
        return (b < 0.0).then(|| -c / b);
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    // Stable forms of the two roots.
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let roots = [q / a, if q != 0.0 { c / q } else { f64::NAN }];
    roots
        .into_iter()
        .filter(|t| t.is_finite() && *t > 0.0)
        .min_by(f64::total_cmp)
}

/// The time in `(0, h)` where the cubic Hermite interpolant of a gap through
/// `(0, g0, ġ0)` and `(h, g1, ġ1)` vanishes (`g0 ≥ 0 > g1`), by bisection.
fn hermite_root(g0: f64, gd0: f64, g1: f64, gd1: f64, h: f64) -> Option<f64> {
    if !(g0 >= 0.0 && g1 < 0.0 && h > 0.0) {
        return None;
    }
    let p = |s: f64| {
        let (s2, s3) = (s * s, s * s * s);
        (2.0 * s3 - 3.0 * s2 + 1.0) * g0
            + (s3 - 2.0 * s2 + s) * h * gd0
            + (-2.0 * s3 + 3.0 * s2) * g1
            + (s3 - s2) * h * gd1
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if p(mid) >= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi) * h)
}

impl Came {
    fn row(
        &self,
        nodes: &[NodeState],
        st: &ContactState<f64>,
        p: f64,
        ft: f64,
        row: &mut Vec<f64>,
    ) {
        let (c_pt, eta, zeta) = if self.s == 0 {
            (
                st.on_surface,
                st.eta,
                self.roller_coordinate(nodes, &st.normal),
            )
        } else {
            (
                st.on_roller,
                self.roller_coordinate(nodes, &st.normal),
                st.eta,
            )
        };
        let active = if p != 0.0 { 1.0 } else { 0.0 };
        row.extend_from_slice(&[
            active,
            st.gap,
            st.gap_rate,
            p,
            ft,
            c_pt.x,
            c_pt.y,
            c_pt.z,
            eta,
            zeta,
        ]);
    }

    /// `ω = √(k / m_eff)`, `m_eff = P / q̈_n`, when the converged state allows it.
    fn omega_estimate(&self, nodes: &[NodeState], st: &ContactState<f64>) -> Option<f64> {
        let p = self.applied(st);
        let acc = self.gap_acceleration(nodes, &st.normal);
        (p > 0.0 && acc > 0.0).then(|| (self.k * acc / p).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::*;
    use crate::model::PlacedProfile;
    use crate::rotation;

    fn data(cam: Profile, fol: Profile, mu: f64, clip: bool) -> CameData {
        CameData {
            stiffness: 1e6,
            damping: 300.0,
            friction: mu,
            // Large enough that the finite difference (velocity steps c_v ε ≈ 2e-3 m/s) stays
            // in the quadratic range of the regularisation.
            friction_speed: 2.0,
            clip_tension: clip,
            impact_steps: 10,
            cam: PlacedProfile {
                profile: cam,
                offset: Vector3::new(0.1, -0.05, 0.02),
                frame: rotation::exp(&Vector3::new(0.1, -0.2, 0.3)),
            },
            follower: PlacedProfile {
                profile: fol,
                offset: Vector3::new(0.03, 0.02, -0.01),
                frame: Matrix3::identity(),
            },
        }
    }

    /// A state with the roller penetrating the surface by about `depth`.
    fn state_in_contact(el: &Came, seed: u64, depth: f64) -> Vec<NodeState> {
        let mut st = random_states(
            &[Vector3::zeros(), Vector3::new(0.0, 0.5, 0.0)],
            0.05,
            0.4,
            seed,
        );
        // Move the roller node so that the gap is −depth.
        for _ in 0..3 {
            let s = el.state(&st).or_else(|| {
                let l = el.local_point(&st);
                let eta0 = el.curve.closest_parameter(&Vector2::new(l.x, l.y));
                Some(el.kernel_at(&st, eta0, false, true))
            });
            let s = s.unwrap();
            let pi = 1 - el.s;
            st[pi].x -= s.normal * (s.gap + depth);
        }
        st
    }

    fn check(cam: Profile, fol: Profile, mu: f64, clip: bool) {
        // Both laws: from a state apart (spring alone) and in contact (spring and dashpot).
        for touching in [false, true] {
            let mut el = Came::new(
                ElementId(1),
                [0, 1],
                &data(cam.clone(), fol.clone(), mu, clip),
            )
            .unwrap();
            el.touching = touching;
            check_law(&el, clip);
        }
    }

    fn check_law(el: &Came, clip: bool) {
        for seed in 1..6 {
            let st = state_in_contact(el, seed, 1e-3);
            let s = el.state(&st).unwrap();
            assert!((s.gap + 1e-3).abs() < 1e-9, "gap {}", s.gap);
            if clip && s.force <= 0.0 {
                continue;
            }
            check_tangent(el, &dyn_ctx(), &st, &[], 1e-6);
        }
    }

    #[test]
    fn tangent_point_on_line_rotated_cam() {
        check(Profile::Line, Profile::Point, 0.0, false);
    }

    #[test]
    fn tangent_point_on_circle() {
        check(Profile::Circle { radius: 0.3 }, Profile::Point, 0.0, false);
    }

    #[test]
    fn tangent_roller_on_circle_with_friction() {
        check(
            Profile::Circle { radius: 0.3 },
            Profile::Circle { radius: 0.05 },
            0.3,
            true,
        );
    }

    #[test]
    fn tangent_roller_on_line_with_friction() {
        check(Profile::Line, Profile::Circle { radius: 0.05 }, 0.4, false);
    }

    #[test]
    fn tangent_point_on_spline() {
        let pts = vec![
            [-0.5, 0.1],
            [-0.2, -0.05],
            [0.1, 0.05],
            [0.4, 0.0],
            [0.8, 0.2],
        ];
        check(
            Profile::Spline {
                points: pts,
                closed: false,
            },
            Profile::Point,
            0.2,
            false,
        );
    }

    #[test]
    fn tangent_flat_follower_on_disc_cam() {
        check(Profile::Circle { radius: 0.2 }, Profile::Line, 0.0, false);
    }

    #[test]
    fn forces_balance_and_push_apart() {
        let el = Came::new(
            ElementId(1),
            [0, 1],
            &data(Profile::Line, Profile::Point, 0.3, true),
        )
        .unwrap();
        let mut st = state_in_contact(&el, 7, 1e-3);
        for s in &mut st {
            s.v = Vector3::zeros();
            s.w = Vector3::zeros();
        }
        let mut out = Local::new(12);
        el.evaluate(&dyn_ctx(), &st, &[], false, &mut out);
        let f_a = Vector3::new(out.res[0], out.res[1], out.res[2]);
        let f_b = Vector3::new(out.res[6], out.res[7], out.res[8]);
        assert!((f_a + f_b).norm() < 1e-9 * f_a.norm());
        let s = el.state(&st).unwrap();
        // Residual = −force; the follower is pushed along +n with k·depth.
        assert!((f_b + s.normal * 1e3).norm() < 1e-6, "{f_b:?}");
    }

    #[test]
    fn far_apart_costs_nothing() {
        let el = Came::new(
            ElementId(1),
            [0, 1],
            &data(Profile::Circle { radius: 0.1 }, Profile::Point, 0.0, true),
        )
        .unwrap();
        let st = vec![
            NodeState::at_rest(Vector3::zeros()),
            NodeState::at_rest(Vector3::new(5.0, 0.0, 0.0)),
        ];
        assert!(el.state(&st).is_none());
        let mut out = Local::new(12);
        el.evaluate(&dyn_ctx(), &st, &[], true, &mut out);
        assert!(out.res.iter().chain(&out.tan).all(|v| *v == 0.0));
    }
}
