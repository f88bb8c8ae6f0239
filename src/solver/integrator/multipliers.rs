//! The reactions of a stage scheme's accepted states, from the index-1 equations of motion
//! at each state (issue 34 §6), and the exact constraint velocities `s B(q) v` both this
//! and the inner stages need.
//!
//! # Why
//! A stiffly accurate ESDIRK's last stage is the step's end, and its multipliers are the
//! last stage's: the `λ` that makes the stage's acceleration
//! `v̇_s = (v_{n+1} − v_n − h Σ_{j<s} a_sj v̇_j)/(γh)` meet the position-level constraint.
//! Those accelerations are only as accurate as the stage order, 2, so the reactions and
//! driving torques converged at order 2 while the velocities converge at 3 (ESDIRK3) and
//! better: on `decks/slider_crank_driven.dat` at h = 4e-2 … 1.25e-3 s the driving torque's
//! error was 6.3e-3 … 6.4e-6 N·m with ESDIRK3 and 2.8e-2 … 2.5e-5 N·m with ESDIRK5, both
//! order 2.0 (the last stage at the velocity level: order 2.0 too; docs/accuracy.md). And a
//! short step amplifies the incoming velocity's error by 1/h: a last step of 0.01 h (END
//! not a multiple of STEP) was 6–26 times as far off as the rows of full steps.
//!
//! Here the accelerations and multipliers of a state are those of
//!
//! `[M  Bᵀ; B  0] [v̇; λ] = [f(q, v, t); −Ḃv − Φ_tt]`
//!
//! at its `(q, v)` (the acceleration-level constraints, as at the start:
//! [`Integrator::consistent_accelerations`]): they carry the order of `(q, v)` — the same
//! torque 1.4e-5 … 2.8e-9 N·m with ESDIRK3 (order 3.0–3.1), 9.3e-8 … 9.0e-11 N·m with
//! ESDIRK5 (order 5, then the floor ~2.5e-11) — and depend on the row's `(q, v, t)` alone,
//! not on the step that led there, so a shortened step's row is as good as any.
//!
//! They are computed for the states an observer reads ([`crate::solver::Observer::reads_reactions`]:
//! the rows `OUTPUT … EVERY n` writes) and put in place of the stage values only while it
//! reads them ([`Integrator::exact_reactions`], [`Integrator::restore_stage_values`]): the
//! integration never sees them, so it is the same whatever is written. The energy balance's
//! drivers' work stays the trapezoid of the stages' multipliers (second order).
//!
//! # How
//! - `c_a M`: the mass matrix is constant in the unknowns `(x, material Θ)` for every element
//!   with inertia (point masses, beams of any order, rigid bars: the Lie-group formulation's
//!   constant mass matrix, Brüls, Cardona & Arnold 2012; asserted by a test here), so it is
//!   computed once (and after a restart), as `(c_a M + K) − K` with `c_a = 2^200`: K lies far
//!   below an ulp of `c_a M` wherever `M ≠ 0` and cancels exactly where `M = 0`, so the result
//!   is `c_a M` bit for bit whatever the state. Each solve then sets the constrained elements'
//!   rows and columns `s B` (`s = c_a m_ref`) from their tangents at the state, assembles the
//!   residual `−f` (zero accelerations and multipliers) and refactors: the nodal right-hand
//!   side is `c_a f`, so `λ = s λ̂ / c_a`.
//! - A matrix of its own, swapped in for the solve: modified Newton keeps its factors of the
//!   iteration matrix across steps, and this one keeps its own pivots (refactored on them
//!   while they pass the threshold test); a checkpoint holds both (`solver/state.rs`), so a
//!   restart writes the same reactions bit for bit.
//! - `Ḃv` as the central difference of the exact `B v` along the geodesic `q exp(±εv)`,
//!   `εω = 1e-5` (`ω = max(|v|/L_ref, |Ω|)`; truncation `(εω)²/6 ≈ 2e-11`, round-off
//!   `ε_mach/(εω) ≈ 1e-11` of the term; the start's second difference of `Φ` with `εω = 1e-3`
//!   has ~1e-7); `Φ_tt` the drivers' own ([`crate::elements::Element::constraint_time_derivatives`]).
//! - Cost, measured (instructions, flexible1 `decks/pendulum_converged.dat` to 0.3 s,
//!   770 steps): 3.18e9 without; with every row read 3.98e9 (+25 %), every 4th (the deck's
//!   `EVERY 4`) 3.39e9 (+6.5 %). With a full tangent assembly per solve it was +65 % and +16 %.
//!
//! `B v` itself ([`ConstraintVelocity`]) is the elements' own directional derivative
//! ([`crate::elements::Element::constraint_rates`], one dual direction), or else the
//! constraint rows of the tangent applied to `(v, Ω)`: exact, where until issue 34 the inner
//! stages took a central difference of `Φ` (its truncation, ~2e-9 of `|v|`, was taken back
//! by the last stage with a force ∝ 1/h: the driven slider-crank's torque error with ESDIRK5
//! grew from 1.3e-4 to 1.05e-3 N·m as h went from 1e-3 to 1.25e-4 s). On flexible1 the exact
//! rows cost 3.3 % fewer instructions than the difference (3.18e9 against 3.29e9 to 0.3 s,
//! the same steps and iterations).

