//! The joint's kernel, generic in the scalar (f64 for residuals, dual numbers for the
//! exact tangent): eccentricity, penetration and its rate, the force law, friction and the
//! nodal residual.

use super::{Clearance, JointState};
use crate::elements::NodeState;
use crate::elements::profile::c;
use crate::model::ContactLaw;
use nalgebra::{Matrix3, RealField, Vector3};

impl Clearance {
    /// The raw normal force of the law and its elastic part, `(F, F_el)`, at penetration
    /// `δ` and rate `δ̇` (`damped` false: the elastic part alone). Zero elastic force when
    /// `δ ≤ 0` (the Hertz power is not defined there).
    pub(super) fn law_force<S: RealField + Copy>(&self, pen: S, rate: S, damped: bool) -> (S, S) {
        match self.law {
            ContactLaw::KelvinVoigt { k, c: cc } => {
                let el = c::<S>(k) * pen;
                let damp = if damped { c::<S>(cc) * rate } else { S::zero() };
                (el + damp, el)
            }
            ContactLaw::LankaraniNikravesh {
                k,
                exponent,
                restitution,
            } => {
                if pen <= S::zero() {
                    return (S::zero(), S::zero());
                }
                let el = c::<S>(k) * pen.powf(c::<S>(exponent));
                if !damped {
                    return (el, el);
                }
                // Lankarani & Nikravesh (1990) eq. 23: D = 3(1 − e²)/4.
                let d = 0.75 * (1.0 - restitution * restitution);
                (el * (S::one() + c::<S>(d / self.approach) * rate), el)
            }
        }
    }

    /// The kernel at the element's two node states (f64).
    pub(super) fn kernel_at(
        &self,
        nodes: &[NodeState],
        force_on: bool,
        damped: bool,
    ) -> JointState<f64> {
        let (b, j) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        self.kernel(
            [b.x, j.x],
            [b.r, j.r],
            [b.v, j.v],
            [b.w, j.w],
            force_on,
            damped,
        )
    }

    /// The kernel: `[bearing, journal]` positions, orientations, velocities and material
    /// angular velocities. `force_on` false gives zero forces.
    pub(super) fn kernel<S: RealField + Copy>(
        &self,
        x: [Vector3<S>; 2],
        r: [Matrix3<S>; 2],
        v: [Vector3<S>; 2],
        w: [Vector3<S>; 2],
        force_on: bool,
        damped: bool,
    ) -> JointState<S> {
        let a = r[0] * self.a0.map(c::<S>);
        let d = x[1] - x[0];
        let ecc = d - a * a.dot(&d);
        let len = ecc.norm();
        // At the exact centre the normal is undefined and the journal far from the wall.
        let normal = if len > S::zero() {
            ecc / len
        } else {
            Vector3::zeros()
        };
        let pen = len - c::<S>(self.c);
        let (wb, wj) = (r[0] * w[0], r[1] * w[1]);
        let pen_rate = normal.dot(&(v[1] - v[0] - wb.cross(&d)));
        let (force, elastic) = self.law_force(pen, pen_rate, damped);
        // Contact point on the journal and the circumferential slip of the material
        // points there.
        let arm_j = normal * c::<S>(self.r_j);
        let arm_b = d + arm_j;
        let vrel = v[1] + wj.cross(&arm_j) - v[0] - wb.cross(&arm_b);
        let slip = vrel - normal * normal.dot(&vrel) - a * a.dot(&vrel);
        let zero = Vector3::zeros();
        let mut res = [zero; 4];
        let mut friction = zero;
        if force_on {
            if self.mu > 0.0 {
                let reg = (slip.dot(&slip) + c::<S>(self.vreg * self.vreg)).sqrt();
                friction = slip * (-(c::<S>(self.mu) * force.abs()) / reg);
            }
            // Forces on the journal: −F n through its centre, friction at p. The residual
            // is minus the force on each body; the bearing takes the opposite forces on
            // the same lines (moments about x_b through x_j and p).
            let f_j = friction - normal * force;
            let m_b = d.cross(&(normal * force)) - arm_b.cross(&friction);
            res[0] = f_j;
            res[1] = -(r[0].transpose() * m_b);
            res[2] = -f_j;
            res[3] = -(r[1].transpose() * arm_j.cross(&friction));
        }
        JointState {
            ecc,
            pen,
            pen_rate,
            force,
            elastic,
            normal,
            slip,
            friction,
            res,
        }
    }

    /// The joint's state at `nodes` (f64) with the law of the step that starts from the
    /// committed state (damped when touching).
    pub fn state(&self, nodes: &[NodeState]) -> JointState<f64> {
        self.kernel_at(nodes, false, self.touching)
    }

    /// Relative acceleration of the journal centre along `n` (the bearing's rotation and
    /// the curvature of the path neglected): `m_eff = F / this`.
    pub(super) fn normal_acceleration(&self, nodes: &[NodeState], n: &Vector3<f64>) -> f64 {
        let (b, j) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        n.dot(&(j.a - b.a))
    }

    /// Second time derivative of `|e|` in free flight: the normal acceleration plus the
    /// curvature term `|ė_t|²/|e|` of a path that crosses the circle.
    pub(super) fn pen_acceleration(&self, nodes: &[NodeState], st: &JointState<f64>) -> f64 {
        let (b, j) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let a = b.r * self.a0;
        let d = j.x - b.x;
        let rel = j.v - b.v - (b.r * b.w).cross(&d);
        let tang = rel - st.normal * st.normal.dot(&rel) - a * a.dot(&rel);
        let len = st.ecc.norm();
        let curv = if len > 0.0 {
            tang.norm_squared() / len
        } else {
            0.0
        };
        self.normal_acceleration(nodes, &st.normal) + curv
    }
}
