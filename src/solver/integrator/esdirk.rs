//! L-stable, stiffly accurate ESDIRK schemes on the Lie group `(ℝ³ × SO(3))ⁿ`, with the
//! index-3 constraints met at every step's end: ESDIRK3 and ESDIRK5.
//!
//! # The schemes
//! Kennedy & Carpenter's (NASA/TM-2016-219173) `ESDIRK3(2)4L[2]SA` (§ 5.2.1: four stages,
//! `γ = 0.4358665215084590`) and `ESDIRK5(4)7L[2]SA2` (§ 7.2.2: seven stages, `γ = 23/125`),
//! their tableaux in [`tableau`]: the first stage explicit, the others with the same
//! diagonal `γ`, stage order 2, L-stable, `b = A`'s last row. They are applied to the
//! first-order form of the equations of motion in the local coordinates of the group about
//! the step's start (Munthe-Kaas' RKMK: Munthe-Kaas 1998, BIT 38; Iserles et al. 2000, Acta
//! Numerica 9, § 5):
//! - per node, `x_i = x_n + U_i`, `R_i = R_n exp(Ũ_i)`, `U_i = h Σ_j a_ij Û_j`, where the
//!   stage's algebra velocity is `Û_j = v_j` (translation) and `Û_j = T(U_j)⁻¹ Ω_j`
//!   (rotation: `Ω = T(U) U̇`, paper eq. (3), so the RK stages see the exact `dexp⁻¹`);
//! - `v_i = v_n + h Σ_j a_ij v̇_j`, `Ω_i = Ω_n + h Σ_j a_ij Ω̇_j` (material frame);
//! - at each implicit stage, equilibrium `r(q_i, v_i, v̇_i, λ_i) = 0` at `t_n + c_i h`; the
//!   inner stages meet the constraints at the velocity level, `B(q_i) v_i + ∂Φ/∂t = 0` (an
//!   index-2 stage: Hairer & Wanner II, § VII.4, order min(p, q + 1) = 3 for stage order
//!   q = 2), the last one at the position level, `Φ(q_{n+1}) = 0`, so the constraints hold
//!   at every step's end (stiffly accurate: the last stage is the step's end).
//!
//! So both schemes are third order in the positions of a constrained model (the index-3
//! order reduction of stage order 2); ESDIRK5 is fifth order without constraints (the free
//! rigid body, tests/esdirk.rs) and has the smaller error constants: it keeps the modes
//! up to `ωh ≈ 5` (`1 − |R(iωh)|` = 3.8e-5 at `ωh = 1`, 8.6e-3 at 5) where ESDIRK3 damps
//! them (1.8e-2 at 1, 0.48 at 5).
//!
//! The last stage's multipliers (and accelerations) are only second order (the stage
//! order): the rows a run writes carry those of the index-1 equations at the state's
//! `(q, v)` instead, computed for the observer alone ([`super::multipliers`]).
//!
//! Stage 1 is the start state itself: its accelerations are the consistent ones the last
//! stage of the previous step (or [`Integrator::consistent_accelerations`] at a start or
//! a contact's restart) solved, so the scheme is one-step in `(q, v)` and keeps no history
//! across steps (a checkpoint needs nothing more than HHT's). Each stage's Newton starts
//! from `predict`'s extrapolation of the stages already solved in the same step.
//!
//! Newton's unknown at stage i is `U_i`; then `∂v_i/∂U_i = 1/(γh)` and
//! `∂v̇_i/∂U_i = 1/(γh)²` exactly for translations (and to `O(|U|)` for rotations, where
//! `T(U)` is left out of the inertia's columns): the iteration matrix is HHT's with
//! `c_v = 1/(γh)`, `c_a = 1/(γh)²`, the same for all the stages and for every step of
//! the same size, so modified Newton keeps one factorisation across stages and steps.
//! Linear stability (all stages share `γ`): `R(z) = 1 + z bᵀ(I − zA)⁻¹1`, `|R(iωh)| < 1`
//! for `ωh > 0`, `R(∞) = 0` (L-stable): high frequencies are annihilated, the low ones
//! damped by `O((ωh)⁴)` (ESDIRK3) or `O((ωh)⁶)` (ESDIRK5) per step.

use super::newton::Kinematics;
use super::*;

