//! HHT and generalized-α time integration on the Lie group `(ℝ³ × SO(3))ⁿ`, Newton–Raphson,
//! step cutting.
//!
//! # The scheme (Arnold & Brüls 2007; Brüls, Cardona & Arnold 2012)
//! The α family ([`AlphaParams`]): HHT's `α ∈ [−1/3, 0]` is `α_m = 0`, `α_f = −α`,
//! `β = (1−α)²/4`, `γ = ½ − α` (Hilber, Hughes & Taylor 1977); generalized-α's `ρ∞ ∈ [0, 1]`
//! is `α_m = (2ρ∞−1)/(ρ∞+1)`, `α_f = ρ∞/(ρ∞+1)`, `γ = ½ + α_f − α_m`, `β = ¼(γ+½)²`
//! (Chung & Hulbert 1993). Per degree of freedom, with the pseudo-acceleration `a`:
//! - `q_{n+1} = q_n ∘ exp(u)`, `u = h v_n + h²(½ − β) a_n + h² β a_{n+1}`;
//! - `v_{n+1} = v_n + h(1 − γ) a_n + h γ a_{n+1}`;
//! - `(1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) v̇_{n+1} + α_f v̇_n`;
//! - equilibrium `r(q_{n+1}, v_{n+1}, v̇_{n+1}, λ_{n+1}) = 0`, `Φ(q_{n+1}) = 0` at `t_{n+1}`.
//!
//! For rotations `∘ exp` is `R_{n+1} = R_n exp(ũ)`, so orientations never pass through a
//! parametrisation singularity. The unknown of Newton's method is `u` (and the scaled
//! multipliers): `∂v/∂u = γ/(βh)`, `∂v̇/∂u = (1−α_m)/((1−α_f)βh²)`, and the rotational
//! columns of the stiffness carry the tangent map `T(u)` of the exponential (exact
//! iteration matrix).
//!
//! Newton is *modified* (the matrix is kept, also from one step to the next of the same
//! size, while each iteration divides the residual by at least 1/[`CONTRACTION`] ≈ 2.9; then only
//! residuals are assembled, which for the beams skips the dual-number tangent, and the LU
//! is reused; the kept matrix is applied in the beams' nodes' co-rotated frames, so that a
//! beam turning since the factorisation does not make it stale: `integrator/corotated.rs`), and an
//! iterate reached with a kept matrix is polished until the residual
//! stagnates, so the converged states equal full Newton's (1.5e-8 m on the rigid pendulum
//! after 0.3 s, where h vs h/2 differ by 1.5e-7 m). On the pendulum this makes a step
//! 5.4× cheaper (81 µs instead of 440 µs).
//! The scheme is second-order accurate and, for linear problems, has the spectral radius
//! at infinity `ρ∞` (HHT: `(1 + α)/(1 − α)`).

use super::system::System;
use super::{Failure, FailureReason, Stats};
use crate::elements::{Energies, EvalContext, NodeState};
use crate::model::{NewtonSettings, Scheme};
use crate::rotation;
use nalgebra::Vector3;

/// Absolute tolerance on constraint equations at convergence (m or rad).
pub const CONSTRAINT_TOL: f64 = 1e-11;

/// Modified Newton keeps its iteration matrix while each iteration divides the relative
/// residual by at least 1/CONTRACTION.
///
/// 0.35 since issue 37 (item 4; ¼ before), measured on the beam benchmarks: a rebuild (the
/// beams' tangent and an LU) costs 10–15 iterations (a residual and a solve) on beams of
/// order 3–5, and a matrix kept from the last step typically contracts by ~3e-3 at its first
/// iteration and by 0.3–0.5 at its second. The cantilever of order 5 per leg (HHT,
/// h = 0.025 s) rebuilt 848 times in 1,200 steps at ¼, 709 at 0.35, 577 at ½; the seed's
/// pendulum 5,651, 4,226, 2,777. ½ (the stages' [`STAGE_CONTRACTION`]) was 7–8 % faster on
/// the cantilever but left the polished iterate of the stiff-bar pendulum 2.8e-8 m from
/// Newton at round-off tolerances after 0.3 s (¼: 1.7e-9 m; 0.4: 1.3e-8 m; 0.35: 5.2e-9 m),
/// past `tests/accuracy.rs`'s bound of a tenth of the time error (1.7e-8 m): a slower
/// contraction leaves more of the error in the mechanism's directions, which stiff bars'
/// residuals do not show. 0.7–0.9, or a cost model (keep while the iterations the measured
/// rate still needs are fewer than a rebuild's cost), gained no more than ½ did
/// (docs/performance.md, "Where the CPU goes").
pub const CONTRACTION: f64 = 0.35;

