//! A driven joint (`HINGE … DRIVE f`, `PRISMATIC … DRIVE f`): the sixth equation
//! `Φ₆ = g(q) − a f(t)` and its gradient, generic in the scalar (model/drive.rs).
//!
//! - `HINGE` (axis `a`, normals `p`, `q = a × p`): `g = θ`, the angle of node 2 relative to
//!   node 1 about the axis. With `Q = R₁ᵀR₂` and `u = Qp`, `θ = atan2(q·u, p·u)` (exact when
//!   the hinge's other equations hold: `Q = exp(θã)`, `u = cos θ p + sin θ q`). The driver's
//!   row is `Φ₆ = θ − a f(t) − 2πk`, `k` the nearest whole number of turns (a constant:
//!   the equation is singularity-free for any number of turns, as only `θ − a f` modulo
//!   2π, the configuration, is constrained). Variations (`δQ = −δΘ̃₁Q + QδΘ̃₂`):
//!   `δu = −δΘ₁ × u + Q(δΘ₂ × p)`, `δθ = w·δu` with `w = ((p·u) q − (q·u) p)/|u_⊥|²`, so
//!   `Bᵀμ₆ = μ₆ (0, w × u, 0, p × Qᵀw)`.
//! - `PRISMATIC` (axis `a`): `g = σ = (R₁a)·d`, the travel; its gradient is that of the
//!   joint's `(R₁u)·d` rows with `u = a` (joints/constraints.rs).
//!
//! The driving torque (force) is `τ = −μ₆`, what the driver applies to node 2's body about
//! (along) the axis, relative to node 1: its power `τ a ḟ` enters the energy balance.

use super::*;
use std::f64::consts::TAU;

impl Joint {
    /// Adds a driver to a HINGE or PRISMATIC (an error for other joints).
    pub fn with_drive(mut self, law: crate::elements::drive::TimeLaw) -> Result<Self, BuildError> {
        if !matches!(
            self.kind,
            JointType::Hinge { .. } | JointType::Prismatic { .. }
        ) {
            return Err(BuildError::Invalid {
                element: self.id,
                message: format!("a {} cannot be driven", self.kind.keyword()),
            });
        }
        self.drive = Some(law);
        Ok(self)
    }

    /// What `g(q)` must equal at time `t` at the nodes' state: `a f(t)`, plus, for a
    /// hinge, the whole turns `2πk` that bring it nearest to the angle `atan2` measures.
    pub(super) fn drive_target(&self, s1: &NodeState, s2: &NodeState, t: f64) -> f64 {
        let Some(d) = &self.drive else { return 0.0 };
        let law = d.value(t);
        match &self.kind {
            JointType::Hinge { .. } => {
                let th = self.drive_g(&s1.x, &s1.r, &s2.x, &s2.r, &self.pairs[0].c2);
                law + ((th - law) / TAU).round() * TAU
            }
            _ => law,
        }
    }

    /// `g(q)`: the hinge's `atan2` angle in (−π, π], the prismatic's travel.
    pub(super) fn drive_g<S: Real>(
        &self,
        x1: &Vector3<S>,
        r1: &Matrix3<S>,
        x2: &Vector3<S>,
        r2: &Matrix3<S>,
        c2: &Vector3<f64>,
    ) -> S {
        let v = |w: &Vector3<f64>| -> Vector3<S> { w.map(c) };
        match &self.kind {
            JointType::Hinge { p, q, .. } => {
                let u = mtv(r1, &mv(r2, &v(p)));
                dot(&v(q), &u).atan2(dot(&v(p), &u))
            }
            JointType::Prismatic { a, .. } => {
                let d = x2 + mv(r2, &v(c2)) - x1;
                dot(&mv(r1, &v(a)), &d)
            }
            _ => S::zero(),
        }
    }

    /// `μ₆ Bᵀ` of the driver row: `(Θ₁, Θ₂, d)` parts (the `d` part, global, as the
    /// multiplier of `d` it adds to).
    pub(super) fn drive_grad<S: Real>(
        &self,
        x1: &Vector3<S>,
        r1: &Matrix3<S>,
        x2: &Vector3<S>,
        r2: &Matrix3<S>,
        c2: &Vector3<S>,
        mu: S,
    ) -> (Vector3<S>, Vector3<S>, Vector3<S>) {
        let v = |w: &Vector3<f64>| -> Vector3<S> { w.map(c) };
        let zero = Vector3::<S>::zeros();
        match &self.kind {
            JointType::Hinge { p, q, .. } => {
                let (p, q) = (v(p), v(q));
                let qm = mtm(r1, r2);
                let u = mv(&qm, &p);
                let (x, y) = (dot(&p, &u), dot(&q, &u));
                let w = (q * x - p * y) * (mu / (x * x + y * y));
                (w.cross(&u), p.cross(&mtv(&qm, &w)), zero)
            }
            JointType::Prismatic { a, .. } => {
                let a = v(a);
                let d = x2 + mv(r2, c2) - x1;
                ((a * mu).cross(&mtv(r1, &d)), zero, mv(r1, &a) * mu)
            }
            _ => (zero, zero, zero),
        }
    }

    /// The driver's multiplier `μ₆ = sλ̂₆ + pΦ₆` at the state (0 without a driver).
    pub(super) fn drive_mu(&self, ctx: &EvalContext, nodes: &[NodeState], lambda: &[f64]) -> f64 {
        let Some(d) = &self.drive else { return 0.0 };
        let pair = &self.pairs[0];
        let (s1, s2) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let _ = d;
        let target = self.drive_target(s1, s2, ctx.t);
        let phi = self.drive_g(&s1.x, &s1.r, &s2.x, &s2.r, &pair.c2) - target;
        ctx.constraint_scale * lambda.get(5).copied().unwrap_or(0.0) + ctx.penalty * phi
    }

    /// `[a f, a ḟ, a f̈]` of the driver, if any.
    pub fn drive_law(&self, t: f64) -> Option<[f64; 3]> {
        self.drive.as_ref().map(|d| d.at(t))
    }

    /// The hinge angle unwrapped against the driver's law (exact for any step).
    pub(super) fn driven_angle(&self, raw: f64, law: f64) -> f64 {
        law + wrap(raw - law)
    }
}
