//! `PRESCRIBED`: a motion of one node prescribed in time (issue 25 §2; model/drive.rs).
//!
//! # Equations (index 3, with their own multipliers)
//! - `X`, `Y`, `Z` (global axis `i`): `Φ = xᵢ − xᵢ⁰ − a f(t)`, one equation; `B = eᵢ` on
//!   `δx`. The multiplier `μ = sλ̂ + pΦ` is the force the node needs; the driver applies
//!   `F = −μ` along `eᵢ`.
//! - `ROTATION AXIS n` (global unit axis `n`, normals `p`, `q = n × p`): the node's
//!   orientation `R = exp(a f(t) ñ)` (it starts at `R = I`), written as a hinge to the
//!   ground with a driver (joints.rs, joints/drive.rs, with `R₁ = I`):
//!   `Φ = [p·(Rn), q·(Rn), θ − a f(t) − 2πk]`, `θ = atan2(q·Rp, p·Rp)`, `k` the nearest
//!   whole number of turns (singularity-free for any number of turns). Variations
//!   (`δR = R δΘ̃`): `δ(u·Rn) = δΘ·(n × Rᵀu)`, `δθ = δΘ·(p × Rᵀw)` with
//!   `w = ((p·Rp) q − (q·Rp) p)/|(Rp)_⊥|²`. The driving moment about `n` is `−μ₃`.
//!
//! Every equation is `g(q) − a f(t)` with `B` independent of time, so `Φ_t = −a ḟ` and
//! `Φ_tt = −a f̈` on the driven row (elements/drive.rs). The tangent is `[K_g(μ) + pBᵀB,
//! sBᵀ; sB, 0]`, `K_g` by dual numbers on the analytic `Bᵀμ` as for the joints.
//!
//! Outputs (`element_<N>.csv`): `prescribed` (`a f(t)`), `displacement` (`xᵢ − xᵢ⁰`, m) or
//! `angle` (rad, counted past ±π), and the driver's `force` (N) or `moment` (N·m).

use crate::dual::{Dual, Real};
use crate::elements::drive::TimeLaw;
use crate::elements::registry::{Kind, node_index, not_mine};
use crate::elements::{Element, EvalContext, Local, NodeState};
use crate::model::{ElementId, ElementKind, NodeMotion};
use crate::rotation::{c, mm, mtv, mv, skew};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::TAU;

type D3 = Dual<3>;

/// The element half of `PRESCRIBED` (`crate::kinds`).
pub const KIND: Kind = Kind {
    types: &["PRESCRIBED"],
    build: |model, el| {
        let ElementKind::Prescribed { motion, drive } = &el.kind else {
            return Err(not_mine(el, "PRESCRIBED"));
        };
        let i = node_index(model, &el.nodes[0]);
        Ok(Box::new(Prescribed::new(
            el.id,
            i,
            model.nodes[i].position,
            *motion,
            TimeLaw::from_model(model, drive),
        )))
    },
};

/// A prescribed node motion.
#[derive(Debug, Clone)]
pub struct Prescribed {
    id: ElementId,
    nodes: [usize; 1],
    motion: NodeMotion,
    /// The node's position at t = 0.
    x0: Vector3<f64>,
    /// Normals `p`, `q = n × p` of a rotation's axis `n` (unused for a displacement).
    p: Vector3<f64>,
    q: Vector3<f64>,
    law: TimeLaw,
}

/// `a·b`, unrolled.
#[inline(always)]
fn dot<S: Real>(a: &Vector3<S>, b: &Vector3<S>) -> S {
    a.x * b.x + a.y * b.y + a.z * b.z
}

impl Prescribed {
    /// The motion `motion` of dense node `node` (at `x0` at t = 0) following `law`.
    pub fn new(
        id: ElementId,
        node: usize,
        x0: Vector3<f64>,
        motion: NodeMotion,
        law: TimeLaw,
    ) -> Self {
        let (p, q) = match motion {
            NodeMotion::Rotation(n) => super::normals(&n),
            NodeMotion::Displacement(_) => (Vector3::x(), Vector3::y()),
        };
        let motion = match motion {
            NodeMotion::Rotation(n) => NodeMotion::Rotation(n.normalize()),
            m => m,
        };
        Prescribed {
            id,
            nodes: [node],
            motion,
            x0,
            p,
            q,
            law,
        }
    }

