//! The Newton loop of a step (modified or full Newton, polishing, constraint and residual
//! tests) and the diagnosis of a failed step.

use super::*;
use crate::solver::energy_guard;

impl Integrator {
    /// What the elements have to say about the last trial state (or, if an element is
    /// silent on it, the last accepted one), e.g. a universal joint at 90°.
    pub(super) fn diagnoses(&self) -> Box<[String]> {
        self.sys
            .elements
            .iter()
            .filter_map(|e| e.diagnose(&self.trial).or_else(|| e.diagnose(&self.nodes)))
            .collect()
    }

    /// The drivers' and controlled inputs' powers at the start and at the end of a trial step (W: the energy
    /// guard integrates them as the loads', trapezoidally).
    fn driver_powers(&self, ctx: &EvalContext) -> (f64, f64) {
        if !self.sys.elements.iter().any(|e| e.does_work()) {
            return (0.0, 0.0);
        }
        let ctx_old = EvalContext {
            t: self.t,
            constraint_scale: self.scale,
            ..*ctx
        };
        let p_old = self.sys.input_power(&ctx_old, &self.nodes, &self.lambda);
        let p_new = self.sys.input_power(ctx, &self.trial, &self.trial_lambda);
        (p_old, p_new)
    }

    /// The energy guard on the trial step of size `h` (`energy_guard`): the record to keep
    /// once the step is accepted, or the refused jump.
    fn guard(
        &mut self,
        h: f64,
        ctx: &EvalContext,
        fref: f64,
    ) -> Result<energy_guard::Passed, energy_guard::EnergyJump> {
        let key = (self.stats.steps, self.stats.restarts, self.t);
        let old = match self.guard_cache {
            Some((s, r, t, m)) if (s, r, t) == key => m,
            _ => energy_guard::measure(&self.sys, &self.nodes, self.t),
        };
        let new = energy_guard::measure(&self.sys, &self.trial, self.t + h);
        // What Newton leaves: the accepted state is within δ (`newton_left`: m / L_ref,
        // rad) of the step's discrete solution, its velocities within c_v δ; its energies
        // are uncertain by Σ|p·δv| + Σ|f·δx| ≤ c_v δ (L_ref √(2T M) + √(2T J)) + δ L_ref n f_ref
        // (M, J the model's translational and rotational masses: Cauchy–Schwarz). The next
        // step starts from that state, so what each step leaves adds up over a run of steps:
        // it is accumulated with the quadrature's brackets (`energy_guard::check`).
        let n = self.nodes.len() as f64;
        let delta = self.newton_left;
        let two_t = 2.0 * old.kinetic.max(new.kinetic).max(0.0);
        let newton = ctx.c_v
            * delta
            * (self.sys.ref_length * (two_t * self.mass_ref * n).sqrt()
                + (two_t * self.rot_mass_ref * n).sqrt())
            + delta * self.sys.ref_length * n * fref;
        // A step across an event it could not land on (a contact's touch closer than the
        // smallest step): the force's derivative jumps inside it, the scheme's order is lost
        // on it, and its energy error is bounded by what the forces stored over it, |ΔU|
        // (the clearance journal's touch at 1e-4 s inside a step of MINSTEP = 9.8e-7 s:
        // 6.2e-6 J created against 1.2e-3 J stored, tests/esdirk.rs
        // stages_see_a_clearance_impact_inside_a_step).
        let straddle = if self.straddled {
            (new.strain - old.strain).abs()
        } else {
            0.0
        };
        // The round-off of the equilibrium.
        let floor = self.residual_floor * self.sys.ref_length + straddle;
        let step = energy_guard::Step {
            old,
            new,
            drive: self.driver_powers(ctx),
            h,
            t_new: self.t + h,
            newton,
            at_floor: h <= self.event_floor * (1.0 + crate::solver::FLOOR_SLACK),
        };
        let passed = energy_guard::check(
            &self.balance,
            &step,
            self.guard_g,
            floor,
            self.sys.elements.len(),
        )?;
        // Kept for the next step if the accepted state is not changed (a restart of the
        // accelerations counts a restart and changes the key).
        self.guard_cache = Some((self.stats.steps + 1, self.stats.restarts, self.t + h, new));
        Ok(passed)
    }

