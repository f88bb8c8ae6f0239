//! Stiffness-proportional (Kelvin–Voigt) structural damping of the beam (material
//! `DAMPING η` in a deck).
//!
//! # Law
//! Each stiffness point carries, besides the elastic resultants, the damping resultants
//! `N_d = η C_N Γ̇`, `M_d = η C_M K̇` (`C_N = diag(EA, kGA, kGA)`, `C_M = diag(GJ, EI₂, EI₃)`):
//! the stiffness-proportional half of Rayleigh damping written on the strains, i.e. the
//! Kelvin–Voigt solid `σ = C (ε + η ε̇)` (Géradin & Cardona 2001, *Flexible Multibody
//! Dynamics*, §5.8; Hughes 1987, §9.2). Linearised about a straight reference, it damps mode
//! `k` of circular frequency `ωₖ` with the modal damping ratio `ζₖ = η ωₖ / 2`.
//!
//! # Objectivity
//! The rates are those of the material strains `Γ = exp(ψ̃)ᵀ y_s − Γ⁰`, `K = T(ψ) ψ_s − K⁰`
//! of the local numbers `yᵢ = Λᵣᵀ(xᵢ − xᵣ)`, `ψᵢ = log(Λᵣᵀ Λᵢ)` ([`super`]), which a rigid
//! motion leaves unchanged: a rigid velocity field gives `Γ̇ = K̇ = 0`, no damping force.
//! With `Ω′ᵢ = Λ⁰ᵢᵀ Ωᵢ` (node angular velocity in the element triad):
//! `ẏᵢ = Λᵣᵀ(ẋᵢ − ẋᵣ) − Ω′ᵣ × yᵢ`, `ψ̇ᵢ = T⁻¹(ψᵢ)(Ω′ᵢ − exp(ψ̃ᵢ)ᵀ Ω′ᵣ)`
//! (from `Λ̇ = Λ Ω̃′`, `d exp(ψ̃) = exp(ψ̃)(T(ψ) dψ)~`), interpolated like `yᵢ`, `ψᵢ`, and at a
//! point `Γ̇ = exp(ψ̃)ᵀ ẏ_s − (T(ψ) ψ̇) × a` (`a = exp(ψ̃)ᵀ y_s`),
//! `K̇ = T(ψ) ψ̇_s + ∂(T(ψ) ψ_s)/∂ψ · ψ̇`.
//!
//! # Forces, tangent, power
//! The damping forces are the virtual work of `N_d`, `M_d`: `f_d = Σ w J Bᵀ (N_d, M_d)`
//! with the same `B = ∂(Γ, K)/∂q` as the elastic forces ([`BeamP::stress_grad`] and the
//! chain rule of [`BeamP::internal_forces`]), so `q̇·f_d = P_d = Σ w J (Γ̇·N_d + K̇·M_d) ≥ 0`,
//! the dissipated power (tested), which the integrator integrates into `energy.csv`'s
//! balance ([`crate::elements::Element::dissipated_power`]). The iteration matrix gets the
//! exact `∂f_d/∂q` (stiffness part) and `c_v ∂f_d/∂(ẋ, Ω)` (rate part), by forward-mode
//! dual numbers through this module's generic `f_d(x, R, ẋ, Ω)`, one node (12 directions)
//! per pass.

use super::{BeamP, t_coefficients};
use crate::dual::{Dual, Real};
use crate::elements::{EvalContext, Local, NodeState, rx, tx};
use crate::rotation::{self, c, skew};
use nalgebra::{Matrix3, Vector3};

type D12 = Dual<12>;

/// Node states in the scalar `S` (positions, rotations, velocities, material angular
/// velocities), element order.
struct States<S: Real> {
    x: Vec<Vector3<S>>,
    r: Vec<Matrix3<S>>,
    v: Vec<Vector3<S>>,
    w: Vec<Vector3<S>>,
}