use super::*;
use crate::elements::Local;
use crate::solver::linear::{LinearError, LuState, SparseSystem};

/// `c_a` of the index-1 assembly: `c_a M + K = c_a M` to round-off (module docs).
const MASS_ONLY: f64 = (1u128 << 100) as f64 * (1u128 << 100) as f64;

/// The exact constraint velocities `s B(q) v` of every multiplier row, from the tangents of
/// the elements that carry multipliers (one local buffer of its size each).
#[derive(Debug, Clone)]
pub(super) struct ConstraintVelocity {
    locals: Vec<(usize, Local)>,
}

impl ConstraintVelocity {
    /// Buffers for the constrained elements of `sys`.
    pub(super) fn new(sys: &System) -> Self {
        ConstraintVelocity {
            locals: sys
                .elements
                .iter()
                .enumerate()
                .filter(|(_, e)| e.multipliers() > 0)
                .map(|(k, e)| (k, Local::new(6 * e.nodes().len() + e.multipliers())))
                .collect(),
        }
    }

    /// `out[k − n_node_eq] = s (B(q) v)_k` for each multiplier row `k` at `nodes` (their
    /// `v` and material `Ω`), `s = ctx.constraint_scale`; with `time`, plus `s ∂Φ_k/∂t` at
    /// `ctx.t` for the drivers' rows. Exact, no difference quotient: the elements' own
    /// [`crate::elements::Element::constraint_rates`] (one dual direction), or else the
    /// constraint rows of its tangent (`∂(sΦ)/∂(δx, δΘ)`, material `δΘ`) applied to `(v, Ω)`.
    pub(super) fn rows(
        &mut self,
        sys: &System,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        time: bool,
        out: &mut [f64],
    ) {
        let nn = sys.n_node_eq;
        let s = ctx.constraint_scale;
        for (e, local) in &mut self.locals {
            let el = &sys.elements[*e];
            let m = el.multipliers();
            let o = sys.mult_offset[*e];
            let rows = &mut out[o - nn..o - nn + m];
            if el.constraint_rates(nodes, rows) {
                rows.iter_mut().for_each(|r| *r *= s);
            } else {
                local.clear();
                el.evaluate(ctx, nodes, &lambda[o..o + m], true, local);
                let first = 6 * el.nodes().len();
                for (k, r) in rows.iter_mut().enumerate() {
                    let mut bv = 0.0;
                    for (a, &node) in el.nodes().iter().enumerate() {
                        let st = &nodes[node];
                        for c in 0..3 {
                            bv += local.tan_at(first + k, 6 * a + c) * st.v[c]
                                + local.tan_at(first + k, 6 * a + 3 + c) * st.w[c];
                        }
                    }
                    *r = bv;
                }
            }
            if time && el.rheonomic() {
                for (k, r) in rows.iter_mut().enumerate() {
                    *r += s * el.constraint_time_derivatives(ctx.t, k)[0];
                }
            }
        }
    }
}

/// A constrained element's constraint entries: `(local row, local column, position in the
/// matrix)`.
type Entries = Vec<(usize, usize, usize)>;

