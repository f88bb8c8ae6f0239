//! The shared joint-frame algebra: the constraint functions `Φ` of every joint kind
//! (generic in the scalar), `Bᵀμ` written out in the material spins, and its exact
//! derivatives by dual numbers (`B` and `K_g(μ) + p BᵀB`).

use super::*;

impl Joint {
    /// The constraint functions of one pair, generic in the scalar; a driven joint's
    /// sixth, `g(q) − target` (`target = a f(t) + 2πk`, joints/drive.rs).
    pub(super) fn phi<S: Real>(
        &self,
        pair: &Pair,
        x1: &Vector3<S>,
        r1: &Matrix3<S>,
        x2: &Vector3<S>,
        r2: &Matrix3<S>,
        target: f64,
    ) -> [S; 6] {
        let mut phi = self.phi_joint(pair, x1, r1, x2, r2);
        if self.drive.is_some() {
            phi[5] = self.drive_g(x1, r1, x2, r2, &pair.c2) - c(target);
        }
        phi
    }

    /// The joint's own (scleronomic) equations of one pair.
    fn phi_joint<S: Real>(
        &self,
        pair: &Pair,
        x1: &Vector3<S>,
        r1: &Matrix3<S>,
        x2: &Vector3<S>,
        r2: &Matrix3<S>,
    ) -> [S; 6] {
        let v = |w: &Vector3<f64>| -> Vector3<S> { w.map(c) };
        let d = x2 + mv(r2, &v(&pair.c2)) - x1;
        let z = S::zero();
        let rot = || rotation::axial(&mtm(r1, r2));
        match &self.kind {
            JointType::Spherical => [d.x, d.y, d.z, z, z, z],
            JointType::Hinge { p, q, a } => {
                let ra = mv(r2, &v(a));
                [
                    d.x,
                    d.y,
                    d.z,
                    dot(&mv(r1, &v(p)), &ra),
                    dot(&mv(r1, &v(q)), &ra),
                    z,
                ]
            }
            JointType::UJoint { a1, a2, .. } => {
                [d.x, d.y, d.z, dot(&mv(r1, &v(a1)), &mv(r2, &v(a2))), z, z]
            }
            JointType::Clamp | JointType::Rigid => {
                let w = rot();
                [d.x, d.y, d.z, w.x, w.y, w.z]
            }
            JointType::Prismatic { p, q, .. } => {
                let w = rot();
                [
                    w.x,
                    w.y,
                    w.z,
                    dot(&mv(r1, &v(p)), &d),
                    dot(&mv(r1, &v(q)), &d),
                    z,
                ]
            }
        }
    }

    /// The joint's own equations at the nodes' state (a driver's row is left at 0).
    pub(super) fn phi_f64(&self, pair: &Pair, s1: &NodeState, s2: &NodeState) -> [f64; 6] {
        self.phi_joint(pair, &s1.x, &s1.r, &s2.x, &s2.r)
    }

