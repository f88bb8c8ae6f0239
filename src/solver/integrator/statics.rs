//! Static load steps that reach equilibrium: proportional loading, the multipliers'
//! predictor, and pseudo-transient continuation where Newton alone fails.
//!
//! A static analysis walks the load factor `t` from 0 to 1 in load steps (`STEPS`, cut in
//! halves automatically when a step fails). A load with a function follows `f(t)`, and so
//! do drivers (quasi-static motion); gravity and the loads without a `FUNCTION` are applied
//! whole, or in proportion to `t` with `PROPORTIONAL` (load increments).
//!
//! **Multipliers' predictor.** A mechanism's stiffness on its free motions can be all
//! geometric: a hanging pendulum resists a swing only through its rod's tension, the
//! multiplier `λ` times the curvature of the joint's constraint. Newton started from
//! `λ = 0` meets a singular matrix. Each load step therefore starts from the multipliers
//! that best balance the unbalanced forces `r(q, t)` at the step's start,
//! `λ = argmin ‖W^{-1/2}(r + sBᵀλ)‖`, i.e. `[W  sBᵀ; sB  0] [y; λ] = [−r; 0]` with
//! `W = diag(1, L²)` (moments weighed as forces at the model's scale `L`); at an
//! equilibrium they are its multipliers exactly.
//!
//! **Pseudo-transient continuation.** Where Newton still fails (a start far from the
//! equilibrium — a four-bar released 114° from it —, a singular tangent), the load step
//! is solved again by Newton on `K + μW`, the residual's Jacobian shifted by a pseudo-mass
//! `μW`, with `μ` following the residual by switched evolution relaxation,
//! `μ_{k+1} = μ_k ‖r_k‖/‖r_{k−1}‖` (Kelley & Keyes, *SIAM J. Numer. Anal.* 35, 1998,
//! eq. 2.1–2.4; Mulder & Van Leer 1985): far from equilibrium the iteration is a damped
//! descent of the potential energy (towards a stable equilibrium), near it `μ → 0` and it
//! is Newton's, quadratic. A load the model cannot carry (a free motion the loads push
//! along) shows as a drift without end: stopped and said so.

use super::newton::Kinematics;
use super::*;
use crate::solver::linear::SparseSystem;

/// Iterations of the pseudo-transient continuation of one load step.
const MAX_RELAXATION: u32 = 400;

impl Integrator {
    /// One static load step to load factor `t + h` (module docs).
    pub(super) fn try_static_step(&mut self, h: f64) -> Result<StepInfo, Failure> {
        let t1 = self.t + h;
        let ctx = self.context(t1, h, self.scale);
        let nn = self.sys.n_node_eq;
        let constrained = self.sys.n_eq() > nn;
        self.u.iter_mut().for_each(|u| *u = [Vector3::zeros(); 2]);
        self.trial_lambda.copy_from_slice(&self.lambda);
        if constrained {
            self.predict_multipliers(h, &ctx);
        }
        // Newton heading uphill (towards a maximum or a saddle of the potential, an
        // unstable equilibrium: a pendulum released above its pivot's horizontal) is
        // replaced by the continuation, which descends.
        if self.newton_heads_uphill(h, &ctx) {
            return self.relax(h, &ctx);
        }
        match self.newton_solve(h, &ctx, Kinematics::Hht) {
            Ok((iter, rel, history, fref)) => self.finish_step(h, &ctx, iter, rel, history, fref),
            Err(f) if f.reason == FailureReason::Aborted => Err(f),
            Err(f) => {
                self.recycle_history(f.residual_history);
                self.u.iter_mut().for_each(|u| *u = [Vector3::zeros(); 2]);
                self.trial_lambda.copy_from_slice(&self.lambda);
                if constrained {
                    self.predict_multipliers(h, &ctx);
                }
                self.relax(h, &ctx)
            }
        }
    }

    /// The multipliers that best balance the forces at the step's start state (module
    /// docs), into `trial_lambda`. Leaves them as they were when the solve fails.
    fn predict_multipliers(&mut self, h: f64, ctx: &EvalContext) {
        let nn = self.sys.n_node_eq;
        let n = self.sys.n_eq();
        self.trial_from_u(h);
        let mut zero = std::mem::take(&mut self.delta);
        zero.iter_mut().for_each(|v| *v = 0.0);
        self.sys.assemble_with(ctx, &self.trial, &zero, true, None);
        self.delta = zero;
        // A fresh matrix each time: its pivots owe nothing to earlier steps, so a restart
        // from a checkpoint predicts the same multipliers bit for bit.
        let Ok(mut lin) = SparseSystem::new(&self.sys.matrix.columns()) else {
            return;
        };
        lin.values.copy_from_slice(&self.sys.matrix.values);
        let l2 = self.sys.ref_length * self.sys.ref_length;
        for col in 0..nn {
            let w = self.weight(col, l2);
            for p in lin.position_range(col) {
                let row = lin.row_of(p);
                if row < nn {
                    lin.values[p] = if row == col { w } else { 0.0 };
                }
            }
        }
        let mut rhs: Vec<f64> = self.sys.rhs[..nn].iter().map(|r| -r).collect();
        rhs.resize(n, 0.0);
        if lin.factor().is_ok()
            && lin.solve(&mut rhs).is_ok()
            && rhs[nn..].iter().all(|v| v.is_finite())
        {
            self.trial_lambda[nn..].copy_from_slice(&rhs[nn..]);
        }
    }