/// The index-1 solve's own matrix and work vectors (sized once).
pub(super) struct Index1 {
    /// `[c_a M  sBᵀ; sB  0]`, the iteration matrix's pattern.
    matrix: SparseSystem,
    /// Right-hand side, then solution `[v̇; λ̂]`.
    rhs: Vec<f64>,
    /// `s B v` at `q exp(+εv)` and `q exp(−εv)`.
    plus_rows: Vec<f64>,
    minus_rows: Vec<f64>,
    /// The nodes moved along their velocities.
    moved: Vec<NodeState>,
    /// A zero multiplier vector (n equations).
    zero: Vec<f64>,
    /// `c_a M` in the matrix's pattern (zero in the constraint rows and columns), computed
    /// at the first solve (and after a restart): the mass matrix is constant in the
    /// unknowns `(x, material Θ)` (module docs).
    mass: Vec<f64>,
    /// The constrained elements, each with a local buffer and the positions of its
    /// constraint entries `(local row, local column, position in the matrix)`.
    constrained: Vec<(usize, Local, Entries)>,
    /// The stage scheme's accelerations and multipliers of the state, while the index-1
    /// ones stand in their place (`swapped`).
    acc: Vec<[Vector3<f64>; 2]>,
    stage_lambda: Vec<f64>,
    swapped: bool,
    bv: ConstraintVelocity,
}

impl Index1 {
    /// For a system with multipliers; `None` without (the stages' accelerations are then
    /// `M⁻¹ f` already).
    pub(super) fn sized(sys: &System) -> Option<Box<Self>> {
        let (n, nn) = (sys.n_eq(), sys.n_node_eq);
        if n == nn {
            return None;
        }
        let matrix = SparseSystem::new(&sys.matrix.columns()).ok()?;
        let fixed = crate::solver::system::FIXED;
        let constrained = sys
            .elements
            .iter()
            .enumerate()
            .filter(|(_, e)| e.multipliers() > 0)
            .map(|(k, e)| {
                let (nodes, m, o) = (e.nodes(), e.multipliers(), sys.mult_offset[k]);
                let mut entries = Vec::new();
                for r in 0..m {
                    for (a, &node) in nodes.iter().enumerate() {
                        for comp in 0..6 {
                            let dof = sys.node_dofs[node][comp];
                            if dof == fixed {
                                continue;
                            }
                            let (lr, lc) = (6 * nodes.len() + r, 6 * a + comp);
                            for (row, col, i, j) in [(o + r, dof, lr, lc), (dof, o + r, lc, lr)] {
                                if let Some(p) = matrix.position(row, col) {
                                    entries.push((i, j, p));
                                }
                            }
                        }
                    }
                }
                (k, Local::new(6 * nodes.len() + m), entries)
            })
            .collect();
        Some(Box::new(Index1 {
            matrix,
            rhs: Vec::with_capacity(n),
            plus_rows: vec![0.0; n - nn],
            minus_rows: vec![0.0; n - nn],
            moved: Vec::with_capacity(sys.x0.len()),
            zero: vec![0.0; n],
            mass: Vec::new(),
            constrained,
            acc: Vec::with_capacity(sys.x0.len()),
            stage_lambda: vec![0.0; n],
            swapped: false,
            bv: ConstraintVelocity::new(sys),
        }))
    }
}

impl Integrator {
    /// The index-1 matrix's values, factors and pivots, for a checkpoint: its factorisations
    /// are refactorisations on kept pivots, so a restart needs them to compute the same
    /// reactions bit for bit (`None` without an index-1 solve).
    pub(crate) fn index1_lu(&self) -> Option<LuState> {
        self.index1.as_ref().map(|ix| ix.matrix.save_state())
    }

    /// Restores [`Self::index1_lu`]; a state for a model with (or without) an index-1 solve
    /// when this one has none (or one) is refused.
    pub(crate) fn restore_index1_lu(&mut self, lu: Option<LuState>) -> Result<(), LinearError> {
        match (self.index1.as_deref_mut(), lu) {
            (Some(ix), Some(lu)) => ix.matrix.restore_state(lu),
            (None, None) => Ok(()),
            _ => Err(LinearError::State(
                "the saved state's index-1 multiplier solve does not fit the model".into(),
            )),
        }
    }

