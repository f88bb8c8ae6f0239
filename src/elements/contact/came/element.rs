//! The [`Element`] interface of the CAME: residual and exact tangent (dual numbers),
//! energies, commits of the contact history, checkpoints and output rows.

use super::{Came, CameState, ContactState, D12};
use crate::elements::{
    Element, ElementState, Energies, EvalContext, Local, NodeState, StateMismatch, StepLimit,
};
use crate::model::ElementId;
use nalgebra::{Matrix3, Vector2, Vector3};
use num_dual::Derivative;
use std::sync::atomic::Ordering;

impl Element for Came {
    fn id(&self) -> ElementId {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    /// The surface turns with its node, so its node's rotation always counts once in
    /// contact. The roller's node: its rotation carries the roller's offset, and with a
    /// radius and friction the friction's moment and the contact point's velocity; a
    /// centred point (no offset, and no radius or no friction) leaves it untouched.
    fn rotation_use(&self, k: usize) -> crate::elements::RotationUse {
        use crate::elements::RotationUse;
        if k == self.s || self.o_p != Vector3::zeros() || (self.rho > 0.0 && self.mu > 0.0) {
            RotationUse::Always
        } else {
            RotationUse::Never
        }
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
        out.add_dual12(&st.res);
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
        let (attempt, flips, last_flag) = self.memory.save();
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
            attempt,
            flips,
            last_flag,
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
        self.memory.restore((s.attempt, s.flips, s.last_flag));
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
    fn intermittent(&self) -> bool {
        true
    }

    fn step_limit(
        &self,
        ctx: &EvalContext,
        old: &[NodeState],
        new: &[NodeState],
    ) -> Option<StepLimit> {
        self.event_limit(ctx, old, new)
    }
}

impl Came {
    pub(super) fn row(
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
}