    /// The row of the driven equation.
    fn driven_row(&self) -> usize {
        self.motion.equations() - 1
    }

    /// The rotation's angle `θ = atan2(q·Rp, p·Rp)`.
    fn angle<S: Real>(&self, r: &Matrix3<S>) -> S {
        let u = mv(r, &self.p.map(c));
        dot(&self.q.map(c), &u).atan2(dot(&self.p.map(c), &u))
    }

    /// What the driven coordinate must equal at `t`: `a f(t)` (+ whole turns for a
    /// rotation, nearest to the node's angle).
    fn target(&self, s: &NodeState, t: f64) -> f64 {
        let law = self.law.value(t);
        match self.motion {
            NodeMotion::Displacement(_) => law,
            NodeMotion::Rotation(_) => {
                let th = self.angle(&s.r);
                law + ((th - law) / TAU).round() * TAU
            }
        }
    }

    /// `Φ` of a rotation (generic).
    fn phi_rot<S: Real>(&self, n: &Vector3<f64>, r: &Matrix3<S>, target: f64) -> [S; 3] {
        let rn = mv(r, &n.map(c));
        [
            dot(&self.p.map(c), &rn),
            dot(&self.q.map(c), &rn),
            self.angle(r) - c(target),
        ]
    }

    /// `Bᵀμ` of a rotation, material spins (generic; module docs).
    fn grad_rot<S: Real>(&self, n: &Vector3<f64>, r: &Matrix3<S>, mu: &[S; 3]) -> Vector3<S> {
        let (n, p, q) = (n.map(c), self.p.map(c), self.q.map(c));
        let u = mv(r, &p);
        let (x, y) = (dot(&p, &u), dot(&q, &u));
        let w = (q * x - p * y) * (mu[2] / (x * x + y * y));
        n.cross(&mtv(r, &(p * mu[0] + q * mu[1]))) + p.cross(&mtv(r, &w))
    }

    /// The driven row's multiplier `μ = sλ̂ + pΦ`.
    fn mu_driven(&self, ctx: &EvalContext, s: &NodeState, lambda: &[f64]) -> f64 {
        let target = self.target(s, ctx.t);
        let phi = match self.motion {
            NodeMotion::Displacement(i) => s.x[i] - self.x0[i] - target,
            NodeMotion::Rotation(_) => self.angle(&s.r) - target,
        };
        ctx.constraint_scale * lambda.get(self.driven_row()).copied().unwrap_or(0.0)
            + ctx.penalty * phi
    }
}

impl Element for Prescribed {
    fn id(&self) -> ElementId {
        self.id
    }