    /// Puts in place of the accepted state's accelerations and multipliers those of the
    /// index-1 equations at its `(q, v)` (module docs), for an observer to read; a stage
    /// scheme's own values are kept aside and come back with
    /// [`Integrator::restore_stage_values`], so the integration does not depend on which
    /// states are observed. `false` (nothing changed) for the α family, a model without
    /// multipliers, or a singular or non-finite solve.
    pub fn exact_reactions(&mut self) -> bool {
        let Some(mut ix) = self.index1.take() else {
            return false;
        };
        std::mem::swap(&mut self.sys.matrix, &mut ix.matrix);
        let ok = self.index1_solve(&mut ix);
        std::mem::swap(&mut self.sys.matrix, &mut ix.matrix);
        ix.swapped = ok;
        self.index1 = Some(ix);
        ok
    }

    /// Gives the accepted state back its stage values after [`Integrator::exact_reactions`]
    /// (nothing if that changed nothing).
    pub fn restore_stage_values(&mut self) {
        let Some(ix) = self.index1.as_deref_mut() else {
            return;
        };
        if !std::mem::take(&mut ix.swapped) {
            return;
        }
        for (st, [a, wd]) in self.nodes.iter_mut().zip(&ix.acc) {
            st.a = *a;
            st.wd = *wd;
        }
        self.lambda.copy_from_slice(&ix.stage_lambda);
    }