    pub(super) fn failure(
        &self,
        h: f64,
        reason: FailureReason,
        history: Vec<f64>,
        fref: f64,
    ) -> Failure {
        // Worst equation of the last assembled residual.
        let (mut worst, mut wv) = (0, 0.0f64);
        for (i, r) in self.sys.rhs.iter().enumerate() {
            let v = if r.is_finite() {
                r.abs()
            } else {
                f64::INFINITY
            };
            if v > wv {
                wv = v;
                worst = i;
            }
        }
        // A step an element refuses (a contact's event ahead) is routine, not a diagnosis:
        // no worst equation or element messages are formatted for it (no allocation).
        let routine = matches!(reason, FailureReason::StepRefused(_));
        Failure {
            time: self.t,
            step: h,
            load_steps: !self.dynamic,
            reason,
            residual_history: history,
            worst: if routine {
                Box::default()
            } else if self.sys.n_eq() > 0 {
                self.sys.describe(worst).into()
            } else {
                "-".into()
            },
            worst_value: wv,
            reference_force: fref,
            diagnoses: if routine {
                Box::default()
            } else {
                self.diagnoses()
            },
        }
    }

    /// Attempts one step of size `h` from the current state (or one load increment to
    /// load factor `t + h` in statics). On success the state advances; on failure it is
    /// left unchanged and a diagnosis is returned.
    pub fn try_step(&mut self, h: f64) -> Result<StepInfo, Failure> {
        if self.dynamic && self.esdirk.is_some() {
            return self.try_esdirk_step(h);
        }
        if !self.dynamic {
            return self.try_static_step(h);
        }
        let t1 = self.t + h;
        let p = self.params;
        // Rescale multipliers to this step's constraint scale.
        let s_new = if self.dynamic {
            self.scale_for(h)
        } else {
            self.scale
        };
        let ratio = self.scale / s_new;
        let nn = self.sys.n_node_eq;
        self.trial_lambda.copy_from_slice(&self.lambda);
        for l in &mut self.trial_lambda[nn..] {
            *l *= ratio;
        }
        // Predictor: constant true acceleration (dynamics): `v̇_{n+1} = v̇_n`, so
        // `a_{n+1} = (v̇_n − α_m a_n)/(1 − α_m)` (HHT: `a_{n+1} = v̇_n`, exactly); or no
        // increment (statics).
        for i in 0..self.nodes.len() {
            let s = &self.nodes[i];
            self.u[i] = if self.dynamic {
                let [a0x, a0r] = self.pseudo[i];
                let m = 1.0 - p.alpha_m;
                let (a1x, a1r) = ((s.a - a0x * p.alpha_m) / m, (s.wd - a0r * p.alpha_m) / m);
                [
                    s.v * h + (a0x * (0.5 - p.beta) + a1x * p.beta) * (h * h),
                    s.w * h + (a0r * (0.5 - p.beta) + a1r * p.beta) * (h * h),
                ]
            } else {
                [Vector3::zeros(); 2]
            };
        }
        let ctx = self.context(t1, h, s_new);
        let (iter, rel, history, fref) = self.newton_solve(h, &ctx, Kinematics::Hht)?;
        self.finish_step(h, &ctx, iter, rel, history, fref)
    }

