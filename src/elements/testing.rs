//! Generic checks stamped on every element (fenris-style): the iteration matrix equals a
//! central finite difference of the residual, and a rigid motion rotates the forces.

use super::*;
use crate::rotation;

/// A deterministic pseudo-random generator for test states (no external crate).
pub struct Lcg(pub u64);
impl Lcg {
    /// Uniform in [-1, 1).
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    /// A vector with components in [-s, s).
    pub fn vec(&mut self, s: f64) -> Vector3<f64> {
        Vector3::new(self.next() * s, self.next() * s, self.next() * s)
    }
}

fn residual(
    el: &dyn Element,
    ctx: &EvalContext,
    nodes: &[NodeState],
    lambda: &[f64],
    n: usize,
) -> Vec<f64> {
    let mut out = Local::new(n);
    el.evaluate(ctx, nodes, lambda, false, &mut out);
    out.res
}

/// Perturbs local direction `dir` by `eps` (position/rotation by `eps`, velocity by
/// `c_v eps`, acceleration by `c_a eps`, multiplier by `eps`).
fn perturb(
    el: &dyn Element,
    ctx: &EvalContext,
    nodes: &mut [NodeState],
    lambda: &mut [f64],
    dir: usize,
    eps: f64,
) {
    let nn = el.nodes().len();
    if dir >= 6 * nn {
        lambda[dir - 6 * nn] += eps;
        return;
    }
    let node = el.nodes()[dir / 6];
    let k = dir % 6;
    let s = &mut nodes[node];
    let mut e = Vector3::zeros();
    e[k % 3] = eps;
    if k < 3 {
        s.x += e;
        s.v += e * ctx.c_v;
        s.a += e * ctx.c_a;
    } else {
        s.r *= rotation::exp(&e);
        s.w += e * ctx.c_v;
        s.wd += e * ctx.c_a;
    }
}

/// Asserts that the tangent matches a central difference of the residual, column by
/// column, to `rel` relative to the largest tangent entry (truncation O(ε²) with
/// ε = 1e-6 times the state scale, round-off O(1e-16/ε)).
pub fn check_tangent(
    el: &dyn Element,
    ctx: &EvalContext,
    nodes: &[NodeState],
    lambda: &[f64],
    rel: f64,
) {
    let n = 6 * el.nodes().len() + el.multipliers();
    let mut out = Local::new(n);
    el.evaluate(ctx, nodes, lambda, true, &mut out);
    let res0 = residual(el, ctx, nodes, lambda, n);
    for (a, b) in out.res.iter().zip(&res0) {
        assert!(
            (a - b).abs() <= 1e-12 * (1.0 + a.abs()),
            "residual differs with and without tangent"
        );
    }
    let scale = out
        .tan
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-300);
    let eps = 1e-6;
    for col in 0..n {
        let (mut np, mut lp) = (nodes.to_vec(), lambda.to_vec());
        perturb(el, ctx, &mut np, &mut lp, col, eps);
        let rp = residual(el, ctx, &np, &lp, n);
        let (mut nm, mut lm) = (nodes.to_vec(), lambda.to_vec());
        perturb(el, ctx, &mut nm, &mut lm, col, -eps);
        let rm = residual(el, ctx, &nm, &lm, n);
        for row in 0..n {
            let fd = (rp[row] - rm[row]) / (2.0 * eps);
            let an = out.tan_at(row, col);
            assert!(
                (fd - an).abs() <= rel * scale,
                "tangent ({row},{col}): analytic {an:e}, finite difference {fd:e} (scale {scale:e})"
            );
        }
    }
}

/// A random state near the reference positions: displacement `du`, rotations of size
/// `dr` (rad), velocities and accelerations of order 1.
pub fn random_states(x0: &[Vector3<f64>], du: f64, dr: f64, seed: u64) -> Vec<NodeState> {
    let mut g = Lcg(seed);
    x0.iter()
        .map(|x| NodeState {
            x: x + g.vec(du),
            r: rotation::exp(&g.vec(dr)),
            v: g.vec(1.0),
            w: g.vec(1.0),
            a: g.vec(1.0),
            wd: g.vec(1.0),
        })
        .collect()
}

/// Applies a rigid motion `x ↦ Q x + b`, `R ↦ Q R` to the states (velocities rotated;
/// material angular velocities unchanged).
pub fn rigidly_moved(nodes: &[NodeState], q: &Matrix3<f64>, b: &Vector3<f64>) -> Vec<NodeState> {
    nodes
        .iter()
        .map(|s| NodeState {
            x: q * s.x + b,
            r: q * s.r,
            v: q * s.v,
            w: s.w,
            a: q * s.a,
            wd: s.wd,
        })
        .collect()
}

/// A context with HHT-like coefficients for h = 1e-3, no gravity.
pub fn dyn_ctx() -> EvalContext {
    EvalContext {
        t: 0.0,
        c_v: 2.1e3,
        c_a: 3.9e6,
        dynamic: true,
        gravity: Vector3::zeros(),
        constraint_scale: 1.0,
        penalty: 0.0,
        h: 1e-3,
    }
}

/// A static context (no inertia, no gravity).
pub fn static_ctx() -> EvalContext {
    EvalContext {
        c_v: 0.0,
        c_a: 0.0,
        dynamic: false,
        h: 0.0,
        ..dyn_ctx()
    }
}

/// Asserts objectivity: under a rigid motion `x ↦ Q x + b`, `R ↦ Q R` of the states, the
/// translational rows of the residual (global forces) rotate by `Q` and the rotational rows
/// (material moments) are unchanged, to `rel` of the largest entry.
pub fn check_objectivity(el: &dyn Element, ctx: &EvalContext, nodes: &[NodeState], rel: f64) {
    let n = 6 * el.nodes().len() + el.multipliers();
    let lambda = vec![0.0; el.multipliers()];
    let q = rotation::exp(&Vector3::new(0.7, -1.1, 0.4));
    let moved = rigidly_moved(nodes, &q, &Vector3::new(1.0, -2.0, 0.5));
    let r0 = residual(el, ctx, nodes, &lambda, n);
    let r1 = residual(el, ctx, &moved, &lambda, n);
    let scale = r0.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    for k in 0..el.nodes().len() {
        let t0 = Vector3::new(r0[6 * k], r0[6 * k + 1], r0[6 * k + 2]);
        let t1 = Vector3::new(r1[6 * k], r1[6 * k + 1], r1[6 * k + 2]);
        let m0 = Vector3::new(r0[6 * k + 3], r0[6 * k + 4], r0[6 * k + 5]);
        let m1 = Vector3::new(r1[6 * k + 3], r1[6 * k + 4], r1[6 * k + 5]);
        assert!(
            (q * t0 - t1).norm() <= rel * scale,
            "node {k}: force {t1:?} is not the rotated {:?}",
            q * t0
        );
        assert!(
            (m0 - m1).norm() <= rel * scale,
            "node {k}: material moment {m1:?} changed from {m0:?}"
        );
    }
}
