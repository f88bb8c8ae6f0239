//! `BUSHING`: six uncoupled linear springs and dampers between two nodes, in a frame
//! fixed to node 1 (issue 25 §3; the "deformable joint" of MBDyn, Chrono's bushing).
//!
//! # Strains (objective)
//! With `Q = R₁ᵀR₂` and `d = x₂ − x₁`, both measured in node 1's material frame:
//! - relative displacement `u = R₁ᵀd − d₀` (`d₀ = x₂⁰ − x₁⁰`, so `u = 0` at t = 0);
//! - relative rotation `φ = log(Q)` ([`crate::rotation::log`], `|φ| ≤ π`).
//!
//! A rigid motion of the pair leaves both unchanged. The rotational part is linear in
//! `φ`: exact for a rotation about one bushing axis, and for a general rotation the
//! stiffness is that of the rotation vector — the small-rotation bushing (`|φ|` of a few
//! degrees to tens of degrees; no whole turns: `φ` wraps at π).
//!
//! Rates: `u̇ = R₁ᵀ(ẋ₂ − ẋ₁) + (R₁ᵀd) × Ω₁` and `φ̇ = T⁻¹(φ)(Ω₂ − QᵀΩ₁)` (material tangent
//! operator of `rotation.rs`, `Qᵀ δQ = (T(φ) δφ)~`); their Jacobians are those of the
//! variations `δu`, `δφ`, so with `y = (u, φ)` and `J = ∂y/∂q` the generalized force is
//! `Jᵀ(K y + C ẏ)` with `K = diag` in the bushing axes `E`: `K_u = E diag(k_x, k_y, k_z) Eᵀ`,
//! `K_φ = E diag(k_rx, k_ry, k_rz) Eᵀ`, likewise `C` — Hooke's law and Rayleigh's
//! dissipation function `½ ẏᵀCẏ`. Written out (material spins):
//!
//! `f = K_u u + C_u u̇`, `m = K_φ φ + C_φ φ̇`,
//! `r_x₁ = −R₁f`, `r_x₂ = R₁f`, `r_Θ₁ = f × R₁ᵀd − Q T⁻ᵀ m`, `r_Θ₂ = T⁻ᵀ m`.
//!
//! The iteration matrix is the exact derivative of this, by dual numbers ([`Dual<12>`]
//! seeding `xᵢ + ε`, `Rᵢ(I + ε̃)` for the stiffness, and the velocities for `c_v ∂r/∂v`).
//!
//! Energy: `U = ½ uᵀK_u u + ½ φᵀK_φ φ`; dissipated power `ẏᵀCẏ`.

use crate::dual::{Dual, Real};
use crate::elements::registry::Kind;
use crate::elements::{Element, Energies, EvalContext, Local, NodeState, rx, tx};
use crate::model::{BushingData, ElementId};
use crate::rotation::{self, c, mm, mtm, mtv, mv, skew};
use nalgebra::{Matrix3, Vector3};

type D12 = Dual<12>;

/// The element half of `BUSHING` (`crate::kinds`): built by [`super::from_model`].
pub const KIND: Kind = Kind {
    types: &["BUSHING"],
    build: super::from_model,
};

/// A BUSHING element (see the module docs).
#[derive(Debug, Clone)]
pub struct Bushing {
    id: ElementId,
    nodes: [usize; 2],
    /// `d₀`, node 1's frame, m.
    d0: Vector3<f64>,
    /// The axes `E` (columns).
    axes: Matrix3<f64>,
    k_u: Matrix3<f64>,
    k_r: Matrix3<f64>,
    c_u: Matrix3<f64>,
    c_r: Matrix3<f64>,
    damped: bool,
}

/// The strains and their conjugate forces at a state.
struct Strains<S> {
    u: Vector3<S>,
    phi: Vector3<S>,
    f: Vector3<S>,
    m: Vector3<S>,
    /// `(u̇, φ̇)`.
    rates: (Vector3<S>, Vector3<S>),
    /// The generalized force `[x₁, Θ₁, x₂, Θ₂]`.
    g: [Vector3<S>; 4],
}

fn cross<S: Real>(a: &Vector3<S>, b: &Vector3<S>) -> Vector3<S> {
    mv(&skew(a), b)
}

impl Bushing {
    /// A bushing on dense nodes `nodes` with reference positions `x0`.
    pub fn new(
        id: ElementId,
        nodes: [usize; 2],
        x0: [Vector3<f64>; 2],
        data: &BushingData,
    ) -> Self {
        let e = data.axes;
        let diag =
            |v: &[f64]| e * Matrix3::from_diagonal(&Vector3::new(v[0], v[1], v[2])) * e.transpose();
        Bushing {
            id,
            nodes,
            d0: x0[1] - x0[0],
            axes: e,
            k_u: diag(&data.stiffness[..3]),
            k_r: diag(&data.stiffness[3..]),
            c_u: diag(&data.damping[..3]),
            c_r: diag(&data.damping[3..]),
            damped: data.damping.iter().any(|v| *v != 0.0),
        }
    }

