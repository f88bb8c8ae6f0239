//! Geometry of the contact: the roller centre in the surface's frame, the closest-point
//! projection, and the contact kernel (gap, rate, normal force and friction, nodal residual)
//! generic in the scalar (f64 for residuals, dual numbers for the exact tangent).

use super::{Came, ContactState};
use crate::elements::NodeState;
use crate::elements::profile::{Projection, c};
use nalgebra::{Matrix3, RealField, Vector2, Vector3};

impl Came {
    /// In-plane coordinates of the roller centre in the surface's profile frame (f64).
    pub(super) fn local_point(&self, nodes: &[NodeState]) -> Vector3<f64> {
        let (ss, sp) = (&nodes[self.nodes[self.s]], &nodes[self.nodes[1 - self.s]]);
        let p = sp.x + sp.r * self.o_p;
        self.f_s.transpose() * (ss.r.transpose() * (p - ss.x) - self.o_s)
    }

    /// The parameter of the closest point, or `None` when the bodies are certainly apart.
    pub(super) fn candidate(&self, nodes: &[NodeState]) -> Option<f64> {
        let l = self.local_point(nodes);
        let l2 = Vector2::new(l.x, l.y);
        if self
            .curve
            .quick_distance(&l2)
            .is_some_and(|d| d - self.rho >= 0.0)
        {
            return None;
        }
        Some(self.curve.closest_parameter(&l2))
    }

    /// [`Came::kernel`] in f64 at the element's two node states.
    pub(super) fn kernel_at(
        &self,
        nodes: &[NodeState],
        eta0: f64,
        force_on: bool,
        damped: bool,
    ) -> ContactState<f64> {
        let (a, b) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        self.kernel(
            [a.x, b.x],
            [a.r, b.r],
            [a.v, b.v],
            [a.w, b.w],
            eta0,
            force_on,
            damped,
        )
    }

    /// The contact kernel, generic in the scalar: gap, rate, force and nodal residual
    /// (computed as if in contact with the raw force `P`; `force_on` false gives zero
    /// forces).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn kernel<S: RealField + Copy>(
        &self,
        x: [Vector3<S>; 2],
        r: [Matrix3<S>; 2],
        v: [Vector3<S>; 2],
        w: [Vector3<S>; 2],
        eta0: f64,
        force_on: bool,
        damped: bool,
    ) -> ContactState<S> {
        let (si, pi) = (self.s, 1 - self.s);
        let (xs, rs, vs, ws) = (x[si], r[si], v[si], r[si] * w[si]);
        let (xp, rp, vp, wp) = (x[pi], r[pi], v[pi], r[pi] * w[pi]);
        let o_p: Vector3<S> = self.o_p.map(c);
        let o_s: Vector3<S> = self.o_s.map(c);
        let f_s: Matrix3<S> = self.f_s.map(c);
        let rho = c::<S>(self.rho);
        let arm_p = rp * o_p;
        let p = xp + arm_p;
        let l = f_s.transpose() * (rs.transpose() * (p - xs) - o_s);
        let pr: Projection<S> = self.curve.project(&Vector2::new(l.x, l.y), eta0);
        let n = rs * (f_s * Vector3::new(pr.normal.x, pr.normal.y, S::zero()));
        let gap = pr.normal.dot(&(Vector2::new(l.x, l.y) - pr.point)) - rho;
        let pdot = vp + wp.cross(&arm_p);
        let gap_rate = n.dot(&(pdot - vs - ws.cross(&(p - xs))));
        let c_n = if damped { self.c } else { 0.0 };
        let force = -(c::<S>(self.k) * gap + c::<S>(c_n) * gap_rate);
        let on_surface = p - n * (gap + rho);
        let on_roller = p - n * rho;
        let mid = (on_surface + on_roller) * c::<S>(0.5);
        let vr = vp + wp.cross(&(on_roller - xp)) - vs - ws.cross(&(on_surface - xs));
        let slip = vr - n * n.dot(&vr);
        let zero = Vector3::zeros();
        let mut res = [zero; 4];
        let mut friction = zero;
        if force_on {
            let fn_ = n * force;
            if self.mu > 0.0 {
                let reg = (slip.dot(&slip) + c::<S>(self.vreg * self.vreg)).sqrt();
                friction = slip * (-(c::<S>(self.mu) * force.abs()) / reg);
            }
            let f = fn_ + friction;
            // Roller body: force f; moments of the normal part about x_p through p, of the
            // friction at the midpoint.
            let mp = arm_p.cross(&fn_) + (mid - xp).cross(&friction);
            let ms = (p - xs).cross(&fn_) + (mid - xs).cross(&friction);
            res[2 * pi] = -f;
            res[2 * pi + 1] = -(rp.transpose() * mp);
            res[2 * si] = f;
            res[2 * si + 1] = rs.transpose() * ms;
        }
        ContactState {
            gap,
            gap_rate,
            force,
            normal: n,
            on_surface,
            on_roller,
            eta: pr.eta,
            slip,
            res,
            friction,
        }
    }

    /// The contact state at `nodes` in f64 (`None` when certainly apart), with the force
    /// law of the step that starts from the committed state (see `touching`).
    pub fn state(&self, nodes: &[NodeState]) -> Option<ContactState<f64>> {
        let eta0 = match self.candidate(nodes) {
            Some(e) => e,
            None if self.touching => {
                let l = self.local_point(nodes);
                self.curve.closest_parameter(&Vector2::new(l.x, l.y))
            }
            None => return None,
        };
        Some(self.kernel_at(nodes, eta0, false, self.touching))
    }

    /// The contact state at `nodes` in f64, computed even when the bodies are apart.
    pub fn full_state(&self, nodes: &[NodeState]) -> ContactState<f64> {
        let l = self.local_point(nodes);
        let eta0 = self.curve.closest_parameter(&Vector2::new(l.x, l.y));
        self.kernel_at(nodes, eta0, false, true)
    }

    /// Relative normal acceleration of the roller centre (curvature terms neglected).
    pub(super) fn gap_acceleration(&self, nodes: &[NodeState], n: &Vector3<f64>) -> f64 {
        let (ss, sp) = (&nodes[self.nodes[self.s]], &nodes[self.nodes[1 - self.s]]);
        let ap = sp.a + sp.r * (sp.wd.cross(&self.o_p));
        n.dot(&(ap - ss.a))
    }

    /// Curvilinear coordinate on the roller (ζ = ρ × angle of the roller point in the
    /// roller's profile plane; 0 for a point).
    pub(super) fn roller_coordinate(&self, nodes: &[NodeState], n: &Vector3<f64>) -> f64 {
        if self.rho == 0.0 {
            return 0.0;
        }
        let sp = &nodes[self.nodes[1 - self.s]];
        let d = self.f_p.transpose() * (sp.r.transpose() * (-n));
        self.rho * d.y.atan2(d.x)
    }
}