/// [`CONTRACTION`] for the stages of the ESDIRK schemes (`newton.rs`).
pub const STAGE_CONTRACTION: f64 = 0.5;

/// `max` that propagates NaN (`f64::max` drops it: a NaN residual would pass for zero).
#[inline]
fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// Coefficients of the generalized-α family (Chung & Hulbert 1993) in the Lie-group form
/// of Arnold & Brüls (2007): the pseudo-acceleration `a` of
/// `(1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) v̇_{n+1} + α_f v̇_n` drives
/// `u = h v_n + h²(½ − β) a_n + h² β a_{n+1}` and `v_{n+1} = v_n + h(1 − γ) a_n + hγ a_{n+1}`.
/// HHT is the member `α_m = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlphaParams {
    /// `α_m` (0 for HHT; `(2ρ∞ − 1)/(ρ∞ + 1)` for generalized-α).
    pub alpha_m: f64,
    /// `α_f` (`−α` for HHT; `ρ∞/(ρ∞ + 1)` for generalized-α).
    pub alpha_f: f64,
    /// `β = ¼(γ + ½)²`.
    pub beta: f64,
    /// `γ = ½ + α_f − α_m` (second order).
    pub gamma: f64,
}

impl AlphaParams {
    /// Parameters of HHT-α (α ∈ [−1/3, 0]): `α_m = 0`, `α_f = −α`, `β = (1 − α)²/4`,
    /// `γ = ½ − α` (Hilber, Hughes & Taylor 1977 in Arnold & Brüls' form).
    pub fn new(alpha: f64) -> Self {
        AlphaParams {
            alpha_m: 0.0,
            alpha_f: -alpha,
            beta: (1.0 - alpha) * (1.0 - alpha) / 4.0,
            gamma: 0.5 - alpha,
        }
    }

    /// Parameters of generalized-α with spectral radius at infinity `ρ∞ ∈ [0, 1]`
    /// (Chung & Hulbert 1993, eqs. 25 and 17; Arnold & Brüls 2007, §3):
    /// `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`, `γ = ½ + α_f − α_m`,
    /// `β = ¼(γ + ½)²`.
    pub fn generalized(rho_inf: f64) -> Self {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        AlphaParams {
            alpha_m,
            alpha_f,
            beta: 0.25 * (gamma + 0.5) * (gamma + 0.5),
            gamma,
        }
    }

    /// The coefficients of a scheme of the α family.
    pub fn of(scheme: &Scheme) -> Self {
        match *scheme {
            Scheme::Hht { alpha } => AlphaParams::new(alpha),
            Scheme::GeneralizedAlpha { rho_inf } => AlphaParams::generalized(rho_inf),
            // Not an α scheme: the trapezoidal rule's coefficients stand for the queries that
            // assume one (a bench's `step_context`, the adaptive steps' error measure).
            Scheme::Esdirk3 | Scheme::Esdirk5 => AlphaParams::new(0.0),
        }
    }

    /// `∂v̇_{n+1}/∂u = (1 − α_m)/((1 − α_f) β h²)`: the mass coefficient `c_a` of the
    /// iteration matrix (and `∂v/∂u = γ/(βh)` its damping coefficient `c_v`).
    pub fn c_a(&self, h: f64) -> f64 {
        (1.0 - self.alpha_m) / ((1.0 - self.alpha_f) * self.beta * h * h)
    }
}