pub mod tableau;

pub use tableau::{ESDIRK3, ESDIRK5, MAX_STAGES, Tableau};

/// The tableau of an ESDIRK scheme, `None` for the α family.
pub fn tableau_of(scheme: &Scheme) -> Option<&'static Tableau> {
    match scheme {
        Scheme::Esdirk3 => Some(&ESDIRK3),
        Scheme::Esdirk5 => Some(&ESDIRK5),
        Scheme::Hht { .. } | Scheme::GeneralizedAlpha { .. } => None,
    }
}

/// Most stages.
const S: usize = MAX_STAGES;

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
    /// The scheme's coefficients.
    tab: &'static Tableau,
    /// Whether the stage being solved meets its constraints at the velocity level (module
    /// docs: the inner stages), with their rows `s γh (B(q_i) v_i + ∂Φ/∂t)` in `rows`.
    velocity_level: bool,
    rows: Vec<f64>,
    /// The exact `s B v` of the constrained elements (the joints, drivers, rigid bars).
    bv: super::multipliers::ConstraintVelocity,
    /// The step's embedded position and velocity errors per node ([`Integrator::embedded_error`]).
    err_x: Vec<Pair>,
    err_v: Vec<Pair>,
}

impl Stages {
    pub(super) fn sized(sys: &System, tab: &'static Tableau) -> Self {
        let nodes = sys.x0.len();
        let z = [Vector3::zeros(); 2];
        Stages {
            vel: vec![[z; S]; nodes],
            acc: vec![[z; S]; nodes],
            known_u: vec![z; nodes],
            known_v: vec![z; nodes],
            gh: 0.0,
            tab,
            velocity_level: false,
            rows: Vec::new(),
            bv: super::multipliers::ConstraintVelocity::new(sys),
            err_x: Vec::with_capacity(nodes),
            err_v: Vec::with_capacity(nodes),
        }
    }
}

/// The predicted algebra velocity `Û_i` of stage `i` from the stages `j < i` of the step
/// under way: the polynomial in `τ = c h` through `(c_j, Û_j)` for the (at most) three
/// stages `j` nearest to `c_i`, with `Û̇(0) = (v̇_n, Ω̇_n)` added while fewer than three are
/// known (Hermite at the start). A low degree on purpose: the stiff components of the stages
/// are not smooth in `c`, and a polynomial through all six of ESDIRK5's stages amplifies
/// them up to 35-fold at its last stage (its Lebesgue constant there), three nearest 2–4.
fn predict(tab: &Tableau, i: usize, vel: &[Pair; S], acc0: &Pair, h: f64) -> Pair {
    let ci = tab.c(i);
    // The nodes: (c_j, index) of the three stages nearest to c_i.
    let mut near: [(f64, usize); S] = [(f64::INFINITY, 0); S];
    for (j, n) in near.iter_mut().enumerate().take(i) {
        *n = ((tab.c(j) - ci).abs(), j);
    }
    near[..i].sort_by(|a, b| a.0.total_cmp(&b.0));
    let m = i.min(3);
    let mut out = [Vector3::zeros(); 2];
    for (comp, o) in out.iter_mut().enumerate() {
        if m == 1 {
            // Û(τ) = Û_0 + τ Û̇_0.
            *o = vel[0][comp] + acc0[comp] * (ci * h);
        } else if m == 2 && near[..2].iter().any(|n| n.1 == 0) {
            // Hermite: Û_0, Û̇_0 at 0 and Û_j at c_j (τ in units of h).
            let j = if near[0].1 == 0 { near[1].1 } else { near[0].1 };
            let cj = tab.c(j);
            let d0 = acc0[comp] * h;
            let slope = (vel[j][comp] - vel[0][comp]) / cj;
            let curv = (slope - d0) / cj;
            *o = vel[0][comp] + d0 * ci + curv * (ci * ci);
        } else {
            // Lagrange through the m nearest stages.
            for a in 0..m {
                let (ja, ca) = (near[a].1, tab.c(near[a].1));
                let mut l = 1.0;
                for b in 0..m {
                    if b != a {
                        let cb = tab.c(near[b].1);
                        l *= (ci - cb) / (ca - cb);
                    }
                }
                *o += vel[ja][comp] * l;
            }
        }
    }
    out
}