    /// Whether Newton's first increment from the step's start raises the potential energy:
    /// `rᵀΔ > 0` for the increment `Δ = −S⁻¹r` (`S` the iteration matrix, `r` the
    /// residual, the gradient of the potential of a conservative model), i.e. the
    /// iteration matrix is not positive along the residual; or the matrix is singular.
    /// Leaves the matrix factored for the step (modified Newton starts from it).
    fn newton_heads_uphill(&mut self, h: f64, ctx: &EvalContext) -> bool {
        let nn = self.sys.n_node_eq;
        self.trial_from_u(h);
        self.update_tangent_maps();
        self.sys
            .assemble_with(ctx, &self.trial, &self.trial_lambda, true, Some(&self.tmap));
        self.lu_step = f64::NAN;
        self.stats.factorizations += 1;
        if self.sys.matrix.factor().is_err() {
            return true;
        }
        self.lu_step = h;
        self.keep_frames();
        match self.descent(nn) {
            Some((along, r, d)) => along < -1e-12 * r * d,
            None => true,
        }
    }

    /// `rᵀΔ` for `Δ` the increment of the factored matrix driven by the nodal residual
    /// alone (the constraint rows' residual set to zero: that part of an increment moves
    /// onto the constraints, not along the potential), with `|r|` and `|Δ|`: positive when
    /// the matrix is positive along the residual's projection on the free motions,
    /// `rᵀZ(ZᵀSZ)⁻¹Zᵀr` (`Z` a basis of the constraints' null space). `None` when the
    /// solve fails.
    fn descent(&mut self, nn: usize) -> Option<(f64, f64, f64)> {
        let mut d = self.sys.rhs.clone();
        d[nn..].fill(0.0);
        self.sys.matrix.solve(&mut d).ok()?;
        let r = &self.sys.rhs[..nn];
        let along: f64 = r.iter().zip(&d[..nn]).map(|(a, b)| a * b).sum();
        let rn = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        let dn = d[..nn].iter().map(|x| x * x).sum::<f64>().sqrt();
        Some((along, rn, dn))
    }

    /// `W`'s entry of nodal equation `eq`: 1 for a translation, `L²` for a rotation.
    fn weight(&self, eq: usize, l2: f64) -> f64 {
        match self.sys.owners[eq] {
            crate::solver::system::DofOwner::Node { comp, .. } if comp >= 3 => l2,
            _ => 1.0,
        }
    }