/// The running state of a time integration (or a static load stepping).
pub struct Integrator {
    /// The assembled system.
    pub sys: System,
    /// Node states at the last accepted time.
    pub nodes: Vec<NodeState>,
    /// Pseudo-accelerations `a` of the nodes, `[translation, rotation]`.
    pub pseudo: Vec<[Vector3<f64>; 2]>,
    /// Scaled multipliers (indexed by global equation; nodal entries unused).
    pub lambda: Vec<f64>,
    /// Current time (or load factor in statics).
    pub t: f64,
    /// Counters.
    pub stats: Stats,
    /// Newton settings.
    pub newton: NewtonSettings,
    /// The time integration scheme (what the deck asked for).
    pub scheme: Scheme,
    /// Its coefficients (the α family).
    pub params: AlphaParams,
    /// Dynamic (true) or static analysis.
    pub dynamic: bool,
    /// Constraint scale `s` currently used for `lambda`.
    pub scale: f64,
    /// Reference mass term per unit `c_a` (mean translational mass per node), kg.
    pub mass_ref: f64,
    /// Reference stiffness term (mean translational diagonal stiffness), N/m.
    pub stiff_ref: f64,
    /// Reference rotational inertia (mean rotational diagonal of the mass matrix), kg·m².
    pub rot_mass_ref: f64,
    /// Round-off floor of the residual, N: `10 ε k_max L_ref`. Positions are known to
    /// `ε |x|`, so a stiffness `k` cannot balance forces better than `ε |x| k`; asking
    /// Newton for less only makes it fail (a stiff bar under a small load).
    pub residual_floor: f64,
    /// Work of applied loads since t = 0, J.
    pub external_work: f64,
    /// Energy dissipated by element dampers since t = 0, J.
    pub damping_work: f64,
    /// Largest step the elements allow after the last accepted step ([`crate::elements::Element::step_limit`],
    /// e.g. a contact resolving an impact); infinity = no limit.
    pub step_cap: f64,
    /// Adaptive time stepping (local error tolerances), `None` = fixed steps.
    pub adaptive: Option<crate::model::Adaptive>,
    /// The run's length, s (its `END`): an adaptive ESDIRK step's velocity error counts as
    /// displacing the positions for this long (`T |e_v|`, [`Self::embedded_error`]).
    pub error_horizon: f64,
    /// Step the local error estimate proposes after the last accepted step (adaptive).
    pub error_next: f64,
    /// Steps no longer than this are never refused by [`crate::elements::Element::step_limit`] (the run's
    /// smallest step), so a refusal cannot repeat forever.
    pub event_floor: f64,
    /// Whether the step being finished crosses an event an element asked to land on, which
    /// the smallest step (`event_floor`) could not (its refusal waived): the energy guard
    /// then allows the step's change of the stored energy (`Integrator::finish_step`).
    pub(super) straddled: bool,
    /// Set (from another thread, e.g. a signal handler's) to give up the step under way
    /// at its next Newton iteration ([`FailureReason::Aborted`]); the state is then left
    /// as a failed attempt leaves it. `None` = never.
    pub abort: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// The energy guard's record along the run ([`crate::solver::energy_guard`]).
    pub balance: crate::solver::energy_guard::Balance,
    /// The scheme's `g` of the energy guard ([`crate::solver::energy_guard::bound`]).
    pub guard_g: f64,
    /// The guard's measure of the accepted state, kept for the next step while nothing
    /// changed the state: (steps, restarts, t) when it was taken.
    pub(super) guard_cache: Option<(u64, u64, f64, crate::solver::energy_guard::Measure)>,
    /// What the last converged Newton loop leaves of its solution, in the increment's
    /// units (`m / L_ref`, rad): at most the increment tolerance (set by `newton_solve`,
    /// read by the energy guard of the same step).
    pub(super) newton_left: f64,
    /// Step size the numeric LU in `sys.matrix` was computed for (NaN = none valid): a later
    /// step of the same size starts from it (modified Newton).
    pub(super) lu_step: f64,
    /// The nodes' orientations at the iterate the numeric LU was computed at: a kept
    /// matrix is applied in their co-rotated frames ([`corotated`]).
    pub(super) lu_frames: Vec<nalgebra::Matrix3<f64>>,
    /// The nodes whose kept matrix is applied in co-rotated frames: those of an element
    /// that [turns with its nodes](crate::elements::Element::turns_with_its_nodes).
    pub(super) turning: Vec<bool>,
    pub(super) trial: Vec<NodeState>,
    pub(super) trial_pseudo: Vec<[Vector3<f64>; 2]>,
    pub(super) trial_lambda: Vec<f64>,
    pub(super) delta: Vec<f64>,
    pub(super) u: Vec<[Vector3<f64>; 2]>,
    pub(super) tmap: Vec<nalgebra::Matrix3<f64>>,
    /// Newton residual history of the step under way (kept between steps so that a
    /// successful step allocates nothing; handed to the [`Failure`] of a failed one).
    history: Vec<f64>,
    /// The stages of the ESDIRK scheme when it replaces HHT (`model::Scheme::Esdirk3`);
    /// `None` = HHT. Scratch within a step: nothing in it is read across steps.
    esdirk: Option<Box<esdirk::Stages>>,
    /// The index-1 solve of a stage scheme's accelerations and multipliers at each step's
    /// end ([`multipliers`]); `None` for the α family and for models without multipliers.
    index1: Option<Box<multipliers::Index1>>,
    /// The adaptive ESDIRK steps' filter of their velocity error ([`drift`]), built at
    /// their first estimate.
    drift: Option<Box<drift::DriftFilter>>,
    /// Buffers of [`Integrator::consistent_accelerations`], kept so that the restarts of
    /// the accelerations at a contact's events allocate nothing (issue 27 §1d).
    acc: AccelerationScratch,
    /// The constraint equations removed as redundant at the start, and the groups where
    /// the reported reactions are made minimum-norm ([`crate::solver::redundancy`]).
    pub redundancy: crate::solver::redundancy::Redundancy,
    /// What the solver changed of the model or its initial state before the first step
    /// (held rotations, removed equations, assembly, projected velocities).
    pub notices: Vec<crate::solver::notice::Notice>,
    /// [`Integrator::initialize`] ran (a restored state needs the start's structure).
    pub(crate) started: bool,
}

