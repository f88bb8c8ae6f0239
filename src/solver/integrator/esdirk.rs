//! A third-order, L-stable, stiffly accurate ESDIRK scheme on the Lie group
//! `(ℝ³ × SO(3))ⁿ`, with the index-3 constraints met at every stage.
//!
//! # The scheme
//! Kennedy & Carpenter's ESDIRK3(2)4L[2]SA (NASA/TM-2016-219173, § 5.2.1: four stages, the
//! first explicit, the three others with the same diagonal `γ = 0.4358665215084590`, stage
//! order 2, L-stable, `b = A`'s last row) applied to the first-order form of the equations
//! of motion in the local coordinates of the group about the step's start (Munthe-Kaas'
//! RKMK: Munthe-Kaas 1998, BIT 38; Iserles et al. 2000, Acta Numerica 9, § 5):
//! - per node, `x_i = x_n + U_i`, `R_i = R_n exp(Ũ_i)`, `U_i = h Σ_j a_ij Û_j`, where the
//!   stage's algebra velocity is `Û_j = v_j` (translation) and `Û_j = T(U_j)⁻¹ Ω_j`
//!   (rotation: `Ω = T(U) U̇`, paper eq. [3], so the RK stages see the exact `dexp⁻¹`);
//! - `v_i = v_n + h Σ_j a_ij v̇_j`, `Ω_i = Ω_n + h Σ_j a_ij Ω̇_j` (material frame);
//! - at each implicit stage, equilibrium `r(q_i, v_i, v̇_i, λ_i) = 0` and `Φ(q_i) = 0` at
//!   `t_n + c_i h`, so the constraints hold at every stage and (stiffly accurate) at the
//!   step's end, which is the last stage.
//!
//! Stage 1 is the start state itself: its accelerations are the consistent ones the last
//! stage of the previous step (or [`Integrator::consistent_accelerations`] at a start or
//! a contact's restart) solved, so the scheme is one-step in `(q, v)` and keeps no history
//! across steps (a checkpoint needs nothing more than HHT's).
//!
//! Newton's unknown at stage i is `U_i`; then `∂v_i/∂U_i = 1/(γh)` and
//! `∂v̇_i/∂U_i = 1/(γh)²` exactly for translations (and to `O(|U|)` for rotations, where
//! `T(U)` is left out of the inertia's columns): the iteration matrix is HHT's with
//! `c_v = 1/(γh)`, `c_a = 1/(γh)²`, the same for the three stages and for every step of
//! the same size, so modified Newton keeps one factorisation across stages and steps.
//! Linear stability (all stages share `γ`): `R(z) = 1 + z bᵀ(I − zA)⁻¹1`, `|R(iωh)| < 1`
//! for `ωh > 0`, `R(∞) = 0` (L-stable): high frequencies are annihilated, the low ones
//! damped by `O((ωh)⁴)` per step.

use super::newton::Kinematics;
use super::*;

/// `γ`, the root of `x³ − 3x² + 3x/2 − 1/6 = 0` in (1/3, 1/2) (Kennedy & Carpenter 2016,
/// eq. 207: the L-stable third-order SDIRK's diagonal).
pub const GAMMA: f64 = 0.435_866_521_508_459;

/// The Butcher matrix `A` (lower triangular, row i = stage i; the last row is `b`):
/// Kennedy & Carpenter (2016), ESDIRK3(2)4L[2]SA, with `c = (0, 2γ, 3/5, 1)`.
pub const A: [[f64; 4]; 4] = [
    [0.0, 0.0, 0.0, 0.0],
    [GAMMA, GAMMA, 0.0, 0.0],
    [
        0.257_648_246_066_427_2,
        -0.093_514_767_574_886_2,
        GAMMA,
        0.0,
    ],
    [
        0.187_641_024_346_723_8,
        -0.595_297_473_576_955,
        0.971_789_927_721_772_1,
        GAMMA,
    ],
];

/// The stability function `R(z) = 1 + z bᵀ(I − zA)⁻¹1` (the step's amplification of
/// `y' = λy`, `z = λh`), stage by stage since `A` is lower triangular:
/// `Y_i = (1 + z Σ_{j<i} a_ij Y_j)/(1 − z a_ii)`, `R = Y_4` (stiffly accurate).
pub fn stability(z: nalgebra::Complex<f64>) -> nalgebra::Complex<f64> {
    let one = nalgebra::Complex::new(1.0, 0.0);
    let mut y = [one; S];
    for i in 0..S {
        let mut s = one;
        for j in 0..i {
            s += z * A[i][j] * y[j];
        }
        y[i] = s / (one - z * A[i][i]);
    }
    y[S - 1]
}