    /// The load step by pseudo-transient continuation (module docs), from the increment
    /// and multipliers already in `u` and `trial_lambda`.
    fn relax(&mut self, h: f64, ctx: &EvalContext) -> Result<StepInfo, Failure> {
        let nn = self.sys.n_node_eq;
        let n = self.sys.n_eq();
        let s = ctx.constraint_scale;
        let l = self.sys.ref_length;
        let l2 = l * l;
        let tol_len = CONSTRAINT_TOL.max(100.0 * f64::EPSILON * l);
        let mut history = std::mem::take(&mut self.history);
        history.clear();
        let (mut mu, mut prev_rn) = (0.0f64, f64::INFINITY);
        let mut last_inc = f64::INFINITY;
        let mut fref = self.sys.ref_force;
        let diag: Vec<usize> = (0..nn)
            .map(|i| {
                self.sys
                    .matrix
                    .position(i, i)
                    .expect("the pattern holds the diagonal")
            })
            .collect();
        for iter in 0..=MAX_RELAXATION {
            if let Some(a) = &self.abort
                && a.load(std::sync::atomic::Ordering::Relaxed)
            {
                return Err(self.failure(h, FailureReason::Aborted, history, fref));
            }
            self.trial_from_u(h);
            self.update_tangent_maps();
            let info = self.sys.assemble_with(
                ctx,
                &self.trial,
                &self.trial_lambda,
                true,
                Some(&self.tmap),
            );
            fref = info.load_scale.max(info.force_scale).max(1e-30);
            let rn = self.sys.rhs[..nn].iter().fold(0.0f64, |m, v| {
                m.max(if v.is_finite() {
                    v.abs()
                } else {
                    f64::INFINITY
                })
            });
            let cf = self.sys.rhs[nn..].iter().fold(0.0f64, |m, v| {
                m.max(if v.is_finite() {
                    v.abs()
                } else {
                    f64::INFINITY
                })
            });
            let fscale = fref.max(self.residual_floor / self.newton.tol_residual);
            let rel = rn.max(cf) / fscale;
            history.push(rel);
            if !rel.is_finite() {
                return Err(self.failure(h, FailureReason::NotFinite, history, fref));
            }
            if rel <= self.newton.tol_residual
                && cf / s <= tol_len
                && last_inc <= self.newton.tol_increment
            {
                self.lu_step = f64::NAN;
                return self.finish_step(h, ctx, iter, rel, history, fref);
            }
            if iter == MAX_RELAXATION {
                break;
            }
            // The pseudo-mass: a first step of about a tenth of the model's size under the
            // residual, then switched evolution relaxation.
            mu = if iter == 0 {
                10.0 * rn / l
            } else {
                mu * (rn / prev_rn).clamp(1e-3, 1e3)
            };
            prev_rn = rn;
            // Shifted until the increment descends (`rᵀΔ > 0` for `Δ = (S + μW)⁻¹r`,
            // as it does once `S + μW` is positive on the free motions).
            let mut shift = mu;
            let mut tries = 0;
            loop {
                for (i, &p) in diag.iter().enumerate() {
                    self.sys.matrix.values[p] += shift * self.weight(i, l2);
                }
                self.lu_step = f64::NAN;
                self.stats.factorizations += 1;
                let solved = self.sys.matrix.factor().is_ok() && {
                    self.delta.copy_from_slice(&self.sys.rhs);
                    self.sys.matrix.solve(&mut self.delta).is_ok()
                };
                let descends = solved && self.descent(nn).is_some_and(|(a, _, _)| a >= 0.0);
                if descends || (solved && tries == 30) {
                    break;
                }
                if tries == 30 {
                    return Err(self.failure(
                        h,
                        FailureReason::Singular(
                            "the shifted iteration matrix of the continuation stays singular"
                                .into(),
                        ),
                        history,
                        fref,
                    ));
                }
                tries += 1;
                shift = 9.0 * mu;
                mu *= 10.0;
            }
            // A trust region of half the model (or half a radian) per iteration.
            let (mut dx, mut dr) = (0.0f64, 0.0f64);
            for d in &self.sys.node_dofs {
                for c in 0..6 {
                    if d[c] != crate::solver::system::FIXED {
                        let v = self.delta[d[c]].abs();
                        if c < 3 {
                            dx = dx.max(v)
                        } else {
                            dr = dr.max(v)
                        }
                    }
                }
            }
            let cut = (0.5 * l / dx.max(1e-300))
                .min(0.5 / dr.max(1e-300))
                .min(1.0);
            for (i, d) in self.sys.node_dofs.iter().enumerate() {
                for c in 0..6 {
                    if d[c] != crate::solver::system::FIXED {
                        let v = -cut * self.delta[d[c]];
                        if c < 3 {
                            self.u[i][0][c] += v;
                        } else {
                            self.u[i][1][c - 3] += v;
                        }
                    }
                }
            }
            for k in nn..n {
                self.trial_lambda[k] -= cut * self.delta[k];
            }
            last_inc = (cut * dx / l).max(cut * dr);
            if !last_inc.is_finite() {
                return Err(self.failure(h, FailureReason::NotFinite, history, fref));
            }
            // A load the model cannot carry drives it away without end.
            let drift = self.u.iter().fold(0.0f64, |m, [x, _]| m.max(x.norm()));
            if drift > 1e3 * l {
                break;
            }
        }
        let (node, drift) = self
            .u
            .iter()
            .enumerate()
            .fold((0, 0.0f64), |(k, m), (i, [x, _])| {
                if x.norm() > m { (i, x.norm()) } else { (k, m) }
            });
        let why = format!(
            "no static equilibrium found at load factor {:.6e}: {} iterations of pseudo-transient continuation left a relative residual of {:.3e}, node {} having moved {drift:.3e} m. The loads are not carried (a free motion they push along: a mechanism without a stop, a body without support), or the equilibrium is beyond a limit point",
            self.t + h,
            history.len().saturating_sub(1),
            history.last().copied().unwrap_or(f64::NAN),
            self.sys.node_ids[node].0
        );
        Err(self.failure(h, FailureReason::NoEquilibrium(why.into()), history, fref))
    }
}