/// Work vectors of the consistent-acceleration solve: sized with the integrator, reused.
#[derive(Debug, Default)]
struct AccelerationScratch {
    /// A zero velocity-correction vector (n equations).
    zero: Vec<f64>,
    /// The matrix values of the stiffness-and-constraint assembly.
    kb: Vec<f64>,
    /// Right-hand side, then solution `[v̇; λ]`.
    rhs: Vec<f64>,
    /// `Ḃ v` per constraint equation.
    bdot_v: Vec<f64>,
    /// Constraint residuals at the state and at `q exp(+εv)`.
    r0: Vec<f64>,
    rp: Vec<f64>,
    /// The nodes moved along their velocities by ±ε.
    plus: Vec<NodeState>,
    minus: Vec<NodeState>,
}

impl AccelerationScratch {
    /// Buffers for `n` equations of which `n_c` are constraints, and `nodes` nodes.
    fn sized(n: usize, n_c: usize, nodes: usize) -> Self {
        AccelerationScratch {
            zero: vec![0.0; n],
            kb: Vec::new(),
            rhs: Vec::with_capacity(n),
            bdot_v: Vec::with_capacity(n_c),
            r0: Vec::with_capacity(n_c),
            rp: Vec::with_capacity(n_c),
            plus: Vec::with_capacity(nodes),
            minus: Vec::with_capacity(nodes),
        }
    }
}

/// Outcome of one accepted step.
#[derive(Debug, Clone, Copy)]
pub struct StepInfo {
    /// Newton iterations used.
    pub iterations: u32,
    /// Final residual relative to the reference force.
    pub residual: f64,
}

