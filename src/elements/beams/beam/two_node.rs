//! The geometrically exact two-node beam (Reissner; Simo 1985; Cardona & Géradin 1988).
//!
//! # Strains and resultants (physics.md §2, paper eqs. [5]–[9])
//! Material strains `Γ = Λᵀ x₀' − E₁` and curvature `K̃ = Λᵀ Λ'`, resultants
//! `N = C_N Γ`, `M = C_M K` with `C_N = diag(EA, kGA, kGA)`, `C_M = diag(GJ, EI₂, EI₃)`.
//!
//! # Interpolation (objective; Crisfield & Jelenić 1999)
//! The element triads at the nodes are `Λᵢ = Rᵢ Λ₀` (`Λ₀`: the reference triad, axis 1
//! along the bar). The triad along the element is `Λ(s) = Λ₁ exp(s ψ̃ / L)` with the
//! *relative* rotation `ψ = log(Λ₁ᵀ Λ₂)`, so a rigid rotation of both nodes leaves `ψ`
//! unchanged: the strains are objective and path-independent. With one-point (reduced)
//! integration at the midpoint (against shear locking):
//! `K = ψ / L`, `Γ = Λ_mᵀ (x₂ − x₁)/L − E₁`, `Λ_m = Λ₁ exp(ψ̃/2)`.
//!
//! # Internal forces (variation of `U = L(½ Γ·C_N Γ + ½ K·C_M K)`)
//! With `a = Λ_mᵀ d`, `d = x₂ − x₁`, `g = N × a`, `p = M + ½ T(ψ/2)ᵀ g`:
//! `f_x₂ = −f_x₁ = Λ_m N`, `f_θ₁ = exp(ψ̃/2) g − Q T(ψ)⁻ᵀ p`, `f_θ₂ = T(ψ)⁻ᵀ p`
//! (`Q = Λ₁ᵀΛ₂`; moments in the element frame, turned to the node frame by `Λ₀`).
//! The tangent stiffness is the exact derivative of these forces, obtained by forward-mode
//! automatic differentiation (dual numbers, [`crate::dual`]) — consistent by construction and
//! checked against finite differences in the tests.
//!
//! # Inertia (paper eqs. [10]–[11])
//! Consistent translational mass `ρAL/6 [2 1; 1 2]`, and rotary inertia lumped at the
//! nodes, `J = (L/2) Λ₀ ρ diag(I₂+I₃, I₂, I₃) Λ₀ᵀ` in the node's material frame, with the
//! gyroscopic force `J Ω̇ + Ω × J Ω`. Gravity: `ρAL g / 2` on each node.
//!
//! # Damping
//! A beam whose material (or section of properties) has `DAMPING η` is built as the order-1 [`super::beam_p::BeamP`]
//! (the same element, tested equal), which carries the Kelvin–Voigt damping stresses
//! `η C (Γ̇, K̇)` (`beam_p/damping.rs`); this element is the undamped fast path.

use crate::dual::{Dual, Real};
use crate::elements::{Element, Energies, EvalContext, Local, NodeState, rx, tx};
use crate::model::ElementId;
use crate::rotation::{self, c, skew};
use nalgebra::{Matrix3, Vector3};

/// Section and material properties of a beam, per unit length (resolved in the model
/// from a material and a geometry, or given by a section of properties).
pub use crate::model::BeamProperties;

/// A two-node geometrically exact beam.
#[derive(Debug, Clone)]
pub struct Beam {
    id: ElementId,
    nodes: [usize; 2],
    length: f64,
    /// Reference triad: columns = local axes 1, 2, 3 in the global frame.
    lambda0: Matrix3<f64>,
    props: BeamProperties,
    /// Lumped rotary inertia at each node, node material frame.
    j_node: Matrix3<f64>,
}

/// The default direction of local axis 2: global Y projected normal to the bar, or global Z
/// when the bar is (nearly) parallel to Y.
pub fn default_axis2(axis1: &Vector3<f64>) -> Vector3<f64> {
    let y = Vector3::y();
    if axis1.cross(&y).norm() > 1e-3 * axis1.norm() {
        y
    } else {
        Vector3::z()
    }
}