impl Integrator {
    /// Whether an ESDIRK scheme integrates (else the α family).
    pub fn is_esdirk(&self) -> bool {
        self.esdirk.is_some()
    }

    /// One ESDIRK step of size `h` (module docs): the implicit stages by Newton,
    /// then the checks of a converged step and the acceptance of the last stage. On
    /// failure the accepted state is unchanged.
    pub(super) fn try_esdirk_step(&mut self, h: f64) -> Result<StepInfo, Failure> {
        let tab = self.esdirk.as_deref().expect("ESDIRK stages").tab;
        let (a, last) = (&tab.a, tab.stages - 1);
        let gh = tab.gamma * h;
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
        for i in 1..=last {
            let ci = tab.c(i);
            let st = self.esdirk.as_deref_mut().expect("ESDIRK stages");
            for (k, s) in self.nodes.iter().enumerate() {
                let (mut ku, mut kv) = ([Vector3::zeros(); 2], [s.v, s.w]);
                for j in 0..i {
                    for c in 0..2 {
                        ku[c] += st.vel[k][j][c] * (h * a[i][j]);
                        kv[c] += st.acc[k][j][c] * (h * a[i][j]);
                    }
                }
                st.known_u[k] = ku;
                st.known_v[k] = kv;
                // Predictor: the stage's algebra velocity extrapolated from the stages
                // solved so far ([`predict`]), `U_i = h Σ_{j<i} a_ij Û_j + γh Û_i`.
                let pred = predict(tab, i, &st.vel[k], &st.acc[k][0], h);
                self.u[k] = [ku[0] + pred[0] * gh, ku[1] + pred[1] * gh];
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
                .velocity_level = i < last;
            let (iter, rel, history, fref) = self.newton_solve(h, &ctx, Kinematics::Stage)?;
            if i == last {
                let mut info = self.finish_step(h, &ctx, iter, rel, history, fref)?;
                self.stats.newton_iterations += u64::from(before);
                info.iterations += before;
                return Ok(info);
            }
            // Event control over [t, t + c_i h], from the step's start to the stage: a stage
            // may sit deep in a contact that both ends of the step are clear of (a step of
            // 1e-3 s over the steel clearance impact of `decks/stab_clearance_impact.dat`,
            // 1e-4 s long, ended with 0.3 J of 5.0 with ESDIRK3 and created 33 J with
            // ESDIRK5, and neither end saw it). A refusal refuses the whole step, to retry at
            // the length asked (measured from the step's start, as at the end).
            let (_, history) = self.event_control(h, ci * h, &ctx, history, fref)?;
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

    /// The error of the step just solved, by the scheme's embedded pair (Kennedy &
    /// Carpenter 2016, § 2.3, weights `b̂`): per node, in the algebra of the step's start,
    /// the position difference `e_x = h Σ_j (b_j − b̂_j) Û_j` (translation, rotation vector;
    /// the last stage's `Û` from Newton's `U`) and the velocity difference
    /// `e_v = h Σ_j (b_j − b̂_j) (v̇_j, Ω̇_j)`, measured as `max(|e_x|, T |e_v|)` against
    /// TOLPOS (TOLROT), `T` the run's length: a velocity error made now displaces the
    /// positions by up to `T |e_v|` by the end of the run. Max over the nodes; ≤ 1 acceptable.
    ///
    /// Why the velocity: with index-3 constraints both schemes are third order in the
    /// positions, the embedded difference of ESDIRK5's positions is `O(h⁵)` while the
    /// positions err by `O(h⁴)` per step, so controlling it alone left the global error
    /// `∝ TOL^0.69`; the velocities' difference carries the order reduction (`O(h³)`, the
    /// order of the global error), and with it the global error is `∝ TOL^1.02` (ESDIRK3:
    /// `TOL^0.97`, whose `e_x` is already `O(h³)`) on the simple pendulum
    /// (`tests/study.rs`, docs/accuracy.md "Accuracy asked for").
    pub(super) fn embedded_error(
        &mut self,
        h: f64,
        a: &crate::model::Adaptive,
        ctx: &EvalContext,
    ) -> f64 {
        let st = self.esdirk.as_deref_mut().expect("ESDIRK stages");
        let (mut ex, mut evs) = (std::mem::take(&mut st.err_x), std::mem::take(&mut st.err_v));
        ex.clear();
        evs.clear();
        let tab = st.tab;
        let last = tab.stages - 1;
        for (k, u) in self.u.iter().enumerate() {
            let w_last = h * (tab.a[last][last] - tab.embedded[last]) / st.gh;
            let mut e = [
                (u[0] - st.known_u[k][0]) * w_last,
                (u[1] - st.known_u[k][1]) * w_last,
            ];
            let wl = h * (tab.a[last][last] - tab.embedded[last]);
            let mut ev = [self.trial[k].a * wl, self.trial[k].wd * wl];
            for j in 0..last {
                let w = h * (tab.a[last][j] - tab.embedded[j]);
                e[0] += st.vel[k][j][0] * w;
                e[1] += st.vel[k][j][1] * w;
                ev[0] += st.acc[k][j][0] * w;
                ev[1] += st.acc[k][j][1] * w;
            }
            ex.push(e);
            evs.push(ev);
        }
        // A velocity error made now displaces the positions by up to `e_v T` by the
        // end of the run (`T` = END) if it is a drift, by `|e_v|/ω` if it is a vibration
        // of frequency ω ([`super::drift`]).
        let t = self.error_horizon;
        let z = match a.carry {
            crate::model::Carry::Run => None,
            crate::model::Carry::Modes => self.drift_filtered(&evs, ctx),
        };
        let mut err = 0.0f64;
        for (k, (e, ev)) in ex.iter().zip(&evs).enumerate() {
            let mut m = [t * ev[0].norm(), t * ev[1].norm()];
            if let Some(z) = z {
                for c in 0..2 {
                    let zn = z[k][c].norm().min(ev[c].norm());
                    m[c] = t * (ev[c].norm() * zn).sqrt();
                }
            }
            err = err
                .max(e[0].norm().max(m[0]) / a.tol_position)
                .max(e[1].norm().max(m[1]) / a.tol_rotation);
        }
        let st = self.esdirk.as_deref_mut().expect("ESDIRK stages");
        (st.err_x, st.err_v) = (ex, evs);
        err
    }

    /// The step controller's exponent `1/(q + 1)`: the local error measure is
    /// `O(h^{q+1})` with `q` the embedded order (ESDIRK) or 2 (HHT's Zienkiewicz–Xie).
    pub(super) fn error_exponent(&self) -> f64 {
        match self.esdirk.as_deref() {
            Some(st) => 1.0 / f64::from(st.tab.embedded_order + 1),
            None => 1.0 / 3.0,
        }
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

    /// The constraint rows of an inner stage, `s γh (B(q_i) v_i + ∂Φ/∂t)` (module docs), into
    /// the stages' `rows`, exact: `B v` the elements' directional derivative of `Φ` along
    /// `(v, Ω)` ([`super::multipliers::ConstraintVelocity`]), `∂Φ/∂t` the drivers' own
    /// ([`crate::elements::Element::constraint_time_derivatives`]). Nothing for HHT or the
    /// last stage.
    ///
    /// (Until issue 34 `B v` was a central difference of `Φ` along `q exp(±εv)` with
    /// `ε|v| = 1e-4 L_ref`: its truncation, ~2e-9 of `|v|`, left each inner stage off the
    /// constraint by ~2e-9 |v| γh, which the last stage's position-level rows took back with
    /// a force ∝ 1/h — the driven slider-crank's torque error with ESDIRK5 doubled as h
    /// halved, 1.3e-4 N·m at h = 1e-3 s and 1.05e-3 N·m at 1.25e-4 s, docs/accuracy.md.)
    pub(super) fn stage_velocity_rows(&mut self, ctx: &EvalContext) {
        let nn = self.sys.n_node_eq;
        let n = self.sys.n_eq();
        let Some(st) = self.esdirk.as_deref_mut() else {
            return;
        };
        if !st.velocity_level || n == nn {
            return;
        }
        st.rows.clear();
        st.rows.resize(n - nn, 0.0);
        st.bv.rows(
            &self.sys,
            ctx,
            &self.trial,
            &self.trial_lambda,
            true,
            &mut st.rows,
        );
        let gh = st.gh;
        st.rows.iter_mut().for_each(|r| *r *= gh);
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