    /// Newton's iterations on the increment `u` (from its predictor) until the equations
    /// at `ctx` hold, the trial state following `u` through `kin`. Returns the iterations,
    /// the final relative residual, the residual history and the reference force; the
    /// accepted state is not touched.
    pub(super) fn newton_solve(
        &mut self,
        h: f64,
        ctx: &EvalContext,
        kin: Kinematics,
    ) -> Result<(u32, f64, Vec<f64>, f64), Failure> {
        let ctx = *ctx;
        let s_new = ctx.constraint_scale;
        let nn = self.sys.n_node_eq;
        let mut history = std::mem::take(&mut self.history);
        history.clear();
        // Constraint equations are met to an absolute tolerance (m or rad), with a round-off
        // floor for very large models.
        let tol_len = CONSTRAINT_TOL.max(100.0 * f64::EPSILON * self.sys.ref_length);
        // A driver's row `s Φ₆` compares an angle of up to π (a hinge's or a rotation's)
        // with its law: its round-off is s ε π, not the s ε L_ref of a row in lengths that
        // the floor below counts. With L_ref < π (a small mechanism) Newton stagnated one
        // ulp of the angle above the tolerance at the 1e-8 s steps of an impact
        // (decks/benchmarks/slider_crank_clearance.dat driven: 1.17e-8 against 1e-8).
        let driver_floor = if self.sys.elements.iter().any(|e| e.rheonomic()) {
            10.0 * f64::EPSILON * std::f64::consts::PI * s_new
        } else {
            0.0
        };
        let mut last_inc = f64::INFINITY;
        let mut prev_inc = f64::INFINITY;
        let mut fref = self.sys.ref_force;
        // Modified Newton: the iteration matrix factored for an earlier iterate (of this
        // step, or of a previous step of the same size) is kept while the residual contracts
        // by at least CONTRACTION per iteration; otherwise it is rebuilt at the current
        // iterate. Iterations without a rebuild assemble the residual alone.
        // (A step of the same size within round-off: fixed steps coming back to their grid after
        // an event are differences of times.)
        // (lu_step is NaN when no factorisation is valid: the test below is then false.)
        // A stage of the ESDIRK schemes keeps its matrix down to a contraction of 1/2: its
        // step moves the state 5–25 HHT steps' worth, so the joints' rows of a matrix kept
        // from an earlier step converge linearly at ~0.1–0.5 while the node rows converge at
        // ~1e-3; rebuilding at 1/4 cost ESDIRK5 1.29 factorisations per step on flexible1 at
        // H = 3.90625e-4 s, at 1/2 0.83, for 11 % more iterations and ~8 % less CPU. HHT and
        // generalized-α keep theirs down to 0.35 (`CONTRACTION`: measured on the beam
        // benchmarks and bounded by the stiff-bar pendulum's accuracy, issue 37).
        let contraction = match kin {
            Kinematics::Hht => CONTRACTION,
            Kinematics::Stage => STAGE_CONTRACTION,
        };
        let same_step = (self.lu_step - h).abs() <= 1e-9 * h;
        let mut tangent = !self.newton.modified || !same_step;
        let mut prev_rel = f64::INFINITY;
        // Whether the last solve used a matrix built at the iterate it started from.
        let mut fresh = false;
        for iter in 0..=self.newton.max_iterations {
            if let Some(a) = &self.abort
                && a.load(std::sync::atomic::Ordering::Relaxed)
            {
                return Err(self.failure(h, FailureReason::Aborted, history, fref));
            }
            match kin {
                Kinematics::Hht => self.trial_from_u(h),
                Kinematics::Stage => {
                    self.stage_from_u();
                    self.stage_velocity_rows(&ctx);
                }
            }
            if tangent {
                self.update_tangent_maps();
            }
            let info = self.sys.assemble_with(
                &ctx,
                &self.trial,
                &self.trial_lambda,
                tangent,
                Some(&self.tmap),
            );
            self.patch_stage_rows();
            // The forces in play now: the loads at t + h and the elements' own forces, not
            // the largest load of the whole run (a pulse long over, or a huge load, would
            // make any residual look small: issue 28).
            fref = info.load_scale.max(info.force_scale).max(1e-30);
            let rn = self.sys.rhs[..nn]
                .iter()
                .fold(0.0f64, |m, v| nan_max(m, v.abs()));
            // Constraint rows hold `s Φ`: a force, so they get the force tolerance too
            // (else a violation of the absolute tolerance, amplified by 1/(βh²) through the
            // inertia terms, shows up in the multipliers: Cardona & Géradin 1989).
            let cf = self.sys.rhs[nn..]
                .iter()
                .fold(0.0f64, |m, v| nan_max(m, v.abs()));
            let cn = cf / s_new;
            // Round-off of the inertia terms: positions known to ε L_ref, angles to ε rad
            // (a body spinning exactly about a principal axis has nothing else to scale by).
            let floor = self.residual_floor
                + driver_floor
                + 10.0
                    * f64::EPSILON
                    * ctx.c_a
                    * (self.sys.ref_length * self.mass_ref + self.rot_mass_ref);
            let fscale = fref.max(floor / self.newton.tol_residual);
            let rel = rn.max(cf) / fscale;
            history.push(rel);
            // A reference that is not finite (a force beyond f64) would make every
            // residual relative zero: that is a non-finite solution, not convergence.
            if !rel.is_finite() || !cn.is_finite() || !fscale.is_finite() {
                return Err(self.failure(h, FailureReason::NotFinite, history, fref));
            }
            // After a solve with a kept matrix the iterate's error is ~ρ/(1−ρ) of the last
            // increment, not ~its square as after a Newton step: iterate on while the
            // residual still falls (each such iteration is one residual and one solve), so
            // the result is as accurate as full Newton's (the rigid pendulum drifts by
            // 4e-5 m in 0.3 s otherwise: residuals at the round-off floor of stiff bars hide
            // 1e-10 m errors in the mechanism's directions, which add up step after step).
            // Where the residual stagnates above that (the round-off floor of stiff models)
            // it no longer shows the error: with E = 2.1e15 bars an iterate accepted there
            // drifted 5.2e-8 m in 0.3 s from full Newton (an error in u becomes a velocity
            // error γ/(βh) times larger). There the increments must have fallen to 1/1000 of
            // the increment tolerance too, or have stopped falling (round-off): 2.3e-9 m
            // (`tests/accuracy.rs`), for no more iterations elsewhere. (5.2e-9 m at
            // CONTRACTION = 0.35, 2.8e-8 m at ½: a kept matrix contracting by nearly ½ passes
            // the "stopped falling" test below, which is why CONTRACTION stays under ½.)
            let increments_done =
                last_inc <= 1e-3 * self.newton.tol_increment || last_inc > 0.5 * prev_inc;
            // A stage of the ESDIRK schemes also stops when the kept matrix's contraction
            // `ρ` (the residual's, as a proxy) says the next iteration would already be
            // polished — its residual `ρ·rel` below 1/100 of the tolerance, the polishing
            // rule's own bound — and bounds what remains of the error, `ρ/(1 − ρ)` of the
            // last increment, below the same 1/1000 of the increment tolerance (Hairer &
            // Wanner II, § IV.8, eq. 8.10): a stage that contracted by 1e-3 per iteration
            // needs no extra iteration to show it. (The increment bound alone is not enough:
            // an error δu is δu/(γh)² in the accelerations, and without the residual bound the
            // simple pendulum's hinge reaction at h = 1e-5 s was 1.0e-3 off, 16 times its
            // round-off bound, `tests/stability/stiff.rs`.) Not for the α family: tried in issue 37
            // (−7 % of the cantilever's CPU), it left the simple pendulum's hinge reaction at
            // h = 1e-6 s 4.5e-2 off, twice its round-off bound (`tests/stability/stiff.rs`,
            // `step_range_keeps_iterations_and_multipliers`): HHT's index-3 multipliers need
            // the polishing the stages' velocity-level rows do not. (On a model without
            // multipliers it left ten times the Newton error at the same tolerance, for the
            // same work at equal error: docs/performance.md, "Tried and dropped".)
            let rho = rel / prev_rel;
            let contracted = kin == Kinematics::Stage
                && rho < 0.5
                && rho * rel <= 0.01 * self.newton.tol_residual
                && rho / (1.0 - rho) * last_inc <= 1e-3 * self.newton.tol_increment;
            let polished = iter == 0
                || fresh
                || rel <= 0.01 * self.newton.tol_residual
                || contracted
                || (rel > 0.5 * prev_rel && increments_done);
            let converged = rel <= self.newton.tol_residual
                && cn <= tol_len
                && (iter == 0 || last_inc <= self.newton.tol_increment)
                && polished;
            if converged {
                // What the iteration leaves of the solution: the last increment bounds it
                // where the iteration contracts by ρ ≤ 1/2 (the remainder is at most
                // ρ/(1 − ρ) of it: Hairer & Wanner II, § IV.8, eq. 8.10) — convergence asks
                // the increments to have fallen to 1/1000 of the tolerance or stopped
                // falling, where they are the round-off the state is known to; the
                // predictor accepted as it is (no increment) gets the tolerance itself.
                self.newton_left = if iter == 0 {
                    self.newton.tol_increment
                } else {
                    last_inc.min(self.newton.tol_increment)
                };
                return Ok((iter, rel, history, fref));
            }
            if iter == self.newton.max_iterations {
                break;
            }
            // A kept matrix must contract the residual by CONTRACTION per iteration, and
            // past half of the iterations allowed it is rebuilt anyway: a linear rate that
            // passes the test could still spend them all on polishing, where a fresh Newton
            // step converges quadratically.
            let slow = iter > 0
                && (rel > contraction * prev_rel || 2 * iter >= self.newton.max_iterations);
            if !tangent && slow {
                // The kept matrix no longer contracts well: rebuild it here (the residual
                // is assembled again with it; `rel` above was finite, or we returned).
                tangent = true;
                self.update_tangent_maps();
                self.sys.assemble_with(
                    &ctx,
                    &self.trial,
                    &self.trial_lambda,
                    true,
                    Some(&self.tmap),
                );
                self.patch_stage_rows();
            }
            prev_rel = rel;
            fresh = tangent;
            if tangent {
                self.lu_step = f64::NAN;
                if let Err(e) = self.sys.matrix.factor() {
                    self.stats.factorizations += 1;
                    let why =
                        match crate::solver::redundancy::redundancy_error(&self.sys, &self.trial) {
                            Some(r) => format!("{e}; {r}"),
                            None => e.to_string(),
                        };
                    return Err(self.failure(h, FailureReason::Singular(why), history, fref));
                }
                self.stats.factorizations += 1;
                self.lu_step = h;
                self.keep_frames();
                tangent = !self.newton.modified;
            }
            self.delta.copy_from_slice(&self.sys.rhs);
            // A kept matrix is applied in the frames of the iterate it was built at
            // (`corotated.rs`: on the beam benchmarks 3–6 times fewer factorisations).
            let turned = !fresh;
            if turned {
                self.turn_translation_rows(false);
            }
            if let Err(e) = self.sys.matrix.solve(&mut self.delta) {
                return Err(self.failure(h, FailureReason::Singular(e.to_string()), history, fref));
            }
            if turned {
                self.turn_translation_rows(true);
            }
            let (mut inc_x, mut inc_r) = (0.0f64, 0.0f64);
            for (i, d) in self.sys.node_dofs.iter().enumerate() {
                for c in 0..6 {
                    if d[c] != crate::solver::system::FIXED {
                        let v = -self.delta[d[c]];
                        if c < 3 {
                            self.u[i][0][c] += v;
                            inc_x = nan_max(inc_x, v.abs());
                        } else {
                            self.u[i][1][c - 3] += v;
                            inc_r = nan_max(inc_r, v.abs());
                        }
                    }
                }
            }
            for k in nn..self.sys.n_eq() {
                self.trial_lambda[k] -= self.delta[k];
            }
            prev_inc = last_inc;
            last_inc = (inc_x / self.sys.ref_length).max(inc_r);
            if !last_inc.is_finite() {
                return Err(self.failure(h, FailureReason::NotFinite, history, fref));
            }
        }
        Err(self.failure(
            h,
            FailureReason::NoConvergence(self.newton.max_iterations),
            history,
            fref,
        ))
    }