/// The reference triad of a bar from node 1 to node 2 with local axis 2 near `axis2`.
pub fn reference_triad(x1: &Vector3<f64>, x2: &Vector3<f64>, axis2: &Vector3<f64>) -> Matrix3<f64> {
    let t1 = (x2 - x1).normalize();
    let t2 = (axis2 - t1 * t1.dot(axis2)).normalize();
    let t3 = t1.cross(&t2);
    Matrix3::from_columns(&[t1, t2, t3])
}

/// Kinematic results of the beam kernel.
struct Kernel<S: Real> {
    /// `[f_x1, f_Θ1, f_x2, f_Θ2]` (node frames).
    f: [Vector3<S>; 4],
    gamma: Vector3<S>,
    kappa: Vector3<S>,
}

impl Beam {
    /// A beam between nodes (dense indices) at reference positions `x1`, `x2`.
    pub fn new(
        id: ElementId,
        nodes: [usize; 2],
        x1: &Vector3<f64>,
        x2: &Vector3<f64>,
        axis2: Option<Vector3<f64>>,
        props: BeamProperties,
    ) -> Self {
        let d = x2 - x1;
        let axis2 = axis2.unwrap_or_else(|| default_axis2(&d));
        let lambda0 = reference_triad(x1, x2, &axis2);
        let length = d.norm();
        let j_node = lambda0
            * Matrix3::from_diagonal(&(props.inertia * (0.5 * length)))
            * lambda0.transpose();
        Beam {
            id,
            nodes,
            length,
            lambda0,
            props,
            j_node,
        }
    }

    /// The reference length, m.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// The strain kernel, generic in the scalar (f64 or dual numbers).
    fn kernel<S: Real>(
        &self,
        x1: Vector3<S>,
        x2: Vector3<S>,
        r1: Matrix3<S>,
        r2: Matrix3<S>,
    ) -> Kernel<S> {
        let l0: Matrix3<S> = self.lambda0.map(c);
        let inv_l = c::<S>(1.0 / self.length);
        let lam1 = rotation::mm(&r1, &l0);
        let lam2 = rotation::mm(&r2, &l0);
        let q = rotation::mtm(&lam1, &lam2);
        let psi = rotation::log(&q);
        let half = psi * c::<S>(0.5);
        let e = rotation::exp(&half);
        let lam_m = rotation::mm(&lam1, &e);
        let d = x2 - x1;
        let a = rotation::mtv(&lam_m, &d);
        let gamma = a * inv_l - Vector3::x();
        let kappa = psi * inv_l;
        let cn: Vector3<S> = self.props.cn.map(c);
        let cm: Vector3<S> = self.props.cm.map(c);
        let n = gamma.component_mul(&cn);
        let m = kappa.component_mul(&cm);
        let force = rotation::mv(&lam_m, &n);
        let g = n.cross(&a);
        let p = m + rotation::mtv(&rotation::tangent(&half), &g) * c::<S>(0.5);
        let qv = rotation::mtv(&rotation::tangent_inv(&psi), &p);
        let f1 = rotation::mv(&e, &g) - rotation::mv(&q, &qv);
        let (m1, m2) = (rotation::mv(&l0, &f1), rotation::mv(&l0, &qv));
        Kernel {
            f: [-force, m1, force, m2],
            gamma,
            kappa,
        }
    }

    /// Internal force vector `[f_x1, f_Θ1, f_x2, f_Θ2]` at the nodes' state.
    pub fn internal_forces(&self, s1: &NodeState, s2: &NodeState) -> [Vector3<f64>; 4] {
        self.kernel(s1.x, s2.x, s1.r, s2.r).f
    }

    /// Strains `Γ` and curvatures `K` at the midpoint.
    pub fn strains(&self, s1: &NodeState, s2: &NodeState) -> (Vector3<f64>, Vector3<f64>) {
        let k = self.kernel(s1.x, s2.x, s1.r, s2.r);
        (k.gamma, k.kappa)
    }