/// `∂(T(ψ) u)/∂ψ · w` with `T u = u − b ψ × u + d ψ × (ψ × u)` and the coefficients of
/// [`t_coefficients`] (`b′ = db/d(φ²)`, `d′ = dd/d(φ²)`, `d(φ²) = 2 ψ·w`).
fn dt_u<S: Real>(psi: &Vector3<S>, u: &Vector3<S>, w: &Vector3<S>) -> Vector3<S> {
    let (b, d, db, dd) = t_coefficients(psi.dot(psi));
    let two_pw = psi.dot(w) * c::<S>(2.0);
    let pu = psi.cross(u);
    pu * (-(db * two_pw)) - w.cross(u) * b
        + psi.cross(&pu) * (dd * two_pw)
        + (w.cross(&pu) + psi.cross(&w.cross(u))) * d
}

impl BeamP {
    /// This element with stiffness-proportional damping `eta` (s, ≥ 0; module doc).
    pub fn with_damping(mut self, eta: f64) -> Self {
        self.eta = eta;
        self
    }

    /// The damping coefficient η, s.
    pub fn damping(&self) -> f64 {
        self.eta
    }

    /// Damping forces (node by node `[f_x, f_Θ]` into `f`, `2n` entries) and the dissipated
    /// power, generic in the scalar; `shift` are the log branch shifts of the nodes'
    /// relative rotations at the (f64) state.
    fn damping_forces<S: Real>(&self, s: &States<S>, shift: &[f64], f: &mut [Vector3<S>]) -> S {
        let n = s.x.len();
        let m = self.refn;
        let l0: Vec<Matrix3<S>> = self.lambda0.iter().map(|l| l.map(c)).collect();
        let lr = rotation::mm(&s.r[m], &l0[m]);
        let om_r = rotation::mtv(&l0[m], &s.w[m]);
        let zero = Vector3::<S>::zeros();
        // (y, ψ, ẏ, ψ̇) per node and exp(ψ̃ᵢ) = Λᵣᵀ Λᵢ.
        let mut z = vec![[zero; 4]; n];
        let mut rel = vec![Matrix3::<S>::identity(); n];
        for i in (0..n).filter(|&i| i != m) {
            let reli = rotation::mtm(&lr, &rotation::mm(&s.r[i], &l0[i]));
            let phi = rotation::log(&reli);
            let psi = if shift[i] != 0.0 {
                phi * (S::one() + c::<S>(shift[i]) / phi.dot(&phi).sqrt())
            } else {
                phi
            };
            let y = rotation::mtv(&lr, &(s.x[i] - s.x[m]));
            let yd = rotation::mtv(&lr, &(s.v[i] - s.v[m])) - om_r.cross(&y);
            let om_i = rotation::mtv(&l0[i], &s.w[i]);
            let psid = rotation::mv(
                &rotation::tangent_inv(&psi),
                &(om_i - rotation::mtv(&reli, &om_r)),
            );
            z[i] = [y, psi, yd, psid];
            rel[i] = reli;
        }
        let eta = c::<S>(self.eta);
        let cn: Vector3<S> = self.props.cn.map(c);
        let cm: Vector3<S> = self.props.cm.map(c);
        let mut gz = vec![[zero; 2]; n];
        let mut power = S::zero();
        for q in &self.stiff {
            // ψ, ψ_s, y_s and their rates at the point.
            let mut p = [zero; 6];
            for ((zi, &ni), &di) in z.iter().zip(&q.n).zip(&q.ds) {
                let (ni, di) = (c::<S>(ni), c::<S>(di));
                p[0] += zi[1] * ni;
                p[1] += zi[1] * di;
                p[2] += zi[0] * di;
                p[3] += zi[3] * ni;
                p[4] += zi[3] * di;
                p[5] += zi[2] * di;
            }
            let [psi, dpsi, dy, psid, dpsid, dyd] = p;
            let e = rotation::exp(&psi);
            let t = rotation::tangent(&psi);
            let a = rotation::mtv(&e, &dy);
            let gd = rotation::mtv(&e, &dyd) - rotation::mv(&t, &psid).cross(&a);
            let kd = rotation::mv(&t, &dpsid) + dt_u(&psi, &dpsi, &psid);
            let nn = gd.component_mul(&cn) * eta;
            let mm = kd.component_mul(&cm) * eta;
            let wj = c::<S>(q.wj);
            power += (gd.dot(&nn) + kd.dot(&mm)) * wj;
            let g = Self::stress_grad(&psi, &dpsi, &e, &t, &a, &nn, &mm);
            let at = |k: usize| Vector3::new(g[k], g[k + 1], g[k + 2]) * wj;
            let (g_psi, g_dpsi, g_dy) = (at(0), at(3), at(6));
            for ((gzi, &ni), &di) in gz.iter_mut().zip(&q.n).zip(&q.ds) {
                let (ni, di) = (c::<S>(ni), c::<S>(di));
                gzi[0] += g_dy * di;
                gzi[1] += g_psi * ni + g_dpsi * di;
            }
        }
        // Chain rule of the local numbers (as `internal_forces`).
        let (mut fxr, mut fthr) = (zero, zero);
        for i in (0..n).filter(|&i| i != m) {
            let [gy, gp] = gz[i];
            let fx = rotation::mv(&lr, &gy);
            let tig = rotation::mtv(&rotation::tangent_inv(&z[i][1]), &gp);
            fxr -= fx;
            fthr += rotation::mv(&l0[m], &(gy.cross(&z[i][0]) - rotation::mv(&rel[i], &tig)));
            f[2 * i] = fx;
            f[2 * i + 1] = rotation::mv(&l0[i], &tig);
        }
        f[2 * m] = fxr;
        f[2 * m + 1] = fthr;
        power
    }