    /// The end of a converged step: the energy guard, the local error (adaptive steps) and
    /// the elements' step limits may still refuse it; else the trial state is accepted.
    pub(super) fn finish_step(
        &mut self,
        h: f64,
        ctx: &EvalContext,
        iter: u32,
        rel: f64,
        mut history: Vec<f64>,
        fref: f64,
    ) -> Result<StepInfo, Failure> {
        let ctx = *ctx;
        // Event control before committing: an element may refuse the step (before the
        // energy guard, which reads whether the step crosses an event it could not land on).
        let mut next_cap = None;
        if self.dynamic {
            let (next, kept) = self.event_control(h, h, &ctx, history, fref)?;
            history = kept;
            next_cap = Some(next);
        }
        // The rotations as they will be accepted (re-orthonormalized), before the guard
        // measures the state: its measure is kept for the next step, and a restart measures
        // the accepted state afresh — both must see the same bits (tests/cli_io/restart.rs).
        for t in &mut self.trial {
            t.r = crate::rotation::orthonormalize(&t.r);
        }
        // A converged state must not hold energy the step (or the run of steps it ends)
        // cannot pay for.
        let passed = if self.dynamic {
            match self.guard(h, &ctx, fref) {
                Ok(p) => Some(p),
                Err(j) => {
                    self.guard_cache = None;
                    return Err(self.failure(
                        h,
                        FailureReason::EnergyJump(Box::new(j)),
                        history,
                        fref,
                    ));
                }
            }
        } else {
            None
        };
        if self.dynamic
            && let Some(a) = self.adaptive.clone()
        {
            // Local error control before committing (Zienkiewicz & Xie 1991).
            let err = self.local_error(h, &a, &ctx);
            let factor = 0.9 * err.max(1e-12).powf(-self.error_exponent());
            if err > 1.0 && h > self.event_floor * (1.0 + crate::solver::FLOOR_SLACK) {
                let retry = (h * factor.max(0.2)).max(self.event_floor);
                return Err(self.failure(h, FailureReason::StepRefused(retry), history, fref));
            }
            self.error_next = h * factor.min(a.max_growth);
        }
        if let Some(next) = next_cap {
            self.step_cap = next;
        }
        self.accept(h, &ctx);
        if let Some(p) = passed {
            self.balance = p.record();
        }
        self.history = history;
        self.stats.newton_iterations += iter as u64;
        Ok(StepInfo {
            iterations: iter,
            residual: rel,
        })
    }