    /// Strains, rates and the generalized force (module docs), generic in the scalar.
    #[allow(clippy::too_many_arguments)]
    fn strains<S: Real>(
        &self,
        x1: &Vector3<S>,
        r1: &Matrix3<S>,
        x2: &Vector3<S>,
        r2: &Matrix3<S>,
        v1: &Vector3<S>,
        w1: &Vector3<S>,
        v2: &Vector3<S>,
        w2: &Vector3<S>,
    ) -> Strains<S> {
        let k = |m: &Matrix3<f64>| -> Matrix3<S> { m.map(c) };
        let d = x2 - x1;
        let dl = mtv(r1, &d);
        let u = dl - self.d0.map(c);
        let q = mtm(r1, r2);
        let phi = rotation::log(&q);
        let ti = rotation::tangent_inv(&phi);
        let ud = mtv(r1, &(v2 - v1)) + cross(&dl, w1);
        let pd = mv(&ti, &(w2 - mtv(&q, w1)));
        let f = mv(&k(&self.k_u), &u) + mv(&k(&self.c_u), &ud);
        let m = mv(&k(&self.k_r), &phi) + mv(&k(&self.c_r), &pd);
        let tm = mtv(&ti, &m);
        let rf = mv(r1, &f);
        let g = [-rf, cross(&f, &dl) - mv(&q, &tm), rf, tm];
        Strains {
            u,
            phi,
            f,
            m,
            rates: (ud, pd),
            g,
        }
    }

    fn at(&self, nodes: &[NodeState]) -> Strains<f64> {
        let (a, b) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        self.strains(&a.x, &a.r, &b.x, &b.r, &a.v, &a.w, &b.v, &b.w)
    }
}

/// Local index of block `i` of `[x₁, Θ₁, x₂, Θ₂]`.
fn block(i: usize) -> usize {
    [tx(0), rx(0), tx(1), rx(1)][i]
}