/// Number of stages.
const S: usize = 4;

/// Per node `[translation, rotation]`.
type Pair = [Vector3<f64>; 2];

/// The stages of the step under way (scratch: written before being read in each step).
#[derive(Debug, Clone)]
pub struct Stages {
    /// Algebra velocities `Û_j` per node and stage.
    vel: Vec<[Pair; S]>,
    /// Accelerations `(v̇_j, Ω̇_j)` per node and stage.
    acc: Vec<[Pair; S]>,
    /// `h Σ_{j<i} a_ij Û_j` of the stage being solved.
    known_u: Vec<Pair>,
    /// `(v_n, Ω_n) + h Σ_{j<i} a_ij (v̇_j, Ω̇_j)` of the stage being solved.
    known_v: Vec<Pair>,
    /// `γh` of the step under way.
    gh: f64,
    /// Whether the stage being solved meets its constraints at the velocity level (module
    /// docs: the inner stages), with their rows `s γh B(q_i) v_i` in `rows`.
    velocity_level: bool,
    rows: Vec<f64>,
    /// The trial nodes moved along their velocities by ±ε (central difference of `Φ`).
    plus: Vec<NodeState>,
    minus: Vec<NodeState>,
}

impl Stages {
    pub(super) fn sized(nodes: usize) -> Self {
        let z = [Vector3::zeros(); 2];
        Stages {
            vel: vec![[z; S]; nodes],
            acc: vec![[z; S]; nodes],
            known_u: vec![z; nodes],
            known_v: vec![z; nodes],
            gh: 0.0,
            velocity_level: false,
            rows: Vec::new(),
            plus: Vec::with_capacity(nodes),
            minus: Vec::with_capacity(nodes),
        }
    }
}

impl Integrator {
    /// Whether the ESDIRK scheme integrates (else HHT).
    pub fn is_esdirk3(&self) -> bool {
        self.esdirk.is_some()
    }

    /// One ESDIRK step of size `h` (module docs): the three implicit stages by Newton,
    /// then the checks of a converged step and the acceptance of the last stage. On
    /// failure the accepted state is unchanged.
    pub(super) fn try_esdirk_step(&mut self, h: f64) -> Result<StepInfo, Failure> {
        let gh = GAMMA * h;
        let c_a = 1.0 / (gh * gh);
        let s_new = (c_a * self.mass_ref + self.stiff_ref).max(1e-12);
        let nn = self.sys.n_node_eq;
        let ratio = self.scale / s_new;
        self.trial_lambda.copy_from_slice(&self.lambda);
        for l in &mut self.trial_lambda[nn..] {
            *l *= ratio;
        }
        let st = self.esdirk.as_deref_mut().expect("ESDIRK stages");
        st.gh = gh;
        // Stage 1: the start state.
        for (k, s) in self.nodes.iter().enumerate() {
            st.vel[k][0] = [s.v, s.w];
            st.acc[k][0] = [s.a, s.wd];
        }
        let mut before = 0;
        for i in 1..S {
            let ci: f64 = A[i].iter().sum();
            let st = self.esdirk.as_deref_mut().expect("ESDIRK stages");
            for (k, s) in self.nodes.iter().enumerate() {
                let (mut ku, mut kv) = ([Vector3::zeros(); 2], [s.v, s.w]);
                for j in 0..i {
                    for c in 0..2 {
                        ku[c] += st.vel[k][j][c] * (h * A[i][j]);
                        kv[c] += st.acc[k][j][c] * (h * A[i][j]);
                    }
                }
                st.known_u[k] = ku;
                st.known_v[k] = kv;
                // Predictor: constant accelerations from the start.
                let t = ci * h;
                self.u[k] = [
                    s.v * t + s.a * (0.5 * t * t),
                    s.w * t + s.wd * (0.5 * t * t),
                ];
            }
            let ctx = EvalContext {
                t: self.t + ci * h,
                c_v: 1.0 / gh,
                c_a,
                dynamic: true,
                gravity: self.sys.gravity,
                constraint_scale: s_new,
                penalty: 0.0,
                h,
            };
            self.esdirk
                .as_deref_mut()
                .expect("ESDIRK stages")
                .velocity_level = i < S - 1;
            let (iter, rel, history, fref) = self.newton_solve(h, &ctx, Kinematics::Stage)?;
            if i == S - 1 {
                let mut info = self.finish_step(h, &ctx, iter, rel, history, fref)?;
                self.stats.newton_iterations += u64::from(before);
                info.iterations += before;
                return Ok(info);
            }
            self.history = history;
            before += iter;
            let st = self.esdirk.as_deref_mut().expect("ESDIRK stages");
            for (k, t) in self.trial.iter().enumerate() {
                let what = (self.u[k][1] - st.known_u[k][1]) / gh;
                st.vel[k][i] = [t.v, what];
                st.acc[k][i] = [t.a, t.wd];
            }
        }
        unreachable!("the last stage returns")
    }