    /// Internal forces and their exact derivative with respect to `[δx₁, δΘ₁, δx₂, δΘ₂]`,
    /// by forward-mode AD with 6 dual directions (`δx₂`, `δΘ₁`) and the element's two
    /// invariances for the other six columns:
    /// - translation: the kernel sees the positions only through `x₂ − x₁`, so
    ///   `∂f/∂x₁ = −∂f/∂x₂`;
    /// - rotation (objectivity): a superposed rotation `δφ` moves `δx_i = δφ × x_i`,
    ///   `δΘ_i = R_iᵀ δφ` and changes `f` by `G δφ` (the global forces `∓F` turn,
    ///   `G = [F̃; 0; −F̃; 0]`, the material moments do not), so
    ///   `A₂ (x̃₁ − x̃₂) + B₁ R₁ᵀ + B₂ R₂ᵀ = G` with `A_i = ∂f/∂x_i`, `B_i = ∂f/∂Θ_i`,
    ///   which gives `B₂ = (G − A₂ (x̃₁ − x̃₂) − B₁ R₁ᵀ) R₂`.
    fn internal_with_tangent(&self, s1: &NodeState, s2: &NodeState, out: &mut Local) {
        type D = Dual<6>;
        let seed = |v: f64, k: usize| D::var(v, k);
        let lift = D::constant;
        // R₁ (I + δΘ̃₁): exact to first order, which is all a dual number carries.
        let dth = Vector3::new(seed(0.0, 3), seed(0.0, 4), seed(0.0, 5));
        let r1: Matrix3<D> = s1.r.map(lift);
        let r1 = r1 + rotation::mm(&r1, &skew(&dth));
        let x1 = s1.x.map(lift);
        let x2 = Vector3::new(seed(s2.x.x, 0), seed(s2.x.y, 1), seed(s2.x.z, 2));
        let k = self.kernel(x1, x2, r1, s2.r.map(lift));
        let force = Vector3::new(k.f[2].x.re, k.f[2].y.re, k.f[2].z.re);
        let g = skew(&force);
        let dx = skew(&(s1.x - s2.x));
        let r1t = s1.r.transpose();
        let n = out.n;
        for (blk, v) in k.f.iter().enumerate() {
            // Rows 3·blk.. of A₂ and B₁, as 3×3 blocks.
            let a2 = Matrix3::from_fn(|r, c| v[r].eps[c]);
            let b1 = Matrix3::from_fn(|r, c| v[r].eps[c + 3]);
            let gb = match blk {
                0 => g,
                2 => -g,
                _ => Matrix3::zeros(),
            };
            let b2 = (gb - a2 * dx - b1 * r1t) * s2.r;
            for r in 0..3 {
                let row = 3 * blk + r;
                out.res[row] += v[r].re;
                for c in 0..3 {
                    out.tan[c * n + row] -= a2[(r, c)]; // x₁
                    out.tan[(c + 3) * n + row] += b1[(r, c)]; // Θ₁
                    out.tan[(c + 6) * n + row] += a2[(r, c)]; // x₂
                    out.tan[(c + 9) * n + row] += b2[(r, c)]; // Θ₂
                }
            }
        }
    }

    fn translational_mass(&self) -> f64 {
        self.props.mass * self.length
    }
}