impl Integrator {
    /// A state at rest in the reference configuration (initial velocities applied by
    /// [`Integrator::set_velocities`]).
    pub fn new(sys: System, newton: NewtonSettings, scheme: Scheme, dynamic: bool) -> Self {
        let nodes: Vec<NodeState> = sys.x0.iter().map(|x| NodeState::at_rest(*x)).collect();
        let n = sys.n_eq();
        let nn = nodes.len();
        let esdirk_scheme = esdirk::tableau_of(&scheme).is_some();
        let esdirk = esdirk::tableau_of(&scheme)
            .filter(|_| dynamic)
            .map(|tab| Box::new(esdirk::Stages::sized(&sys, tab)));
        let index1 = esdirk
            .as_ref()
            .and_then(|_| multipliers::Index1::sized(&sys));
        Integrator {
            lu_step: f64::NAN,
            lu_frames: vec![nalgebra::Matrix3::identity(); nn],
            turning: corotated::turning_nodes(&sys),
            trial: nodes.clone(),
            nodes,
            pseudo: vec![[Vector3::zeros(); 2]; nn],
            trial_pseudo: vec![[Vector3::zeros(); 2]; nn],
            lambda: vec![0.0; n],
            trial_lambda: vec![0.0; n],
            delta: vec![0.0; n],
            u: vec![[Vector3::zeros(); 2]; nn],
            tmap: vec![nalgebra::Matrix3::identity(); nn],
            history: Vec::with_capacity(newton.max_iterations as usize + 1),
            acc: AccelerationScratch::sized(n, n - sys.n_node_eq, nn),
            esdirk,
            index1,
            drift: None,
            t: 0.0,
            stats: Stats::default(),
            newton,
            scheme,
            params: AlphaParams::of(&scheme),
            dynamic,
            scale: 1.0,
            mass_ref: 0.0,
            stiff_ref: 0.0,
            residual_floor: 0.0,
            rot_mass_ref: 0.0,
            external_work: 0.0,
            damping_work: 0.0,
            step_cap: f64::INFINITY,
            adaptive: None,
            error_horizon: 1.0,
            error_next: f64::INFINITY,
            event_floor: 0.0,
            straddled: false,
            abort: None,
            redundancy: Default::default(),
            notices: Vec::new(),
            started: false,
            balance: Default::default(),
            // The stage schemes have no acceleration history: g = 0 (energy_guard::bound).
            guard_g: if esdirk_scheme {
                0.0
            } else {
                crate::solver::energy_guard::bound::run_bound(&AlphaParams::of(&scheme))
            },
            guard_cache: None,
            newton_left: 0.0,
            sys,
        }
    }

    /// Gives back the residual history of a refused attempt (a [`Failure`] the run loop
    /// recovers from by cutting the step), so that the next attempt's Newton loop reuses its
    /// storage instead of growing a new one (no allocation through an impact: issue 27 §1d).
    pub fn recycle_history(&mut self, mut history: Vec<f64>) {
        if history.capacity() > self.history.capacity() {
            history.clear();
            self.history = history;
        }
    }

    /// Sets node velocities: `v` global, `w` global angular velocity (turned to material).
    pub fn set_velocity(&mut self, node: usize, v: Vector3<f64>, w: Vector3<f64>) {
        let s = &mut self.nodes[node];
        s.v = v;
        s.w = s.r.transpose() * w;
    }

    fn context(&self, t: f64, h: f64, scale: f64) -> EvalContext {
        let (c_v, c_a) = if self.dynamic && h > 0.0 {
            let p = &self.params;
            (p.gamma / (p.beta * h), p.c_a(h))
        } else {
            (0.0, 0.0)
        };
        EvalContext {
            t,
            c_v,
            c_a,
            dynamic: self.dynamic,
            // `ANALYSIS STATIC … PROPORTIONAL`: gravity by the load factor ([`statics`]).
            gravity: if !self.dynamic && self.sys.proportional {
                self.sys.gravity * t.clamp(0.0, 1.0)
            } else {
                self.sys.gravity
            },
            constraint_scale: scale,
            penalty: 0.0,
            h,
        }
    }

    /// Constraint scale for step `h`: the magnitude of the mass and stiffness terms of the
    /// iteration matrix (Cardona & Géradin 1989; Bottasso, Bauchau & Cardona 2007), so the
    /// constraint rows keep the size of the others whatever `h`.
    fn scale_for(&self, h: f64) -> f64 {
        let ca = if self.dynamic && h > 0.0 {
            self.params.c_a(h)
        } else {
            0.0
        };
        (ca * self.mass_ref + self.stiff_ref).max(1e-12)
    }

    /// Sum of element energies at the current state.
    pub fn energies(&self) -> Energies {
        let mut e = Energies::default();
        for el in &self.sys.elements {
            e += el.energies(&self.nodes, &self.sys.gravity);
        }
        e
    }

