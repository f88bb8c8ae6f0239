//! `RSPRING`: a rotational spring, damper and regularised Coulomb friction about the axis
//! of a `HINGE`, between the hinge's two nodes (issue 25 §3). The hinge keeps its own
//! constraints; this element adds only the torque.
//!
//! # Angle
//! With `(p, q, a)` the orthonormal triad on the hinge axis `a` (material frames = global at
//! t = 0), `Q = R₁ᵀR₂` and `u = Q p`, the relative angle is
//! `θ = atan2(q·u, p·u) + 2πn`, the whole turns `n` counted from step to step (the angle
//! nearest the last accepted one), so a flywheel may turn any number of times. On the
//! hinge's motions `Q = exp(θ ã)`; off them (Newton's iterates) `θ` is still defined as
//! long as `Q p` is not parallel to `a`.
//!
//! Its variation (material spins): with `w = ((p·u) q − (q·u) p)/((p·u)² + (q·u)²)`,
//! `δθ = (w × u)·δΘ₁ + (p × Qᵀw)·δΘ₂ = g·δΘ` (`g = (−a, a)` on the hinge's motions), and
//! `θ̇ = g·(Ω₁, Ω₂)`.
//!
//! # Torque
//! `T = k (θ − θ₀) + c θ̇ + T_f tanh(θ̇/ω_reg)`: the spring, the viscous damper and Coulomb
//! friction `T_f sign(θ̇)` regularised by `tanh` (smooth, slope `T_f/ω_reg` at rest; the
//! friction torque is within `2 e^{−2|θ̇|/ω_reg}` of `T_f` once `|θ̇| ≫ ω_reg`). The element's
//! residual is `T g` on the rotations; the torque on node 2 about the axis is `−T`.
//! Friction and damping dissipate: their power `c θ̇² + T_f θ̇ tanh(θ̇/ω_reg) ≥ 0`. Strain
//! energy `½ k (θ − θ₀)²`.
//!
//! # Tangent (exact)
//! `∂(T g)/∂q = T ∂g/∂q + g ⊗ (k g + T_θ̇ (∂g/∂q)ᵀΩ)`, `∂(T g)/∂Ω = T_θ̇ g ⊗ g`, with
//! `T_θ̇ = c + (T_f/ω_reg)(1 − tanh²(θ̇/ω_reg))` and `∂g/∂q` by dual numbers ([`Dual<6>`]
//! seeding `Rᵢ(I + ε̃)`).

use crate::dual::{Dual, Real};
use crate::elements::joints::normals;
use crate::elements::registry::Kind;
use crate::elements::{
    Element, ElementState, Energies, EvalContext, Local, NodeState, StateMismatch, rx,
};
use crate::model::{ElementId, RSpringData};
use crate::rotation::{c, mm, mtm, mtv, mv, skew};
use nalgebra::{Matrix3, Vector3, Vector6};

type D6 = Dual<6>;

/// The element half of `RSPRING` (`crate::kinds`): built by [`super::from_model`].
pub const KIND: Kind = Kind {
    types: &["RSPRING"],
    build: super::from_model,
};

/// An RSPRING element (see the module docs).
#[derive(Debug, Clone)]
pub struct RSpring {
    id: ElementId,
    nodes: [usize; 2],
    p: Vector3<f64>,
    q: Vector3<f64>,
    k: f64,
    c: f64,
    theta0: f64,
    tf: f64,
    wreg: f64,
    /// θ at the last accepted state, whole turns counted.
    angle: f64,
}

/// The angle's state at a configuration.
struct At {
    theta: f64,
    rate: f64,
    g: Vector6<f64>,
    /// Torque `T` and `∂T/∂θ̇`.
    torque: f64,
    dt_drate: f64,
}

