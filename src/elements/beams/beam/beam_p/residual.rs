//! The residual path of [`BeamP`] (every Newton iteration): internal forces only, in `f64`,
//! with the Jacobian of the local numbers in closed form and one `sin`/`cos` per point.

use super::{BeamP, Point, t_coefficients};
use crate::elements::{Local, NodeState, rx, tx};
use nalgebra::Vector3;

/// `[a, b, d, b′, d′]`: `a = sin φ/φ` and the [`t_coefficients`] `b, d, b′, d′` of `x = φ²`,
/// from one `sin`/`cos` (f64 residual path); the same Taylor series below `x = 0.01`
/// (`a`: four terms, truncation `x⁴/9! < 3e-14`).
fn point_coefficients(x: f64) -> [f64; 5] {
    if x < 1e-2 {
        let (b, d, db, dd) = t_coefficients(x);
        let a = 1.0 - x / 6.0 + x * x / 120.0 - x * x * x / 5040.0;
        return [a, b, d, db, dd];
    }
    let f = x.sqrt();
    let (sn, cs) = f.sin_cos();
    let (oc, fs, x2) = (1.0 - cs, f - sn, x * x);
    [
        sn / f,
        oc / x,
        fs / (x * f),
        (f * sn - 2.0 * oc) / (2.0 * x2),
        (oc * f - 3.0 * fs) / (2.0 * x2 * f),
    ]
}

/// `T⁻ᵀ(ψ) g = g − ½ ψ × g + e ψ × (ψ × g)` with `e = (1 − (φ/2) cot(φ/2))/φ²`
/// ([`crate::rotation::tangent_inv`] applied by cross products; the same series below
/// `φ² = 0.01`), `cot_half = cot(φ/2)` from the node's quaternion
/// ([`crate::rotation::log_and_cot_half`], [`BeamP::locals`]).
fn tangent_inv_t(psi: &Vector3<f64>, cot_half: f64, g: &Vector3<f64>) -> Vector3<f64> {
    let p = psi.norm_squared();
    let e = if p < 1e-2 {
        1.0 / 12.0 + p / 720.0 + p * p / 30240.0 + p * p * p / 1209600.0
    } else {
        (1.0 - 0.5 * p.sqrt() * cot_half) / p
    };
    let pg = psi.cross(g);
    g - pg * 0.5 + psi.cross(&pg) * e
}

/// A point's strains in `f64` from its nine local numbers `(ψ, ψ_s, y_s)`, by cross
/// products with the coefficients of one `sin`/`cos` ([`point_coefficients`]):
/// `a = exp(ψ̃)ᵀ y_s` (`exp(ψ̃) = I + a ψ̃ + b ψ̃²`) and `T(ψ) ψ_s` (`T(ψ) = I − b ψ̃ + d ψ̃²`),
/// the `(Γ, K)` of [`super::point_strains`], with what the gradient reuses.
struct Strains {
    psi: Vector3<f64>,
    dpsi: Vector3<f64>,
    /// [`point_coefficients`] of `|ψ|²`.
    co: [f64; 5],
    /// `exp(ψ̃)ᵀ y_s`.
    gamma: Vector3<f64>,
    /// `ψ × ψ_s`, `ψ × (ψ × ψ_s)`.
    pv: Vector3<f64>,
    ppv: Vector3<f64>,
    /// `T(ψ) ψ_s`.
    kappa: Vector3<f64>,
}

/// `u + α ψ × u + β ψ × (ψ × u)`.
fn op(psi: &Vector3<f64>, al: f64, be: f64, u: &Vector3<f64>) -> Vector3<f64> {
    let pu = psi.cross(u);
    u + pu * al + psi.cross(&pu) * be
}

impl Strains {
    fn of(v: &[f64; 9]) -> Self {
        let at = |k: usize| Vector3::new(v[k], v[k + 1], v[k + 2]);
        let (psi, dpsi, dy) = (at(0), at(3), at(6));
        let co = point_coefficients(psi.norm_squared());
        let [a, b, d, _, _] = co;
        let pv = psi.cross(&dpsi);
        let ppv = psi.cross(&pv);
        Strains {
            gamma: op(&psi, -a, b, &dy),
            kappa: dpsi - pv * b + ppv * d,
            psi,
            dpsi,
            co,
            pv,
            ppv,
        }
    }
}

impl BeamP {
    /// [`Self::density`] in `f64` (the energy guard's strain energy at every step):
    /// `½ Γ·C_N Γ + ½ K·C_M K` from [`Strains`]. Equal to the generic path to round-off
    /// (tested).
    pub(super) fn density_f64(&self, q: &Point, v: &[f64; 9]) -> f64 {
        let s = Strains::of(v);
        let g = s.gamma - q.gamma0;
        let k = s.kappa - q.kappa0;
        0.5 * (g.component_mul(&self.props.cn).dot(&g) + k.component_mul(&self.props.cm).dot(&k))
    }