impl Element for Beam {
    fn id(&self) -> ElementId {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn turns_with_its_nodes(&self) -> bool {
        true
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        let s1 = &nodes[self.nodes[0]];
        let s2 = &nodes[self.nodes[1]];
        if tangent {
            self.internal_with_tangent(s1, s2, out);
        } else {
            let f = self.internal_forces(s1, s2);
            for (k, v) in f.iter().enumerate() {
                out.add_res(3 * k, v);
            }
        }
        let m = self.translational_mass();
        // Gravity (external: enters with a minus sign).
        let wg = ctx.gravity * (0.5 * m);
        out.add_res(tx(0), &-wg);
        out.add_res(tx(1), &-wg);
        if ctx.dynamic {
            let (a1, a2) = (s1.a, s2.a);
            out.add_res(tx(0), &((a1 * 2.0 + a2) * (m / 6.0)));
            out.add_res(tx(1), &((a1 + a2 * 2.0) * (m / 6.0)));
            for (k, s) in [s1, s2].into_iter().enumerate() {
                let jw = self.j_node * s.w;
                out.add_res(rx(k), &(self.j_node * s.wd + s.w.cross(&jw)));
            }
            if tangent {
                let i = Matrix3::identity();
                let m2 = i * (ctx.c_a * m / 3.0);
                let m1 = i * (ctx.c_a * m / 6.0);
                out.add_rate_block(tx(0), tx(0), &m2);
                out.add_rate_block(tx(1), tx(1), &m2);
                out.add_rate_block(tx(0), tx(1), &m1);
                out.add_rate_block(tx(1), tx(0), &m1);
                for (k, s) in [s1, s2].into_iter().enumerate() {
                    let gyro = skew(&s.w) * self.j_node - skew(&(self.j_node * s.w));
                    out.add_rate_block(rx(k), rx(k), &(self.j_node * ctx.c_a + gyro * ctx.c_v));
                }
            }
        }
    }

    fn force_scale(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> f64 {
        // Squared norms, one square root.
        let m = 0.5 * self.translational_mass();
        let mut f2 = m * m * gravity.norm_squared();
        for &i in &self.nodes {
            let s = &nodes[i];
            f2 = f2
                .max(m * m * s.a.norm_squared())
                .max((self.j_node * s.wd).norm_squared())
                .max(s.w.cross(&(self.j_node * s.w)).norm_squared());
        }
        f2.sqrt()
    }

    fn energies(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> Energies {
        let s1 = &nodes[self.nodes[0]];
        let s2 = &nodes[self.nodes[1]];
        let (gamma, kappa) = self.strains(s1, s2);
        let strain = 0.5
            * self.length
            * (gamma.component_mul(&self.props.cn).dot(&gamma)
                + kappa.component_mul(&self.props.cm).dot(&kappa));
        let m = self.translational_mass();
        let kinetic = m / 6.0 * (s1.v.dot(&s1.v) + s1.v.dot(&s2.v) + s2.v.dot(&s2.v))
            + 0.5 * s1.w.dot(&(self.j_node * s1.w))
            + 0.5 * s2.w.dot(&(self.j_node * s2.w));
        let gravity = -0.5 * m * gravity.dot(&(s1.x + s2.x));
        Energies {
            kinetic,
            strain,
            gravity,
        }
    }

    fn output_header(&self) -> Vec<String> {
        [
            "n1", "n2", "n3", "m1", "m2", "m3", "gamma1", "gamma2", "gamma3", "k1", "k2", "k3",
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
        let (g, k) = self.strains(&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let n = g.component_mul(&self.props.cn);
        let m = k.component_mul(&self.props.cm);
        for v in [n, m, g, k] {
            row.extend_from_slice(v.as_slice());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::*;

    fn steel_props() -> BeamProperties {
        let (e, g, a, i, j, rho) = (2.1e11, 2.1e11 / 2.6, 9e-4, 8.3e-8, 4.15e-8, 7800.0);
        BeamProperties {
            cn: Vector3::new(e * a, 5.0 / 6.0 * g * a, 5.0 / 6.0 * g * a),
            cm: Vector3::new(g * j, e * i, e * i),
            mass: rho * a,
            inertia: Vector3::new(rho * 2.0 * i, rho * i, rho * i),
        }
    }

    fn beam(x1: Vector3<f64>, x2: Vector3<f64>) -> Beam {
        Beam::new(ElementId(1), [0, 1], &x1, &x2, None, steel_props())
    }

    #[test]
    fn tangent_matches_finite_differences_static_and_dynamic() {
        let x0 = [Vector3::new(0.1, 0.2, -0.1), Vector3::new(0.3, 0.25, 0.0)];
        let b = beam(x0[0], x0[1]);
        for seed in 1..6 {
            // Large rotations (up to ~1.5 rad per node) and stretches of a few per cent.
            let st = random_states(&x0, 0.01, 0.9, seed);
            check_tangent(&b, &static_ctx(), &st, &[], 2e-7);
            check_tangent(&b, &dyn_ctx(), &st, &[], 2e-7);
        }
    }

    #[test]
    fn internal_forces_are_the_gradient_of_the_strain_energy() {
        let x0 = [Vector3::new(0.0, 0.1, 0.0), Vector3::new(0.2, 0.1, 0.1)];
        let b = beam(x0[0], x0[1]);
        let st = random_states(&x0, 0.003, 0.5, 11);
        let f = b.internal_forces(&st[0], &st[1]);
        let energy = |s: &[NodeState]| b.energies(s, &Vector3::zeros()).strain;
        let eps = 1e-7;
        let fmax = f.iter().map(|v| v.norm()).fold(0.0, f64::max);
        for dir in 0..12 {
            let mut e = Vector3::zeros();
            e[dir % 3] = eps;
            let (mut p, mut m) = (st.clone(), st.clone());
            let k = dir / 6;
            if dir % 6 < 3 {
                p[k].x += e;
                m[k].x -= e;
            } else {
                p[k].r *= rotation::exp(&e);
                m[k].r *= rotation::exp(&-e);
            }
            let fd = (energy(&p) - energy(&m)) / (2.0 * eps);
            let an = f[dir / 3][dir % 3];
            assert!((fd - an).abs() < 1e-6 * fmax, "dof {dir}: {an} vs {fd}");
        }
    }

    #[test]
    fn rigid_motion_gives_zero_strain_and_zero_force() {
        let x0 = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(0.1, 0.05, 0.02)];
        let b = beam(x0[0], x0[1]);
        let rest = [NodeState::at_rest(x0[0]), NodeState::at_rest(x0[1])];
        let q = rotation::exp(&Vector3::new(2.0, -1.0, 2.5)); // |Φ| ≈ 3.35 rad > π
        let moved = rigidly_moved(&rest, &q, &Vector3::new(1.0, -2.0, 3.0));
        let (g, k) = b.strains(&moved[0], &moved[1]);
        assert!(g.norm() < 1e-14 && k.norm() < 1e-14, "{g} {k}");
        let f = b.internal_forces(&moved[0], &moved[1]);
        let fmax = f.iter().map(|v| v.norm()).fold(0.0, f64::max);
        // Relative to the force of a unit axial strain EA:
        assert!(fmax < 1e-12 * steel_props().cn.x, "{fmax}");
    }

    #[test]
    fn rigid_rotation_rotates_internal_forces() {
        let x0 = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(0.1, 0.0, 0.0)];
        let b = beam(x0[0], x0[1]);
        let st = random_states(&x0, 0.002, 0.3, 7);
        let q = rotation::exp(&Vector3::new(-0.4, 1.3, 0.8));
        let moved = rigidly_moved(&st, &q, &Vector3::new(0.3, 0.2, 0.1));
        let f0 = b.internal_forces(&st[0], &st[1]);
        let f1 = b.internal_forces(&moved[0], &moved[1]);
        let scale = f0.iter().map(|v| v.norm()).fold(0.0, f64::max);
        // Forces are global (rotate with Q); moments are material (unchanged).
        for k in [0, 2] {
            assert!((f1[k] - q * f0[k]).norm() < 1e-9 * scale);
        }
        for k in [1, 3] {
            assert!((f1[k] - f0[k]).norm() < 1e-9 * scale);
        }
    }

    #[test]
    fn pure_bending_curvature_is_exact() {
        // Nodes rotated about local axis 3 by ±θ/2 around a circular arc: K₃ = θ/L.
        let l = 0.2;
        let b = beam(Vector3::zeros(), Vector3::new(l, 0.0, 0.0));
        let theta = 0.3;
        let r = l / theta; // arc radius, chord = 2 r sin(θ/2)
        let s1 = NodeState::at_rest(Vector3::zeros());
        let mut s2 =
            NodeState::at_rest(Vector3::new(r * theta.sin(), r * (1.0 - theta.cos()), 0.0));
        s2.r = rotation::exp(&Vector3::new(0.0, 0.0, theta));
        let (g, k) = b.strains(&s1, &s2);
        assert!((k.z - theta / l).abs() < 1e-12);
        // Midpoint-chord strain of an arc: chord/L·(1/cos 0)… axial strain = 2 sin(θ/2)/θ − 1.
        assert!(
            (g.x - (2.0 * (theta / 2.0).sin() / theta - 1.0)).abs() < 1e-12,
            "{g}"
        );
        assert!(g.y.abs() < 1e-12);
    }
}