    fn drive_law_mut(&mut self) -> Option<&mut TimeLaw> {
        Some(&mut self.law)
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn multipliers(&self) -> usize {
        self.motion.equations()
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        let st = &nodes[self.nodes[0]];
        let (s, pen) = (ctx.constraint_scale, ctx.penalty);
        let target = self.target(st, ctx.t);
        match self.motion {
            NodeMotion::Displacement(i) => {
                let phi = st.x[i] - self.x0[i] - target;
                out.res[i] += s * lambda[0] + pen * phi;
                out.res[6] += s * phi;
                if tangent {
                    out.add_tan(i, i, pen);
                    out.add_tan(i, 6, s);
                    out.add_tan(6, i, s);
                }
            }
            NodeMotion::Rotation(n) => {
                if !tangent {
                    let phi = self.phi_rot(&n, &st.r, target);
                    let mu = [0, 1, 2].map(|k| s * lambda[k] + pen * phi[k]);
                    let g = self.grad_rot(&n, &st.r, &mu);
                    out.add_res(3, &g);
                    for k in 0..3 {
                        out.res[6 + k] += s * phi[k];
                    }
                    return;
                }
                // R (I + δΘ̃): exact to first order, all a dual number carries.
                let dth = Vector3::new(D3::var(0.0, 0), D3::var(0.0, 1), D3::var(0.0, 2));
                let rr: Matrix3<D3> = st.r.map(D3::constant);
                let r = rr + mm(&rr, &skew(&dth));
                let phi = self.phi_rot(&n, &r, target);
                let mu =
                    [0, 1, 2].map(|k| phi[k] * D3::constant(pen) + D3::constant(s * lambda[k]));
                let g = self.grad_rot(&n, &r, &mu);
                for (row, gr) in [g.x, g.y, g.z].iter().enumerate() {
                    out.res[3 + row] += gr.re;
                    for (col, e) in gr.eps.iter().enumerate() {
                        out.add_tan(3 + row, 3 + col, *e);
                    }
                }
                for (k, v) in phi.iter().enumerate() {
                    out.res[6 + k] += s * v.re;
                    for (col, e) in v.eps.iter().enumerate() {
                        out.add_tan(6 + k, 3 + col, s * e);
                        out.add_tan(3 + col, 6 + k, s * e);
                    }
                }
            }
        }
    }

    fn rheonomic(&self) -> bool {
        true
    }

    /// `B v`: the velocity's component for a displacement; for a rotation, `Φ` at
    /// `R(I + εΩ̃)` by one dual direction.
    fn constraint_rates(&self, nodes: &[NodeState], out: &mut [f64]) -> bool {
        let st = &nodes[self.nodes[0]];
        match self.motion {
            NodeMotion::Displacement(i) => out[0] = st.v[i],
            NodeMotion::Rotation(n) => {
                let rw = st.r * skew(&st.w);
                let r = Matrix3::from_fn(|i, j| Dual::<1> {
                    re: st.r[(i, j)],
                    eps: [rw[(i, j)]],
                });
                for (o, p) in out.iter_mut().zip(&self.phi_rot(&n, &r, 0.0)) {
                    *o = p.eps[0];
                }
            }
        }
        true
    }

    fn constraint_time_derivatives(&self, t: f64, k: usize) -> [f64; 2] {
        if k == self.driven_row() {
            let [_, fd, fdd] = self.law.at(t);
            [-fd, -fdd]
        } else {
            [0.0; 2]
        }
    }

    fn input_power(&self, ctx: &EvalContext, nodes: &[NodeState], lambda: &[f64]) -> f64 {
        -self.mu_driven(ctx, &nodes[self.nodes[0]], lambda) * self.law.at(ctx.t)[1]
    }

    fn constraint_violation(&self, nodes: &[NodeState]) -> f64 {
        // The driven row needs the time: the alignment of a rotation's axis only.
        match self.motion {
            NodeMotion::Displacement(_) => 0.0,
            NodeMotion::Rotation(n) => {
                let phi = self.phi_rot(&n, &nodes[self.nodes[0]].r, 0.0);
                phi[0].abs().max(phi[1].abs())
            }
        }
    }

    fn output_header(&self) -> Vec<String> {
        let cols: [&str; 3] = match self.motion {
            NodeMotion::Displacement(_) => ["prescribed", "displacement", "force"],
            NodeMotion::Rotation(_) => ["prescribed", "angle", "moment"],
        };
        cols.iter().map(|s| s.to_string()).collect()
    }

    fn write_output_row(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        let st = &nodes[self.nodes[0]];
        let law = self.law.value(ctx.t);
        let value = match self.motion {
            NodeMotion::Displacement(i) => st.x[i] - self.x0[i],
            NodeMotion::Rotation(_) => {
                let th = self.angle(&st.r);
                law + (th - law - ((th - law) / TAU).round() * TAU)
            }
        };
        row.extend_from_slice(&[law, value, -self.mu_driven(ctx, st, lambda)]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::*;
    use crate::model::Function;

    fn ctx() -> EvalContext {
        EvalContext {
            constraint_scale: 3.7,
            penalty: 11.0,
            t: 0.3,
            ..dyn_ctx()
        }
    }

    fn law() -> TimeLaw {
        TimeLaw::new(
            Function::Haversine {
                start: 0.0,
                duration: 1.0,
            },
            2.5,
        )
    }

    /// The tangent is the finite difference of the residual, at large rotations, for
    /// every motion.
    #[test]
    fn tangent_matches_finite_differences() {
        let x0 = [Vector3::new(0.1, 0.2, -0.1)];
        let motions = [
            NodeMotion::Displacement(0),
            NodeMotion::Displacement(2),
            NodeMotion::Rotation(Vector3::new(0.3, -0.5, 0.8)),
        ];
        for m in motions {
            let e = Prescribed::new(ElementId(3), 0, x0[0], m, law());
            for seed in 1..4 {
                let st = random_states(&x0, 0.3, 1.5, seed);
                let mut g = Lcg(seed + 7);
                let lam: Vec<f64> = (0..e.multipliers()).map(|_| g.next() * 5.0).collect();
                check_tangent(&e, &ctx(), &st, &lam, 1e-7);
                check_tangent(&e, &static_ctx(), &st, &lam, 1e-7);
            }
        }
    }

    /// `B v` of [`Element::constraint_rates`] is the tangent's constraint rows applied to
    /// `(v, Ω)`, over the scale, for every motion (to round-off).
    #[test]
    fn constraint_rates_are_the_tangents_constraint_rows_times_the_velocities() {
        let x0 = [Vector3::new(0.1, 0.2, -0.1)];
        for m in [
            NodeMotion::Displacement(1),
            NodeMotion::Rotation(Vector3::new(0.3, -0.5, 0.8)),
        ] {
            let e = Prescribed::new(ElementId(3), 0, x0[0], m, law());
            let k = e.multipliers();
            for seed in 1..4 {
                let st = random_states(&x0, 0.3, 1.5, seed);
                let mut local = Local::new(6 + k);
                e.evaluate(&ctx(), &st, &vec![0.0; k], true, &mut local);
                let mut rates = vec![0.0; k];
                assert!(e.constraint_rates(&st, &mut rates));
                for (row, r) in rates.iter().enumerate() {
                    let bv: f64 = (0..3)
                        .map(|d| {
                            local.tan_at(6 + row, d) * st[0].v[d]
                                + local.tan_at(6 + row, 3 + d) * st[0].w[d]
                        })
                        .sum::<f64>()
                        / ctx().constraint_scale;
                    assert!(
                        (r - bv).abs() <= 1e-12 * bv.abs().max(1.0),
                        "{m:?} {row}: {r} vs {bv}"
                    );
                }
            }
        }
    }

    /// A node at `R = exp(θ ñ)` with `θ = a f(t)` (many turns) satisfies the rotation's
    /// equations, and its reported angle is θ itself, not θ modulo 2π.
    #[test]
    fn rotation_of_many_turns_satisfies_the_equations() {
        let n = Vector3::new(0.3, -0.5, 0.8).normalize();
        // 250 rad at the pulse's peak: about 40 turns.
        let many = TimeLaw::new(
            Function::Haversine {
                start: 0.0,
                duration: 1.0,
            },
            250.0,
        );
        let e = Prescribed::new(
            ElementId(3),
            0,
            Vector3::zeros(),
            NodeMotion::Rotation(n),
            many.clone(),
        );
        let mut out = Local::new(9);
        for k in 0..20 {
            let mut c = ctx();
            c.t = 0.05 * k as f64;
            let th = many.value(c.t);
            let mut st = NodeState::at_rest(Vector3::zeros());
            st.r = crate::rotation::exp(&(n * th));
            out.clear();
            e.evaluate(&c, &[st], &[0.0; 3], false, &mut out);
            for k in 0..3 {
                assert!(out.res[6 + k].abs() < 1e-9, "t = {}: {:?}", c.t, out.res);
            }
            let row = e.output_row(&c, &[st], &[0.0; 3]);
            assert!((row[1] - th).abs() < 1e-9, "angle {} vs {th}", row[1]);
        }
    }
}