    /// The generalized constraint force `Bᵀμ` of one pair, `[x₁, Θ₁, x₂, Θ₂]` (material
    /// spins), written out analytically and generic in the scalar. With `Q = R₁ᵀR₂` and the
    /// variations `δx`, `δR = R δΘ̃`:
    /// - `d = x₂ + R₂c₂ − x₁`: `δd = δx₂ − δx₁ − R₂ c̃₂ δΘ₂`, so `μ_d` gives
    ///   `(−μ_d, 0, μ_d, c₂ × R₂ᵀμ_d)`;
    /// - `(R₁u)·(R₂v)`: `δΘ₁·(u × Qv) + δΘ₂·(v × Qᵀu)`;
    /// - `(R₁u)·d`: `δΘ₁·(u × R₁ᵀd) + (R₁u)·δd`;
    /// - `w = axial(skew Q)`: `δQ = −δΘ̃₁Q + QδΘ̃₂` and `axial(ω̃A + Aᵀω̃) = (tr A I − A)ω`
    ///   give `δw = ½(tr Q I − Qᵀ)δΘ₂ − ½(tr Q I − Q)δΘ₁`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn grad<S: Real>(
        &self,
        pair: &Pair,
        x1: &Vector3<S>,
        r1: &Matrix3<S>,
        x2: &Vector3<S>,
        r2: &Matrix3<S>,
        mu: &[S; 6],
    ) -> [S; 12] {
        let v = |w: &Vector3<f64>| -> Vector3<S> { w.map(c) };
        let c2 = v(&pair.c2);
        let q = mtm(r1, r2);
        let zero = Vector3::<S>::zeros();
        // Multipliers of `d` (global) and of `axial(skew Q)`, and the dot-product terms.
        let first = Vector3::new(mu[0], mu[1], mu[2]);
        let (mut md, mw, mut gt1, mut gt2) = match &self.kind {
            JointType::Spherical => (first, None, zero, zero),
            JointType::Hinge { p, q: qq, a } => {
                let u = v(p) * mu[3] + v(qq) * mu[4];
                let a = v(a);
                (first, None, u.cross(&mv(&q, &a)), a.cross(&mtv(&q, &u)))
            }
            JointType::UJoint { a1, a2, .. } => {
                let (u, w) = (v(a1) * mu[3], v(a2));
                (first, None, u.cross(&mv(&q, &w)), w.cross(&mtv(&q, &u)))
            }
            JointType::Clamp | JointType::Rigid => {
                (first, Some(Vector3::new(mu[3], mu[4], mu[5])), zero, zero)
            }
            JointType::Prismatic { p, q: qq, .. } => {
                let u = v(p) * mu[3] + v(qq) * mu[4];
                let d = x2 + mv(r2, &c2) - x1;
                (mv(r1, &u), Some(first), u.cross(&mtv(r1, &d)), zero)
            }
        };
        if self.drive.is_some() {
            let (g1, g2, gd) = self.drive_grad(x1, r1, x2, r2, &c2, mu[5]);
            gt1 += g1;
            gt2 += g2;
            md += gd;
        }
        if let Some(mw) = mw {
            let tr = q[(0, 0)] + q[(1, 1)] + q[(2, 2)];
            let h = c::<S>(0.5);
            gt1 -= (mw * tr - mtv(&q, &mw)) * h;
            gt2 += (mw * tr - mv(&q, &mw)) * h;
        }
        gt2 += c2.cross(&mtv(r2, &md));
        let (gx1, gx2) = (-md, md);
        [
            gx1.x, gx1.y, gx1.z, gt1.x, gt1.y, gt1.z, gx2.x, gx2.y, gx2.z, gt2.x, gt2.y, gt2.z,
        ]
    }

    /// `Φ` and `Bᵀμ` of one pair at the nodes' state, `μ = s λ̂ + p Φ`.
    pub(super) fn forces_f64(
        &self,
        pair: &Pair,
        s1: &NodeState,
        s2: &NodeState,
        ctx: &EvalContext,
        lam: &[f64],
    ) -> ([f64; 6], [f64; 12]) {
        let target = self.drive_target(s1, s2, ctx.t);
        let phi = self.phi(pair, &s1.x, &s1.r, &s2.x, &s2.r, target);
        let mut mu = [0.0; 6];
        for (i, m) in mu.iter_mut().enumerate().take(self.m_pair()) {
            *m = ctx.constraint_scale * lam.get(i).copied().unwrap_or(0.0) + ctx.penalty * phi[i];
        }
        (phi, self.grad(pair, &s1.x, &s1.r, &s2.x, &s2.r, &mu))
    }

    /// `Φ` and `Bᵀμ` of one pair with their exact derivatives along `[δx₁, δΘ₁, δx₂, δΘ₂]`
    /// (12 dual directions, seeding `R (I + δΘ̃)`): `Φ.eps = B`, and, since `μ = sλ̂ + pΦ`
    /// is itself dual, `(Bᵀμ).eps = K_g(μ) + p BᵀB`.
    pub(super) fn forces_dual(
        &self,
        pair: &Pair,
        s1: &NodeState,
        s2: &NodeState,
        ctx: &EvalContext,
        lam: &[f64],
    ) -> ([D12; 6], [D12; 12]) {
        let xs = |x: &Vector3<f64>, base: usize| {
            Vector3::new(
                D12::var(x.x, base),
                D12::var(x.y, base + 1),
                D12::var(x.z, base + 2),
            )
        };
        let rs = |r: &Matrix3<f64>, base: usize| {
            // R (I + δΘ̃): exact to first order, which is all a dual number carries.
            let dth = Vector3::new(
                D12::var(0.0, base),
                D12::var(0.0, base + 1),
                D12::var(0.0, base + 2),
            );
            let rr: Matrix3<D12> = r.map(D12::constant);
            rr + mm(&rr, &skew(&dth))
        };
        let (x1, r1, x2, r2) = (xs(&s1.x, 0), rs(&s1.r, 3), xs(&s2.x, 6), rs(&s2.r, 9));
        let target = self.drive_target(s1, s2, ctx.t);
        let phi = self.phi(pair, &x1, &r1, &x2, &r2, target);
        let mut mu = [D12::constant(0.0); 6];
        for (i, m) in mu.iter_mut().enumerate().take(self.m_pair()) {
            *m = phi[i] * D12::constant(ctx.penalty) + D12::constant(ctx.constraint_scale * lam[i]);
        }
        (phi, self.grad(pair, &x1, &r1, &x2, &r2, &mu))
    }

    /// Local index of entry `j` (0..12) of a pair's `[x₁, Θ₁, x₂, Θ₂]` vector.
    pub(super) fn local(pair: &Pair, j: usize) -> usize {
        if j < 6 {
            6 * pair.a + j
        } else {
            6 * pair.b + j - 6
        }
    }
}