fn dot<S: Real>(a: &Vector3<S>, b: &Vector3<S>) -> S {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// Wraps an angle to (−π, π].
fn wrap(x: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let y = x.rem_euclid(t);
    if y > std::f64::consts::PI { y - t } else { y }
}

impl RSpring {
    /// The element on the hinge's dense nodes.
    pub fn new(id: ElementId, nodes: [usize; 2], d: &RSpringData) -> Self {
        let (p, q) = normals(&d.axis);
        RSpring {
            id,
            nodes,
            p,
            q,
            k: d.stiffness,
            c: d.damping,
            theta0: d.angle0,
            tf: d.friction,
            wreg: d.friction_speed,
            angle: 0.0,
        }
    }

    /// `(q·u, p·u, g)` (module docs), generic in the scalar.
    fn grad<S: Real>(&self, r1: &Matrix3<S>, r2: &Matrix3<S>) -> (S, S, [S; 6]) {
        let (p, q) = (self.p.map(c::<S>), self.q.map(c::<S>));
        let qm = mtm(r1, r2);
        let u = mv(&qm, &p);
        let (s, co) = (dot(&q, &u), dot(&p, &u));
        let n2 = s * s + co * co;
        let w = (q * co - p * s) / n2;
        let g1 = mv(&skew(&w), &u);
        let g2 = mv(&skew(&p), &mtv(&qm, &w));
        (s, co, [g1.x, g1.y, g1.z, g2.x, g2.y, g2.z])
    }

    /// Whether `Q p` is (nearly) parallel to the axis: no angle.
    fn degenerate(s: f64, co: f64) -> bool {
        let n2 = s * s + co * co;
        n2.is_nan() || n2 <= 1e-12
    }

    fn at(&self, nodes: &[NodeState]) -> Option<At> {
        let (a, b) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let (s, co, g) = self.grad(&a.r, &b.r);
        if Self::degenerate(s, co) {
            return None;
        }
        let g = Vector6::from_column_slice(&g);
        let theta = self.angle + wrap(s.atan2(co) - self.angle);
        let om = Vector6::new(a.w.x, a.w.y, a.w.z, b.w.x, b.w.y, b.w.z);
        let rate = g.dot(&om);
        let th = if self.tf > 0.0 {
            (rate / self.wreg).tanh()
        } else {
            0.0
        };
        Some(At {
            theta,
            rate,
            g,
            torque: self.k * (theta - self.theta0) + self.c * rate + self.tf * th,
            dt_drate: self.c
                + if self.tf > 0.0 {
                    self.tf / self.wreg * (1.0 - th * th)
                } else {
                    0.0
                },
        })
    }
}

impl Element for RSpring {
    fn id(&self) -> ElementId {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        let Some(s) = self.at(nodes) else {
            // No angle: refuse the state, never a NaN (the hinge is torn apart).
            out.add_res(rx(1), &Vector3::repeat(f64::INFINITY));
            return;
        };
        let f = s.g * s.torque;
        out.add_res(rx(0), &f.fixed_rows::<3>(0).into());
        out.add_res(rx(1), &f.fixed_rows::<3>(3).into());
        if !tangent {
            return;
        }
        let (a, b) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let rot = |r: &Matrix3<f64>, base: usize| {
            let rr: Matrix3<D6> = r.map(D6::constant);
            let e = Vector3::new(
                D6::var(0.0, base),
                D6::var(0.0, base + 1),
                D6::var(0.0, base + 2),
            );
            // R (I + δΘ̃): exact to first order, which is all a dual number carries.
            rr + mm(&rr, &skew(&e))
        };
        let (_, _, gd) = self.grad(&rot(&a.r, 0), &rot(&b.r, 3));
        // J[i][j] = ∂g_i/∂Θ_j.
        let jac = nalgebra::Matrix6::from_fn(|i, j| gd[i].eps[j]);
        let om = Vector6::new(a.w.x, a.w.y, a.w.z, b.w.x, b.w.y, b.w.z);
        let row = s.g * self.k + jac.transpose() * om * s.dt_drate;
        let kmat = jac * s.torque + s.g * row.transpose();
        let rate = s.g * s.g.transpose() * (s.dt_drate * ctx.c_v);
        let idx = [rx(0), rx(1)];
        for (bi, &i) in idx.iter().enumerate() {
            for (bj, &j) in idx.iter().enumerate() {
                let blk: Matrix3<f64> = kmat.fixed_view::<3, 3>(3 * bi, 3 * bj).into();
                out.add_block(i, j, &blk);
                if s.dt_drate != 0.0 && ctx.c_v != 0.0 {
                    let rb: Matrix3<f64> = rate.fixed_view::<3, 3>(3 * bi, 3 * bj).into();
                    out.add_rate_block(i, j, &rb);
                }
            }
        }
    }

    fn energies(&self, nodes: &[NodeState], _gravity: &Vector3<f64>) -> Energies {
        let strain = self.at(nodes).map_or(0.0, |s| {
            0.5 * self.k * (s.theta - self.theta0) * (s.theta - self.theta0)
        });
        Energies {
            strain,
            ..Energies::default()
        }
    }

    fn dissipated_power(&self, nodes: &[NodeState]) -> f64 {
        self.at(nodes).map_or(0.0, |s| {
            let fr = if self.tf > 0.0 {
                self.tf * s.rate * (s.rate / self.wreg).tanh()
            } else {
                0.0
            };
            self.c * s.rate * s.rate + fr
        })
    }

    fn force_scale(&self, nodes: &[NodeState], _gravity: &Vector3<f64>) -> f64 {
        self.at(nodes).map_or(0.0, |s| {
            (self.k * (s.theta - self.theta0))
                .abs()
                .max((self.c * s.rate).abs())
                .max(self.tf * (s.rate / self.wreg).tanh().abs())
        })
    }

    fn commit(&mut self, _ctx: &EvalContext, nodes: &[NodeState], _lambda: &[f64]) {
        if let Some(s) = self.at(nodes) {
            self.angle = s.theta;
        }
    }

    fn diagnose(&self, nodes: &[NodeState]) -> Option<String> {
        self.at(nodes).is_none().then(|| {
            format!(
                "{} (RSPRING): the hinge's relative rotation has no angle about its axis (the hinge is torn apart)",
                self.id
            )
        })
    }

    fn output_header(&self) -> Vec<String> {
        [
            "angle",
            "rate",
            "torque",
            "spring_torque",
            "damper_torque",
            "friction_torque",
        ]
        .map(String::from)
        .to_vec()
    }

    fn write_output_row(
        &self,
        _ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        let Some(s) = self.at(nodes) else {
            row.extend([0.0; 6]);
            return;
        };
        let fr = if self.tf > 0.0 {
            self.tf * (s.rate / self.wreg).tanh()
        } else {
            0.0
        };
        row.extend([
            s.theta,
            s.rate,
            s.torque,
            self.k * (s.theta - self.theta0),
            self.c * s.rate,
            fr,
        ]);
    }

    fn save_state(&self) -> ElementState {
        ElementState::RSpring(self.angle)
    }

    fn restore_state(&mut self, state: &ElementState) -> Result<(), StateMismatch> {
        let ElementState::RSpring(a) = state else {
            return Err(StateMismatch { element: self.id });
        };
        self.angle = *a;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::*;
    use crate::rotation;

    fn rspring(tf: f64) -> RSpring {
        let d = RSpringData {
            hinge: ElementId(1),
            axis: Vector3::new(1.0, 2.0, 2.0) / 3.0,
            stiffness: 30.0,
            damping: 0.7,
            angle0: 0.2,
            friction: tf,
            friction_speed: 2.0,
        };
        RSpring::new(ElementId(2), [0, 1], &d)
    }

    /// The iteration matrix against central differences of the residual, off the hinge's
    /// motions too (random rotations of 0.5 rad of each node), with and without friction:
    /// tolerance 1e-6 of the largest entry (central differences, ε = 1e-6: truncation
    /// O(ε²), round-off O(1e-10) relative). The velocities move by `c_v ε` = 2.1e-3 rad/s,
    /// so the friction's tanh adds a truncation of `(c_v ε)²/6` times its third derivative
    /// `~T_f/ω_reg³`, times `c_v`: with ω_reg = 2 rad/s, ~1e-8 of the scale (with
    /// 0.5 rad/s it was 1.5e-6, above the tolerance: the test's own error, not the tangent's).
    #[test]
    fn tangent_matches_finite_differences() {
        for (k, tf) in [0.0, 3.0].into_iter().enumerate() {
            let e = rspring(tf);
            let st = random_states(&[Vector3::zeros(), Vector3::x()], 0.1, 0.5, 7 + k as u64);
            check_tangent(&e, &dyn_ctx(), &st, &[], 1e-6);
            check_objectivity(&e, &dyn_ctx(), &st, 1e-10);
        }
    }

    /// On the hinge's motions (`R₂ = R₁ exp(θ ã)`): the angle is θ, the rate is the
    /// relative angular velocity about the axis, the torques are the closed forms, and
    /// the angle counts whole turns through commits (a flywheel's 3.2 turns).
    #[test]
    fn angle_rate_and_torque_on_hinge_motions() {
        let mut e = rspring(3.0);
        let a = Vector3::new(1.0, 2.0, 2.0) / 3.0;
        let r1 = rotation::exp(&Vector3::new(0.3, -0.4, 1.0));
        let mut st = vec![NodeState::at_rest(Vector3::zeros()); 2];
        st[0].r = r1;
        st[0].w = Vector3::new(0.1, 0.2, -0.3);
        let ctx = dyn_ctx();
        let total = 3.2 * std::f64::consts::TAU;
        let n = 64;
        for i in 1..=n {
            let th = total * i as f64 / n as f64;
            st[1].r = r1 * rotation::exp(&(a * th));
            // Ω₂ = Q^T Ω₁ + θ̇ a with θ̇ = 1.5.
            st[1].w = (rotation::exp(&(a * th))).transpose() * st[0].w + a * 1.5;
            e.commit(&ctx, &st, &[]);
            let row = e.output_row(&ctx, &st, &[]);
            assert!((row[0] - th).abs() < 1e-12, "angle {} vs {th}", row[0]);
            assert!((row[1] - 1.5).abs() < 1e-12, "rate {}", row[1]);
            let t = 30.0 * (th - 0.2) + 0.7 * 1.5 + 3.0 * (1.5f64 / 2.0).tanh();
            assert!(
                (row[2] - t).abs() < 1e-9 * t.abs(),
                "torque {} vs {t}",
                row[2]
            );
        }
        let p = e.dissipated_power(&st);
        let want = 0.7 * 1.5 * 1.5 + 3.0 * 1.5 * (0.75f64).tanh();
        assert!((p - want).abs() < 1e-12 * want);
    }
}