    /// The index-1 solve into `ix` and the state (see [`Self::exact_reactions`]).
    fn index1_solve(&mut self, ix: &mut Index1) -> bool {
        let n = self.sys.n_eq();
        let nn = self.sys.n_node_eq;
        let c = MASS_ONLY;
        let s = c * self.mass_ref.max(f64::MIN_POSITIVE);
        let ctx = EvalContext {
            t: self.t,
            c_v: 0.0,
            c_a: c,
            dynamic: true,
            gravity: self.sys.gravity,
            constraint_scale: s,
            penalty: 0.0,
            h: 0.0,
        };
        // The residual at zero accelerations and multipliers is −f(q, v, t).
        ix.acc.clear();
        ix.acc.extend(self.nodes.iter().map(|s| [s.a, s.wd]));
        ix.stage_lambda.copy_from_slice(&self.lambda);
        for st in &mut self.nodes {
            st.a = Vector3::zeros();
            st.wd = Vector3::zeros();
        }
        if ix.mass.is_empty() {
            // c_a M = (c_a M + K) − K: K is far below an ulp of c_a M wherever M is not zero,
            // and cancels exactly where it is; the constraint rows cancel too.
            let stiff = EvalContext { c_a: 0.0, ..ctx };
            self.sys.assemble(&stiff, &self.nodes, &ix.zero, true);
            ix.mass.extend_from_slice(&self.sys.matrix.values);
            self.sys.assemble(&ctx, &self.nodes, &ix.zero, true);
            for (m, v) in ix.mass.iter_mut().zip(&self.sys.matrix.values) {
                *m = v - *m;
            }
        }
        self.sys.assemble(&ctx, &self.nodes, &ix.zero, false);
        self.sys.matrix.values.copy_from_slice(&ix.mass);
        for (e, local, entries) in &mut ix.constrained {
            let el = &self.sys.elements[*e];
            local.clear();
            el.evaluate(&ctx, &self.nodes, &ix.zero[..el.multipliers()], true, local);
            for &(i, j, p) in entries.iter() {
                self.sys.matrix.values[p] = local.tan_at(i, j);
            }
        }
        ix.rhs.clear();
        ix.rhs.extend(self.sys.rhs[..nn].iter().map(|r| -c * r));
        // −s(Ḃv + Φ_tt): Ḃv by the central difference of the exact s B v along q exp(±εv).
        let l = self.sys.ref_length;
        let rate = self
            .nodes
            .iter()
            .fold(0.0f64, |m, st| m.max(st.v.norm() / l).max(st.w.norm()));
        ix.rhs.resize(n, 0.0);
        if rate > 0.0 {
            let eps = 1e-5 / rate;
            for (dt, rows) in [(eps, &mut ix.plus_rows), (-eps, &mut ix.minus_rows)] {
                moved_along_velocities(&self.nodes, dt, &mut ix.moved);
                ix.bv
                    .rows(&self.sys, &ctx, &ix.moved, &ix.zero, false, rows);
            }
            for k in 0..n - nn {
                ix.rhs[nn + k] = -(ix.plus_rows[k] - ix.minus_rows[k]) / (2.0 * eps);
            }
        }
        // The drivers' laws at t itself: at a breakpoint of a law (a step lands on it) the
        // row shows the state the step reached, the law's value from before its jump, as
        // the step's own equations and HHT's rows do (the accelerations the next step
        // starts from take the value after it: `consistent_accelerations`).
        let tt = self.t;
        for (e, el) in self.sys.elements.iter().enumerate() {
            if el.rheonomic() {
                let o = self.sys.mult_offset[e];
                for k in 0..el.multipliers() {
                    ix.rhs[o + k] -= s * el.constraint_time_derivatives(tt, k)[1];
                }
            }
        }
        let solved = self.sys.matrix.factor().is_ok() && {
            self.stats.factorizations += 1;
            self.sys.matrix.solve(&mut ix.rhs).is_ok()
        };
        if !solved || ix.rhs.iter().any(|v| !v.is_finite()) {
            for (st, [a, wd]) in self.nodes.iter_mut().zip(&ix.acc) {
                st.a = *a;
                st.wd = *wd;
            }
            return false;
        }
        for (i, d) in self.sys.node_dofs.iter().enumerate() {
            for k in 0..6 {
                let v = if d[k] == crate::solver::system::FIXED {
                    0.0
                } else {
                    ix.rhs[d[k]]
                };
                if k < 3 {
                    self.nodes[i].a[k] = v;
                } else {
                    self.nodes[i].wd[k - 3] = v;
                }
            }
        }
        // λ = s λ̂ / c, stored at the state's scale.
        let to_state = (s / c) / self.scale;
        for k in nn..n {
            self.lambda[k] = ix.rhs[k] * to_state;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use crate::elements::NodeState;
    use nalgebra::Vector3;

    /// Every element kind with inertia (a two-node BEAM, a BEAM of order 3, a damped BEAM, a
    /// MASS with rotary inertia, a RIGID-section bar) and joints that hold some of them.
    const DECK: &str = "TITLE mass block
MATERIALS
  1 E 2.1e11 NU 0.3 RHO 7800
  2 E 2.1e11 NU 0.3 RHO 7800 DAMPING 1e-4
SECTIONS
  1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8
  2 RIGID A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8
NODES
  1 0 0 0 FIX ALL
  2 0 0 0
  3 0.5 0 0
  4 1.0 0.2 0
  5 1.5 0.2 0.1
  6 1.5 0.2 0.1
  7 2.0 0.0 0.3
ELEMENTS
  1 HINGE 1 2 AXIS 0 0 1
  2 BEAM 2 3 MAT 1 SEC 1
  3 BEAM 3 4 MAT 1 SEC 1 ORDER 3
  4 BEAM 4 5 MAT 2 SEC 1
  5 SPHERICAL 5 6
  6 BEAM 6 7 MAT 1 SEC 2
  7 MASS 7 M 1.5 INERTIA 0.01 0.02 0.03
ANALYSIS DYNAMIC ESDIRK5 STEP 1e-4 END 1e-3
END
";

    /// The index-1 solve's mass block `c_a M` does not depend on the state (the property
    /// its cache rests on): computed at the reference state and at random positions,
    /// rotations (up to ~2.6 rad) and velocities, it is the same bit for bit, for every
    /// element kind with inertia. (A future element whose mass matrix depends on the
    /// configuration fails here.)
    #[test]
    fn the_mass_block_is_constant() {
        let model = crate::deck::parse_deck(DECK, "t").expect("parses");
        let mut integ = crate::solver::prepare(&model).expect("builds");
        integ.initialize().expect("starts");
        assert!(integ.exact_reactions());
        let first = integ.index1.as_ref().unwrap().mass.clone();
        assert!(first.iter().any(|v| *v != 0.0));
        let mut g = 12345u64;
        let mut rnd = move || {
            g = g
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (g >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for _ in 0..3 {
            for (k, s) in integ.nodes.iter_mut().enumerate().skip(1) {
                let mut v = || Vector3::new(rnd(), rnd(), rnd());
                *s = NodeState {
                    x: integ.sys.x0[k] + v() * 0.3,
                    r: crate::rotation::exp(&(v() * 3.0)),
                    v: v(),
                    w: v(),
                    a: v(),
                    wd: v(),
                };
            }
            integ.index1.as_mut().unwrap().mass.clear();
            assert!(integ.exact_reactions());
            integ.restore_stage_values();
            assert!(integ.index1.as_ref().unwrap().mass == first);
        }
    }
}