    /// The trial state of the stage being solved from Newton's increment `u` (module
    /// docs): positions and orientations from `U`, velocities from the stage's algebra
    /// velocity `Û = (U − h Σ_{j<i} a_ij Û_j)/(γh)` (`Ω = T(U) Û` for rotations),
    /// accelerations from `v = v_n + h Σ_{j<i} a_ij v̇_j + γh v̇`.
    pub(super) fn stage_from_u(&mut self) {
        let st = self.esdirk.as_deref().expect("ESDIRK stages");
        let gh = st.gh;
        for (k, t) in self.trial.iter_mut().enumerate() {
            let s0 = &self.nodes[k];
            let [ux, ur] = self.u[k];
            t.x = s0.x + ux;
            t.r = s0.r * rotation::exp(&ur);
            t.v = (ux - st.known_u[k][0]) / gh;
            t.w = rotation::tangent(&ur) * ((ur - st.known_u[k][1]) / gh);
            t.a = (t.v - st.known_v[k][0]) / gh;
            t.wd = (t.w - st.known_v[k][1]) / gh;
            // What `accept` keeps as HHT's pseudo-accelerations: the true ones (a restart's).
            self.trial_pseudo[k] = [t.a, t.wd];
        }
    }

    /// The constraint rows of an inner stage, `s γh (B(q_i) v_i + ∂Φ/∂t)` (module docs), into the
    /// stages' `rows`: `B v` is the derivative of `Φ` along `q exp(εv)`, by a central
    /// difference with `ε|v| = 1e-4 L_ref` (truncation `ε²|v|³Φ‴/6`: 1e-8 of `|v|` for a
    /// constraint of curvature 1/L_ref; round-off `ε_mach L_ref/ε`: 1e-12 of `|v|`).
    /// Nothing for HHT or the last stage.
    pub(super) fn stage_velocity_rows(&mut self, ctx: &EvalContext) {
        let nn = self.sys.n_node_eq;
        let n = self.sys.n_eq();
        let Some(st) = self.esdirk.as_deref_mut() else {
            return;
        };
        if !st.velocity_level || n == nn {
            return;
        }
        let l = self.sys.ref_length;
        let vmax = self
            .trial
            .iter()
            .fold(0.0f64, |m, s| m.max(s.v.norm() / l).max(s.w.norm()));
        st.rows.clear();
        st.rows.resize(n - nn, 0.0);
        // At rest the difference is along time alone (a driver's ∂Φ/∂t), over 1e-4 of the step.
        let eps = if vmax > 0.0 {
            1e-4 / vmax
        } else {
            1e-4 * st.gh
        };
        moved_along_velocities(&self.trial, eps, &mut st.plus);
        moved_along_velocities(&self.trial, -eps, &mut st.minus);
        // Time moves with the state, so a driven (rheonomic) constraint's rows are its
        // total derivative `B v + ∂Φ/∂t`.
        let at = |dt: f64| EvalContext {
            t: ctx.t + dt,
            ..*ctx
        };
        // The constraint rows alone: the elements without multipliers (beams, contacts)
        // are not evaluated at the moved states (and a contact's per-attempt memory is not
        // touched by evaluations at other times).
        self.sys
            .assemble_constraint_rows(&at(eps), &st.plus, &self.trial_lambda);
        st.rows.copy_from_slice(&self.sys.rhs[nn..]);
        self.sys
            .assemble_constraint_rows(&at(-eps), &st.minus, &self.trial_lambda);
        let c = st.gh / (2.0 * eps);
        for (r, m) in st.rows.iter_mut().zip(&self.sys.rhs[nn..]) {
            *r = (*r - m) * c;
        }
    }

    /// Puts the rows of [`Self::stage_velocity_rows`] in place of `s Φ(q_i)` in the
    /// assembled residual (inner stages only).
    pub(super) fn patch_stage_rows(&mut self) {
        let nn = self.sys.n_node_eq;
        if let Some(st) = self.esdirk.as_deref()
            && st.velocity_level
            && st.rows.len() == self.sys.n_eq() - nn
        {
            self.sys.rhs[nn..].copy_from_slice(&st.rows);
        }
    }
}