    /// The elements' event control (a contact's touch, release, impact resolution:
    /// `Element::step_limit`) from the accepted state to the trial one, over `len` (the
    /// step's length `h`, or an inner stage's `c_i h`). A refusal refuses the step, to retry
    /// at the length asked; at the smallest step a landing refusal is waived (the event is
    /// timed within the step) and one that cannot resolve the event at all stops the run,
    /// diagnosed (it would integrate an impact in too few steps, which can create energy
    /// no work paid for). Returns the cap of the next step and the Newton history.
    pub(super) fn event_control(
        &mut self,
        h: f64,
        len: f64,
        ctx: &EvalContext,
        history: Vec<f64>,
        fref: f64,
    ) -> Result<(f64, Vec<f64>), Failure> {
        let sub = EvalContext { h: len, ..*ctx };
        let (old, new) = (&self.nodes, &self.trial);
        let (mut next, mut refuse) = (f64::INFINITY, None::<f64>);
        let mut unresolved = None::<(f64, crate::model::ElementId)>;
        for e in self.sys.elements.iter() {
            let Some(lim) = e.step_limit(&sub, old, new) else {
                continue;
            };
            next = next.min(lim.next);
            if len > lim.accept_up_to {
                refuse = Some(refuse.map_or(lim.retry, |r| r.min(lim.retry)));
                if lim.unresolved && unresolved.is_none() {
                    unresolved = Some((lim.retry, e.id()));
                }
            }
        }
        if let Some(retry) =
            refuse.filter(|_| h > self.event_floor * (1.0 + crate::solver::FLOOR_SLACK))
        {
            let retry = retry.max(self.event_floor).min(0.999 * h);
            return Err(self.failure(h, FailureReason::StepRefused(retry), history, fref));
        }
        // A landing refusal waived at the smallest step: the step crosses the event.
        self.straddled = refuse.is_some();
        if let Some((asks, element)) = unresolved {
            let why = FailureReason::EventUnresolved { element, asks };
            return Err(self.failure(h, why, history, fref));
        }
        Ok((next, history))
    }
}

/// How the trial state follows Newton's increment `u`: HHT's update formulas, or those
/// of an implicit stage of the ESDIRK scheme ([`super::esdirk`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kinematics {
    Hht,
    Stage,
}