    /// The evaluation context of the current state (for outputs).
    pub fn current_context(&self) -> EvalContext {
        self.context(self.t, 0.0, self.scale)
    }

    /// The evaluation context of a step of size `h` from the current state: time `t + h`
    /// and the coefficients `c_v = γ/(βh)`, `c_a = (1 − α_m)/((1 − α_f)βh²)` the step uses
    /// (for benchmarks and tools that assemble outside [`Self::try_step`]).
    pub fn step_context(&self, h: f64) -> EvalContext {
        self.context(self.t + h, h, self.scale)
    }

    /// The multipliers to report at the current state: the run's, but where redundant
    /// equations were removed the minimum-norm ones that carry the same loads
    /// ([`crate::solver::redundancy::Redundancy::reported_multipliers`]; a copy only then).
    pub fn reported_multipliers(&self) -> std::borrow::Cow<'_, [f64]> {
        if self.redundancy.is_empty() {
            std::borrow::Cow::Borrowed(&self.lambda)
        } else {
            std::borrow::Cow::Owned(self.redundancy.reported_multipliers(
                &self.sys,
                &self.nodes,
                self.t,
                &self.lambda,
            ))
        }
    }

    /// The largest violation of an equation removed as redundant at the start, if it
    /// exceeds what the kept equations' tolerance explains: the redundancy was one of the
    /// initial position only (the mechanism reached a position where the removed equation
    /// no longer follows from the others), or the equations contradict each other. A
    /// failure diagnosis then.
    pub fn check_removed_equations(&self) -> Result<(), Failure> {
        let Some((v, r)) = self
            .redundancy
            .removed_violation(&self.sys, &self.nodes, self.t)
        else {
            return Ok(());
        };
        if v <= start::removed_tolerance(self.sys.ref_length) {
            return Ok(());
        }
        Err(self.failure(
            0.0,
            FailureReason::Constraints(format!(
                "element {}'s equation {} ({}), removed at the start as redundant, is violated by {v:.3e}: it no longer follows from the other constraints (the redundancy held at the initial position only, or the constraints contradict each other, e.g. two drivers of one motion); model the joint so that it blocks only the motions the others leave free",
                r.id.0,
                r.equation + 1,
                r.motion
            ).into()),
            vec![],
            self.sys.ref_force,
        ))
    }

    /// Adds to the diagnosis of the failure that stops a run (not of every refused step:
    /// the check costs a factorisation of the constraint rows) the constraint equations
    /// that are nearly dependent at the failed attempt's last iterate, if any: a loop
    /// reaching a singular position ([`crate::solver::redundancy::singular_position`]).
    pub fn diagnose_constraints(&self, f: &mut Failure) {
        if self.sys.n_eq() == self.sys.n_node_eq {
            return;
        }
        if let Some(d) =
            crate::solver::redundancy::singular_position(&self.sys, &self.trial, self.t + f.step)
        {
            let mut all = f.diagnoses.to_vec();
            all.push(d);
            f.diagnoses = all.into_boxed_slice();
        }
    }

    /// Largest constraint violation over all elements at the current state.
    pub fn constraint_violation(&self) -> f64 {
        self.sys
            .elements
            .iter()
            .map(|e| e.constraint_violation(&self.nodes))
            .fold(0.0, f64::max)
    }
}

/// `nodes` moved along their velocities for a time `dt` (the geodesic `q exp(dt v)`:
/// `x + v dt`, `R exp(dt Ω̃)`), into `out`: the points of the restart's central second
/// difference of `Φ` along `v` (`Ḃv`).
fn moved_along_velocities(nodes: &[NodeState], dt: f64, out: &mut Vec<NodeState>) {
    out.clear();
    out.extend(nodes.iter().map(|s| NodeState {
        x: s.x + s.v * dt,
        r: s.r * rotation::exp(&(s.w * dt)),
        ..*s
    }));
}

mod corotated;
mod drift;
pub use drift::DriftState;
mod error;
pub mod esdirk;
mod hht;
mod multipliers;
mod newton;
mod start;
mod statics;
