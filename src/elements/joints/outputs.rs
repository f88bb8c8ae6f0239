//! What a joint reports: reactions from the multipliers, relative angles counted across
//! ±π, and the universal joint's singularity watch.

use super::*;

impl Joint {
    /// `(F, M)`: reaction force and moment (about the joint point, global) exerted on node
    /// `b` of each pair, from the multipliers (`μ = s λ̂ + p Φ`).
    pub fn reactions(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
    ) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        (0..self.pairs.len())
            .map(|k| self.reaction(k, ctx, nodes, lambda))
            .collect()
    }

    /// The reaction of pair `k` (see [`Self::reactions`]).
    pub(super) fn reaction(
        &self,
        k: usize,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
    ) -> (Vector3<f64>, Vector3<f64>) {
        let m = self.m_pair();
        let pair = &self.pairs[k];
        let (s1, s2) = (&nodes[self.nodes[pair.a]], &nodes[self.nodes[pair.b]]);
        let lam = lambda.get(k * m..(k + 1) * m).unwrap_or(&[]);
        let (_, g) = self.forces_f64(pair, s1, s2, ctx, lam);
        let f = -Vector3::new(g[6], g[7], g[8]);
        let mom = s2.r * -Vector3::new(g[9], g[10], g[11]) - (s2.r * pair.c2).cross(&f);
        (f, mom)
    }

    /// Joint angles: HINGE relative angle in (−π, π]; UJOINT `(θ₁, θ₂, cos bend)`.
    pub(super) fn raw_angles(&self, nodes: &[NodeState]) -> [f64; 3] {
        let (s1, s2) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let q = s1.r.transpose() * s2.r;
        match &self.kind {
            JointType::Hinge { p, q: qq, .. } => {
                let rp = q * p;
                [qq.dot(&rp).atan2(p.dot(&rp)), 0.0, 0.0]
            }
            JointType::UJoint { a1, a2, b } => {
                let qa2 = q * a2;
                let qta1 = q.transpose() * a1;
                let t1 = b.dot(&qa2).atan2(a2.dot(&qa2));
                let t2 = b.dot(&qta1).atan2(a1.dot(&qta1));
                [t1, t2, b.dot(&(q * b))]
            }
            _ => [0.0; 3],
        }
    }

    /// Angles unwrapped against the last committed ones.
    pub(super) fn angles(&self, nodes: &[NodeState]) -> [f64; 3] {
        let r = self.raw_angles(nodes);
        let a = &self.hist.angles;
        [a[0] + wrap(r[0] - a[0]), a[1] + wrap(r[1] - a[1]), r[2]]
    }

    /// [`Self::angles`] at time `t`: a driven hinge's angle is unwrapped against its law
    /// `a f(t)` instead (exact whatever the angle turned in one step).
    pub(super) fn angles_at(&self, t: f64, nodes: &[NodeState]) -> [f64; 3] {
        let mut a = self.angles(nodes);
        if let (JointType::Hinge { .. }, Some([law, _, _])) = (&self.kind, self.drive_law(t)) {
            a[0] = self.driven_angle(self.raw_angles(nodes)[0], law);
        }
        a
    }

    /// The diagnosis of a universal joint near its singular configuration (bend within
    /// `acos(UJOINT_SINGULAR_COS)` of 90°) at this state, or `None`.
    pub fn singularity(&self, nodes: &[NodeState]) -> Option<String> {
        if !matches!(self.kind, JointType::UJoint { .. }) {
            return None;
        }
        let [t1, t2, cb] = self.raw_angles(nodes);
        (cb.abs() < UJOINT_SINGULAR_COS).then(|| {
            format!(
                "{} (UJOINT) is at its singular configuration: the shafts are perpendicular (bend {:.2}°, \
                 joint angles {:.2}°, {:.2}°); the joint cannot transmit a torque about the shaft axes \
                 and a driveline through it loses a degree of freedom",
                self.id,
                cb.clamp(-1.0, 1.0).acos().to_degrees(),
                t1.to_degrees(),
                t2.to_degrees()
            )
        })
    }
}