    /// [`Self::density_grad`] in `f64` for the residual path: the same formulas with
    /// `exp(ψ̃) = I + a ψ̃ + b ψ̃²`, `T(ψ) = I − b ψ̃ + d ψ̃²` applied as cross products and
    /// the coefficients `a, b, d, b′, d′` from one evaluation of `sin φ`, `cos φ`
    /// ([`point_coefficients`]). Equal to the generic path to round-off (tested).
    fn density_grad_f64(&self, q: &Point, v: &[f64; 9]) -> [f64; 9] {
        let s = Strains::of(v);
        let (psi, dpsi) = (&s.psi, &s.dpsi);
        let [a, b, d, db, dd] = s.co;
        let (av, pv, ppv) = (s.gamma, s.pv, s.ppv);
        let nn = (av - q.gamma0).component_mul(&self.props.cn);
        let mm = (s.kappa - q.kappa0).component_mul(&self.props.cm);
        let g_dy = op(psi, a, b, &nn);
        let g_dpsi = op(psi, b, d, &mm); // T(ψ)ᵀ M
        let g_psi = op(psi, b, d, &nn.cross(&av)) - psi * (2.0 * db * pv.dot(&mm))
            + mm.cross(dpsi) * b
            + psi * (2.0 * dd * ppv.dot(&mm))
            - (mm.cross(&pv) + mm.cross(psi).cross(dpsi)) * d;
        [
            g_psi.x, g_psi.y, g_psi.z, g_dpsi.x, g_dpsi.y, g_dpsi.z, g_dy.x, g_dy.y, g_dy.z,
        ]
    }

    /// Internal forces only (the residual path, evaluated at every Newton iteration): the
    /// chain rule of the module doc with the Jacobian of the local numbers in closed form,
    /// `∂yᵢ/∂xᵢ = Λᵣᵀ = −∂yᵢ/∂xᵣ`, `∂yᵢ/∂θᵣ = ỹᵢ Λ⁰ᵣᵀ`,
    /// `∂ψᵢ/∂θᵢ = T⁻¹(ψᵢ) Λ⁰ᵢᵀ`, `∂ψᵢ/∂θᵣ = −T⁻¹(ψᵢ) exp(ψ̃ᵢ)ᵀ Λ⁰ᵣᵀ`
    /// (from `exp(ψ̃ᵢ) = Λᵣᵀ Λᵢ`, `δ exp(ψ̃) = exp(ψ̃)(T(ψ) δψ)~`), and the gradient of each
    /// point's energy density `∂e/∂y_s = exp(ψ̃) N`, `∂e/∂ψ_s = T(ψ)ᵀ M`, `∂e/∂ψ` by a
    /// 3-direction dual number. Same numbers as the tangent path to round-off (tested).
    pub(super) fn internal_forces(&self, nodes: &[NodeState], out: &mut Local) {
        self.with_locals(nodes, |sc, n| {
            let m = self.refn;
            for g in sc.gz[..n].iter_mut() {
                *g = [0.0; 6];
            }
            for q in &self.stiff {
                let v = Self::point_vars(q, &sc.z[..n]);
                let at = |k: usize, v: &[f64; 9]| Vector3::new(v[k], v[k + 1], v[k + 2]);
                let g = self.density_grad_f64(q, &v);
                let (g_psi, g_dpsi, g_dy) = (at(0, &g) * q.wj, at(3, &g) * q.wj, at(6, &g) * q.wj);
                // Every node, the reference node's entry included (unused: its forces
                // follow from the others').
                for ((gz, &ni), &di) in sc.gz[..n].iter_mut().zip(&q.n).zip(&q.ds) {
                    for k in 0..3 {
                        gz[k] += di * g_dy[k];
                        gz[3 + k] += ni * g_psi[k] + di * g_dpsi[k];
                    }
                }
            }
            let sr = &nodes[self.nodes[m]];
            let lr = sr.r * self.lambda0[m];
            let l0r = &self.lambda0[m];
            let (mut fxr, mut fthr) = (Vector3::zeros(), Vector3::zeros());
            for i in (0..n).filter(|&i| i != m) {
                let z = &sc.z[i];
                let (y, psi) = (
                    Vector3::new(z[0], z[1], z[2]),
                    Vector3::new(z[3], z[4], z[5]),
                );
                let gy = Vector3::new(sc.gz[i][0], sc.gz[i][1], sc.gz[i][2]);
                let gp = Vector3::new(sc.gz[i][3], sc.gz[i][4], sc.gz[i][5]);
                let fx = lr * gy;
                let tig = tangent_inv_t(&psi, sc.cot[i], &gp);
                let fth = self.lambda0[i] * tig;
                fxr -= fx;
                fthr += l0r * (gy.cross(&y) - sc.rel[i] * tig);
                out.add_res(tx(i), &fx);
                out.add_res(rx(i), &fth);
            }
            out.add_res(tx(m), &fxr);
            out.add_res(rx(m), &fthr);
        })
    }
}