    /// The log branch shifts of the nodes' relative rotations at `nodes`.
    fn shifts(&self, nodes: &[NodeState]) -> Vec<f64> {
        self.with_locals(nodes, |sc, n| sc.shift[..n].to_vec())
    }

    /// The element's node states in `f64`.
    fn states(&self, nodes: &[NodeState]) -> States<f64> {
        let st = |i: &usize| &nodes[*i];
        States {
            x: self.nodes.iter().map(|i| st(i).x).collect(),
            r: self.nodes.iter().map(|i| st(i).r).collect(),
            v: self.nodes.iter().map(|i| st(i).v).collect(),
            w: self.nodes.iter().map(|i| st(i).w).collect(),
        }
    }

    /// The dissipated power `P_d = Σ w J (Γ̇·η C_N Γ̇ + K̇·η C_M K̇)`, W (module doc).
    pub(super) fn damping_power(&self, nodes: &[NodeState]) -> f64 {
        let mut f = vec![Vector3::zeros(); 2 * self.nodes.len()];
        self.damping_forces(&self.states(nodes), &self.shifts(nodes), &mut f)
    }

    /// Adds the damping forces to `out.res` and, with `tangent`, their exact derivative:
    /// `∂f_d/∂q` to the stiffness and `c_v ∂f_d/∂(ẋ, Ω)` to the rate part of `out`.
    pub(super) fn add_damping(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        tangent: bool,
        out: &mut Local,
    ) {
        let n = self.nodes.len();
        let shift = self.shifts(nodes);
        let s = self.states(nodes);
        // The residual by the f64 path in both cases (bit for bit the same with and
        // without the tangent); the dual passes give the tangent only.
        let mut f = vec![Vector3::zeros(); 2 * n];
        self.damping_forces(&s, &shift, &mut f);
        for (k, v) in f.iter().enumerate() {
            out.add_res(3 * k, v);
        }
        if !tangent {
            return;
        }
        let lift3 = |v: &Vector3<f64>| v.map(D12::constant);
        let mut f = vec![Vector3::<D12>::zeros(); 2 * n];
        for j in 0..n {
            let mut d = States {
                x: s.x.iter().map(lift3).collect(),
                r: s.r.iter().map(|r| r.map(D12::constant)).collect(),
                v: s.v.iter().map(lift3).collect(),
                w: s.w.iter().map(lift3).collect(),
            };
            let seed = |v: &Vector3<f64>, k: usize| {
                Vector3::new(D12::var(v.x, k), D12::var(v.y, k + 1), D12::var(v.z, k + 2))
            };
            // R (I + δΘ̃): the right-multiplied rotation variation, to first order.
            let dth = seed(&Vector3::zeros(), 3);
            d.x[j] = seed(&s.x[j], 0);
            d.r[j] = d.r[j] + rotation::mm(&d.r[j], &skew(&dth));
            d.v[j] = seed(&s.v[j], 6);
            d.w[j] = seed(&s.w[j], 9);
            self.damping_forces(&d, &shift, &mut f);
            for (k, fk) in f.iter().enumerate() {
                let row = 3 * k;
                let block = |o: usize| Matrix3::from_fn(|r, cc| fk[r].eps[o + cc]);
                out.add_block(row, tx(j), &block(0));
                out.add_block(row, rx(j), &block(3));
                out.add_rate_block(row, tx(j), &(block(6) * ctx.c_v));
                out.add_rate_block(row, rx(j), &(block(9) * ctx.c_v));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::straight;
    use super::*;
    use crate::elements::Element;
    use crate::elements::testing::*;

    /// A damped straight beam of order `p` (η = 1e-4 s: c_v η = 0.2, the damping part is a
    /// fifth of the stiffness in the iteration matrix) and its reference positions.
    fn damped(p: usize) -> (BeamP, Vec<Vector3<f64>>) {
        let (x1, x2) = (Vector3::new(0.1, 0.2, -0.1), Vector3::new(0.4, 0.25, 0.05));
        let (b, x0) = straight(p, x1, x2);
        (b.with_damping(1e-4), x0)
    }

    /// The iteration matrix of the damped beam (stiffness and rate parts) equals central
    /// differences of its residual, at large rotations and random velocities, for
    /// p = 1, 2, 4 (same tolerance as the undamped beam's check).
    #[test]
    fn damped_tangent_matches_finite_differences() {
        for p in [1, 2, 4] {
            let (b, x0) = damped(p);
            for seed in 1..4 {
                let st = random_states(&x0, 0.01, 0.9, seed);
                check_tangent(&b, &dyn_ctx(), &st, &[], 2e-7);
            }
        }
    }

    /// `q̇·f_d = P_d` (the forces are the virtual work of the damping stresses whose rates
    /// define the power), `P_d > 0` on a deforming state, and a rigid velocity field
    /// (`ẋ = V + W × x`, `Ω = Rᵀ W`) dissipates nothing and feels no damping force
    /// (objectivity), on a deformed, rotated state.
    #[test]
    fn damping_power_is_the_work_of_the_forces_and_vanishes_for_rigid_motions() {
        for p in [1, 3] {
            let (b, x0) = damped(p);
            let st = random_states(&x0, 0.01, 0.9, 5);
            let n = st.len();
            let mut f = vec![Vector3::zeros(); 2 * n];
            let power = b.damping_forces(&b.states(&st), &b.shifts(&st), &mut f);
            let work: f64 = (0..n)
                .map(|i| f[2 * i].dot(&st[i].v) + f[2 * i + 1].dot(&st[i].w))
                .sum();
            assert!(power > 0.0);
            assert!((work - power).abs() < 1e-10 * power, "{work} vs {power}");
            let (vv, ww) = (Vector3::new(0.3, -1.0, 2.0), Vector3::new(1.5, 0.7, -2.0));
            let rigid: Vec<NodeState> = st
                .iter()
                .map(|s| NodeState {
                    v: vv + ww.cross(&s.x),
                    w: s.r.transpose() * ww,
                    ..*s
                })
                .collect();
            let fmax = f.iter().map(|v| v.norm()).fold(0.0, f64::max);
            let pr = b.damping_forces(&b.states(&rigid), &b.shifts(&rigid), &mut f);
            let fr = f.iter().map(|v| v.norm()).fold(0.0, f64::max);
            // Round-off of the rates (velocities ~2, strains' operators ~1) against the
            // random state's forces and power.
            assert!(pr.abs() < 1e-10 * power, "rigid power {pr} ({power})");
            assert!(fr < 1e-8 * fmax, "rigid force {fr} ({fmax})");
            assert!(b.dissipated_power(&rigid) < 1e-10 * power);
        }
    }
}
