//! One step of the α family (HHT, generalized-α) on the Lie group: the trial state from Newton's increment `u`, the tangent
//! maps of the rotational increments, and the acceptance of a converged step.

use super::*;

impl Integrator {
    /// Trial state from the increment `u` (the update formulas of the module's doc):
    /// `a_{n+1} = (u/h² − v_n/h − (½ − β) a_n)/β`, `v_{n+1} = v_n + h((1 − γ) a_n + γ a_{n+1})`,
    /// `v̇_{n+1} = ((1 − α_m) a_{n+1} + α_m a_n − α_f v̇_n)/(1 − α_f)`.
    pub(super) fn trial_from_u(&mut self, h: f64) {
        let p = self.params;
        for i in 0..self.nodes.len() {
            let s0 = &self.nodes[i];
            let [u_x, u_r] = self.u[i];
            let t = &mut self.trial[i];
            t.x = s0.x + u_x;
            t.r = s0.r * rotation::exp(&u_r);
            if self.dynamic {
                let [a0x, a0r] = self.pseudo[i];
                let ax = (u_x / (h * h) - s0.v / h - a0x * (0.5 - p.beta)) / p.beta;
                let ar = (u_r / (h * h) - s0.w / h - a0r * (0.5 - p.beta)) / p.beta;
                self.trial_pseudo[i] = [ax, ar];
                t.v = s0.v + (a0x * (1.0 - p.gamma) + ax * p.gamma) * h;
                t.w = s0.w + (a0r * (1.0 - p.gamma) + ar * p.gamma) * h;
                let (m1, m0) = (1.0 - p.alpha_m, p.alpha_m);
                t.a = (ax * m1 + a0x * m0 - s0.a * p.alpha_f) / (1.0 - p.alpha_f);
                t.wd = (ar * m1 + a0r * m0 - s0.wd * p.alpha_f) / (1.0 - p.alpha_f);
            }
        }
    }

    /// Tangent maps `T(u)` of the rotational increments, for the iteration matrix.
    pub(super) fn update_tangent_maps(&mut self) {
        for (t, [_, u_r]) in self.tmap.iter_mut().zip(&self.u) {
            *t = rotation::tangent(u_r);
        }
    }

    pub(super) fn accept(&mut self, h: f64, ctx: &EvalContext) {
        // The drivers' power counts as external work (its multipliers at their own scale).
        let ctx_old = EvalContext {
            t: self.t,
            constraint_scale: self.scale,
            ..*ctx
        };
        let p_old = if self.dynamic {
            self.sys.external_power(self.t, &self.nodes)
                + self.sys.input_power(&ctx_old, &self.nodes, &self.lambda)
        } else {
            0.0
        };
        let d_old: f64 = if self.dynamic {
            self.sys
                .elements
                .iter()
                .map(|e| e.dissipated_power(&self.nodes))
                .sum()
        } else {
            0.0
        };
        // (The trial's rotations were re-orthonormalized by `finish_step`, before the guard.)
        self.nodes.copy_from_slice(&self.trial);
        if self.dynamic {
            self.pseudo.copy_from_slice(&self.trial_pseudo);
        }
        self.lambda.copy_from_slice(&self.trial_lambda);
        self.scale = ctx.constraint_scale;
        self.t += h;
        if self.dynamic {
            let p_new = self.sys.external_power(self.t, &self.nodes)
                + self.sys.input_power(ctx, &self.nodes, &self.lambda);
            self.external_work += 0.5 * (p_old + p_new) * h;
            let d_new: f64 = self
                .sys
                .elements
                .iter()
                .map(|e| e.dissipated_power(&self.nodes))
                .sum();
            self.damping_work += 0.5 * (d_old + d_new) * h;
        }
        for (e, el) in self.sys.elements.iter_mut().enumerate() {
            let k = el.multipliers();
            let o = self.sys.mult_offset[e];
            el.commit(ctx, &self.nodes, &self.lambda[o..o + k]);
        }
        self.stats.steps += 1;
        if self.dynamic && self.sys.elements.iter().any(|e| e.restart()) {
            // The same matrix factored at t = 0: if it fails now, the accelerations of
            // the step are kept (a valid start, one order less accurate across the jump).
            if self.consistent_accelerations().is_ok() {
                self.stats.restarts += 1;
            }
        }
    }
}
