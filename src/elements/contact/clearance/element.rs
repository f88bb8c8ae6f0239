//! The [`Element`] interface of the clearance joint: residual and exact tangent (dual
//! numbers), energies, commits of the contact history, checkpoints and output rows.

use super::{Clearance, ClearanceState};
use crate::elements::came::LIMIT_SLACK;
use crate::elements::{
    Element, ElementState, Energies, EvalContext, Local, NodeState, StateMismatch, StepLimit,
};
use crate::model::ElementId;
use nalgebra::{Const, Matrix3, U1, Vector3};
use num_dual::{Derivative, DualSVec64};
use std::sync::atomic::Ordering;

type D12 = DualSVec64<12>;

impl Element for Clearance {
    fn id(&self) -> ElementId {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    /// The bearing's axis turns with its node (always counts); the journal's rotation
    /// enters only through friction (the moment of the friction force at its radius and
    /// the surface's slip velocity).
    fn rotation_use(&self, k: usize) -> crate::elements::RotationUse {
        use crate::elements::RotationUse;
        if k == 0 || self.mu > 0.0 {
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
        let damped = self.touching;
        let st = self.kernel_at(nodes, false, damped);
        let active = self.memory.flag(ctx, self.closed(&st));
        if !(active && st.force > 0.0) {
            return;
        }
        if !tangent {
            let st = self.kernel_at(nodes, true, damped);
            for (blk, v) in st.res.iter().enumerate() {
                out.add_res(3 * blk, v);
            }
            return;
        }
        // Forward mode in the 12 directions [δx_b, δΘ_b, δx_j, δΘ_j]: positions seeded by
        // 1, velocities by c_v, orientations by R (I + δΘ̃).
        let seed = |k: usize| D12::new(0.0, Derivative::derivative_generic(Const::<12>, U1, k));
        let lift = |v: f64| D12::new(v, Derivative::none());
        let cv = lift(ctx.c_v);
        let xs =
            |x: &Vector3<f64>, base: usize| Vector3::from_fn(|i, _| lift(x[i]) + seed(base + i));
        let vs = |x: &Vector3<f64>, base: usize| {
            Vector3::from_fn(|i, _| lift(x[i]) + seed(base + i) * cv)
        };
        let rs = |r: &Matrix3<f64>, base: usize| {
            let t = Vector3::new(seed(base), seed(base + 1), seed(base + 2));
            let rr: Matrix3<D12> = r.map(lift);
            rr + rr * t.cross_matrix()
        };
        let (b, j) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let st = self.kernel(
            [xs(&b.x, 0), xs(&j.x, 6)],
            [rs(&b.r, 3), rs(&j.r, 9)],
            [vs(&b.v, 0), vs(&j.v, 6)],
            [vs(&b.w, 3), vs(&j.w, 9)],
            true,
            damped,
        );
        out.add_dual12(&st.res);
    }

    fn energies(&self, nodes: &[NodeState], _gravity: &Vector3<f64>) -> Energies {
        Energies {
            strain: self.contact_energy(self.state(nodes).pen),
            ..Energies::default()
        }
    }

    fn commit(&mut self, ctx: &EvalContext, nodes: &[NodeState], _lambda: &[f64]) {
        // Dissipation over the step (trapezoidal), with the law the step used.
        let power = self.power(&self.state(nodes));
        self.dissipated += 0.5 * (self.last_power + power) * ctx.h;
        // Touch event: a state within the landing tolerance of the wall and approaching
        // it is *at* the event; from there the full law acts, with the approach speed of
        // this impact, and the integrator restarts its accelerations.
        let was = self.touching;
        let full = self.kernel_at(nodes, false, true);
        if ctx.dynamic {
            let tol = self.touch_tolerance(ctx.h, full.pen_rate);
            self.touching = full.pen > 0.0 || (-full.pen <= tol && full.pen_rate > 0.0);
            self.touch_tol = if self.touching { tol } else { 0.0 };
        } else {
            self.touching = full.pen > 0.0;
            self.touch_tol = 0.0;
        }
        if self.touching && !was {
            self.approach = full.pen_rate.max(self.vmin);
        }
        self.restart = ctx.dynamic && self.touching != was;
        let st = self.state(nodes);
        let f = self.applied(&st);
        let active = f > 0.0;
        if active && !self.active {
            self.impacts += 1;
        }
        self.active = active;
        self.max_force = self.max_force.max(f);
        if st.pen > 0.0 {
            self.max_penetration = self.max_penetration.max(st.pen);
            if let Some(w) = self.omega_estimate(nodes, &st) {
                self.omega = w;
            }
        }
        if ctx.dynamic && was && self.touching && ctx.h > LIMIT_SLACK * self.impact_step(self.omega)
        {
            self.unresolved += 1;
        }
        self.last_power = if self.restart && self.touching {
            self.power(&st)
        } else {
            power
        };
    }

    fn restart(&self) -> bool {
        self.restart
    }

    fn save_state(&self) -> ElementState {
        ElementState::Clearance(ClearanceState {
            touching: self.touching,
            touch_tol: self.touch_tol,
            restart: self.restart,
            active: self.active,
            approach: self.approach,
            impacts: self.impacts,
            unresolved: self.unresolved,
            max_penetration: self.max_penetration,
            max_force: self.max_force,
            dissipated: self.dissipated,
            last_power: self.last_power,
            omega: self.omega,
            omega_trial: self.omega_trial.load(Ordering::Relaxed),
            memory: self.memory.save(),
        })
    }

    fn restore_state(&mut self, state: &ElementState) -> Result<(), StateMismatch> {
        let ElementState::Clearance(s) = state else {
            return Err(StateMismatch { element: self.id });
        };
        self.touching = s.touching;
        self.touch_tol = s.touch_tol;
        self.restart = s.restart;
        self.active = s.active;
        self.approach = s.approach;
        self.impacts = s.impacts;
        self.unresolved = s.unresolved;
        self.max_penetration = s.max_penetration;
        self.max_force = s.max_force;
        self.dissipated = s.dissipated;
        self.last_power = s.last_power;
        self.omega = s.omega;
        self.omega_trial.store(s.omega_trial, Ordering::Relaxed);
        self.memory.restore(s.memory);
        Ok(())
    }

    fn output_header(&self) -> Vec<String> {
        [
            "active",
            "eccentricity",
            "ex",
            "ey",
            "ez",
            "penetration",
            "penetration_rate",
            "normal_force",
            "friction_force",
            "approach_speed",
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
        let st = self.state(nodes);
        let f = self.applied(&st);
        let ft = if self.mu > 0.0 && f > 0.0 {
            let s2 = st.slip.norm_squared();
            self.mu * f * s2.sqrt() / (s2 + self.vreg * self.vreg).sqrt()
        } else {
            0.0
        };
        // The eccentricity in the bearing's material frame (its orbit in the bearing).
        let e = nodes[self.nodes[0]].r.transpose() * st.ecc;
        row.extend_from_slice(&[
            if f > 0.0 { 1.0 } else { 0.0 },
            st.ecc.norm(),
            e.x,
            e.y,
            e.z,
            st.pen,
            st.pen_rate,
            f,
            ft,
            self.approach,
        ]);
    }

    fn summary(&self) -> Option<serde_json::Value> {
        Some(serde_json::json!({
            "impacts": self.impacts,
            "unresolved_steps": self.unresolved,
            "max_penetration": self.max_penetration,
            "max_normal_force": self.max_force,
            "dissipated_energy": self.dissipated,
        }))
    }

    fn dissipated_power(&self, nodes: &[NodeState]) -> f64 {
        self.power(&self.state(nodes))
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