impl Element for Bushing {
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
        let s = self.at(nodes);
        for (i, g) in s.g.iter().enumerate() {
            out.add_res(block(i), g);
        }
        if !tangent {
            return;
        }
        let (a, b) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let var = |v: &Vector3<f64>, base: usize, seed: bool| {
            Vector3::from_fn(|i, _| {
                if seed {
                    D12::var(v[i], base + i)
                } else {
                    D12::constant(v[i])
                }
            })
        };
        let rot = |r: &Matrix3<f64>, base: usize, seed: bool| {
            let rr: Matrix3<D12> = r.map(D12::constant);
            if !seed {
                return rr;
            }
            // R (I + δΘ̃): exact to first order, which is all a dual number carries.
            rr + mm(&rr, &skew(&var(&Vector3::zeros(), base, true)))
        };
        // Stiffness: seeds on positions and rotations, velocities held.
        let g = self
            .strains(
                &var(&a.x, 0, true),
                &rot(&a.r, 3, true),
                &var(&b.x, 6, true),
                &rot(&b.r, 9, true),
                &var(&a.v, 0, false),
                &var(&a.w, 0, false),
                &var(&b.v, 0, false),
                &var(&b.w, 0, false),
            )
            .g;
        let jac = |g: &[Vector3<D12>; 4], bi: usize, bj: usize, scale: f64| {
            Matrix3::from_fn(|r, col| g[bi][r].eps[3 * bj + col] * scale)
        };
        for bi in 0..4 {
            for bj in 0..4 {
                out.add_block(block(bi), block(bj), &jac(&g, bi, bj, 1.0));
            }
        }
        if !self.damped || ctx.c_v == 0.0 {
            return;
        }
        // Damping: seeds on the velocities (the force is linear in them).
        let g = self
            .strains(
                &var(&a.x, 0, false),
                &rot(&a.r, 0, false),
                &var(&b.x, 0, false),
                &rot(&b.r, 0, false),
                &var(&a.v, 0, true),
                &var(&a.w, 3, true),
                &var(&b.v, 6, true),
                &var(&b.w, 9, true),
            )
            .g;
        for bi in 0..4 {
            for bj in 0..4 {
                out.add_rate_block(block(bi), block(bj), &jac(&g, bi, bj, ctx.c_v));
            }
        }
    }

    fn energies(&self, nodes: &[NodeState], _gravity: &Vector3<f64>) -> Energies {
        let s = self.at(nodes);
        Energies {
            strain: 0.5 * (s.u.dot(&(self.k_u * s.u)) + s.phi.dot(&(self.k_r * s.phi))),
            ..Energies::default()
        }
    }

    fn dissipated_power(&self, nodes: &[NodeState]) -> f64 {
        if !self.damped {
            return 0.0;
        }
        let (ud, pd) = self.at(nodes).rates;
        ud.dot(&(self.c_u * ud)) + pd.dot(&(self.c_r * pd))
    }

    fn force_scale(&self, nodes: &[NodeState], _gravity: &Vector3<f64>) -> f64 {
        let s = self.at(nodes);
        s.f.norm().max(s.m.norm())
    }

    fn output_header(&self) -> Vec<String> {
        [
            "ux", "uy", "uz", "rx", "ry", "rz", "fx", "fy", "fz", "mx", "my", "mz",
        ]
        .map(String::from)
        .to_vec()
    }

    /// `u`, `φ` and the force and moment the bushing exerts on node 2 (`−f`, `−m`), all
    /// in the bushing axes.
    fn write_output_row(
        &self,
        _ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        let s = self.at(nodes);
        let e = self.axes.transpose();
        for v in [e * s.u, e * s.phi, -(e * s.f), -(e * s.m)] {
            row.extend(v.iter());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::*;
    use crate::model::BushingData;

    fn bushing(d0: Vector3<f64>) -> Bushing {
        let e1 = Vector3::new(1.0, 1.0, 0.0).normalize();
        let e3 = Vector3::new(0.0, 0.0, 1.0);
        let data = BushingData {
            stiffness: [1e3, 2e3, 3e3, 40.0, 50.0, 60.0],
            damping: [5.0, 6.0, 7.0, 0.8, 0.9, 1.0],
            axes: Matrix3::from_columns(&[e1, e3.cross(&e1), e3]),
        };
        Bushing::new(ElementId(1), [0, 1], [Vector3::zeros(), d0], &data)
    }

    /// The iteration matrix against central differences of the residual (dynamic context:
    /// stiffness and c_v × damping; rotations up to 0.4 rad), for coincident and offset
    /// nodes. Tolerance 1e-6 of the largest entry: central differences with ε = 1e-6 err by
    /// O(ε²) in truncation and O(1e-16/ε) = 1e-10 relative in round-off.
    #[test]
    fn tangent_matches_finite_differences() {
        for (k, d0) in [Vector3::zeros(), Vector3::new(0.3, -0.2, 0.5)]
            .into_iter()
            .enumerate()
        {
            let b = bushing(d0);
            let st = random_states(&[Vector3::zeros(), d0], 0.05, 0.4, 11 + k as u64);
            check_tangent(&b, &dyn_ctx(), &st, &[], 1e-6);
            check_tangent(&b, &static_ctx(), &st, &[], 1e-6);
        }
    }

    /// Objectivity: a rigid motion of the pair rotates the nodal forces and leaves the
    /// material moments, the energy and the dissipation unchanged.
    #[test]
    fn objective() {
        let d0 = Vector3::new(0.3, -0.2, 0.5);
        let b = bushing(d0);
        let st = random_states(&[Vector3::zeros(), d0], 0.05, 0.4, 5);
        check_objectivity(&b, &dyn_ctx(), &st, 1e-10);
        let q = rotation::exp(&Vector3::new(0.7, -1.1, 0.4));
        let moved = rigidly_moved(&st, &q, &Vector3::new(1.0, 2.0, 3.0));
        let g = Vector3::zeros();
        let (e0, e1) = (b.energies(&st, &g).strain, b.energies(&moved, &g).strain);
        assert!((e0 - e1).abs() <= 1e-12 * e0.abs());
        let (p0, p1) = (b.dissipated_power(&st), b.dissipated_power(&moved));
        assert!((p0 - p1).abs() <= 1e-12 * p0.abs());
    }

    /// The closed forms of single-component motions: a translation along bushing axis 1
    /// by a gives the force −k_x a along it; a rotation θ about axis 3 gives the moment
    /// −k_rz θ about it (exact for one axis: log of a rotation about a fixed axis); and
    /// the strain energies ½k a², ½k_rz θ².
    #[test]
    fn single_axis_closed_forms() {
        let b = bushing(Vector3::zeros());
        let e = b.axes;
        let mut st = vec![NodeState::at_rest(Vector3::zeros()); 2];
        let a = 0.01;
        st[1].x = e.column(0) * a;
        let row = b.output_row(&dyn_ctx(), &st, &[]);
        assert!(
            (row[0] - a).abs() < 1e-15 && (row[6] + 1e3 * a).abs() < 1e-12,
            "{row:?}"
        );
        assert!(row[7].abs() < 1e-12 && row[8].abs() < 1e-12);
        let u = b.energies(&st, &Vector3::zeros()).strain;
        assert!((u - 0.5 * 1e3 * a * a).abs() < 1e-15);
        let th = 0.3;
        let mut st = vec![NodeState::at_rest(Vector3::zeros()); 2];
        st[1].r = rotation::exp(&(e.column(2) * th));
        let row = b.output_row(&dyn_ctx(), &st, &[]);
        assert!((row[5] - th).abs() < 1e-14 && (row[11] + 60.0 * th).abs() < 1e-12);
        let u = b.energies(&st, &Vector3::zeros()).strain;
        assert!((u - 0.5 * 60.0 * th * th).abs() < 1e-13);
    }
}
