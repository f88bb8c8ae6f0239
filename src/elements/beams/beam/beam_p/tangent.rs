//! The tangent path of [`BeamP`]: internal forces and their exact derivative, evaluated when
//! the iteration matrix is rebuilt (module doc of [`super`]: `∇²U = Zᵀ ∇²Ũ Z + Σₐ (∇Ũ)ₐ ∇²zₐ`
//! plus the Baker–Campbell–Hausdorff term).

use super::BeamP;
use crate::dual::{Dual, Real};
use crate::elements::{Local, NodeState, rx};
use crate::rotation::{self, c, skew};
use nalgebra::{Matrix3, SMatrix, Vector3};

/// `zᵢ = (yᵢ, ψᵢ)` of a node against the reference node, generic in the scalar: node `i` at
/// `x`, `R exp(θ̃) Λ⁰`, the reference node at `x_r`, `R_r exp(θ̃_r) Λ⁰_r`; `shift = 2πk`
/// selects the branch of the logarithm.
#[allow(clippy::too_many_arguments)]
fn local_vars<S: Real>(
    x: &Vector3<S>,
    th: &Vector3<S>,
    xr: &Vector3<S>,
    thr: &Vector3<S>,
    r: &Matrix3<f64>,
    rr: &Matrix3<f64>,
    l0: &Matrix3<f64>,
    l0r: &Matrix3<f64>,
    shift: f64,
) -> [S; 6] {
    let li = rotation::mm(&rotation::mm(&r.map(c), &rotation::exp(th)), &l0.map(c));
    let lr = rotation::mm(&rotation::mm(&rr.map(c), &rotation::exp(thr)), &l0r.map(c));
    let mut psi = rotation::log(&rotation::mtm(&lr, &li));
    if shift != 0.0 {
        let n = psi.dot(&psi).sqrt();
        psi *= S::one() + c::<S>(shift) / n;
    }
    let y = rotation::mtv(&lr, &(x - xr));
    [y.x, y.y, y.z, psi.x, psi.y, psi.z]
}

impl BeamP {
    /// Internal forces (node-by-node `[f_x, f_Θ]`, `Θ` material) into `out.res` and their
    /// exact derivative into `out.tan` (module doc of [`super`]).
    pub(super) fn internal_tangent(&self, nodes: &[NodeState], out: &mut Local) {
        self.with_locals(nodes, |sc, n| {
            let m = self.refn;
            // Jacobians of the local numbers of every node but the reference, columns
            // (xᵢ, θᵢ, xᵣ, θᵣ), in closed form (see `internal_forces`; ψ does not depend on positions).
            let sr = &nodes[self.nodes[m]];
            let lr = sr.r * self.lambda0[m];
            let l0r = &self.lambda0[m];
            for k in (0..n).filter(|&k| k != m) {
                let l0 = &self.lambda0[k];
                let z = &sc.z[k];
                let (y, psi) = (
                    Vector3::new(z[0], z[1], z[2]),
                    Vector3::new(z[3], z[4], z[5]),
                );
                let ti = rotation::tangent_inv(&psi);
                let dk = ti * l0.transpose();
                let dr = -(ti * rotation::exp(&psi).transpose() * l0r.transpose());
                let jac = &mut sc.jac[k];
                *jac = SMatrix::zeros();
                let yr = skew(&y) * l0r.transpose();
                for r in 0..3 {
                    for c in 0..3 {
                        jac[(r, c)] = lr[(c, r)];
                        jac[(r, 6 + c)] = -lr[(c, r)];
                        jac[(r, 9 + c)] = yr[(r, c)];
                        jac[(3 + r, 3 + c)] = dk[(r, c)];
                        jac[(3 + r, 9 + c)] = dr[(r, c)];
                    }
                }
            }
            // Gradient (and Hessian) of Ũ in the local numbers.
            for g in sc.gz[..n].iter_mut() {
                *g = [0.0; 6];
            }
            for h in sc.ht[..n * n].iter_mut() {
                *h = SMatrix::zeros();
            }
            for q in &self.stiff {
                let v = Self::point_vars(q, &sc.z[..n]);
                let vars: [Dual<9>; 9] = std::array::from_fn(|k| Dual::var(v[k], k));
                let gd = self.density_grad(q, &vars);
                let grad: [f64; 9] = std::array::from_fn(|k| gd[k].re);
                let h = SMatrix::<f64, 9, 9>::from_fn(|r, c| gd[r].eps[c]);
                for i in (0..n).filter(|&i| i != m) {
                    for a in 0..3 {
                        sc.gz[i][a] += q.wj * q.ds[i] * grad[6 + a];
                        sc.gz[i][3 + a] += q.wj * (q.n[i] * grad[a] + q.ds[i] * grad[3 + a]);
                    }
                }
                {
                    // hp_j = h P_j (9×6), then H̃_ij += wJ P_iᵀ hp_j (column-major slices:
                    // h[c·9 + r], hp[c·9 + r], H̃[c·6 + r]).
                    let hs = h.as_slice();
                    for j in (0..n).filter(|&j| j != m) {
                        let (dj, nj) = (q.ds[j], q.n[j]);
                        let hp = sc.hp[j].as_mut_slice();
                        for a in 0..3 {
                            let (cy, cp, cs) = (
                                &hs[(6 + a) * 9..][..9],
                                &hs[a * 9..][..9],
                                &hs[(3 + a) * 9..][..9],
                            );
                            for r in 0..9 {
                                hp[a * 9 + r] = dj * cy[r];
                                hp[(3 + a) * 9 + r] = nj * cp[r] + dj * cs[r];
                            }
                        }
                    }
                    // H̃ is symmetric: the blocks j ≥ i here, the others mirrored below.
                    for i in (0..n).filter(|&i| i != m) {
                        let (wd, wn) = (q.wj * q.ds[i], q.wj * q.n[i]);
                        for j in (i..n).filter(|&j| j != m) {
                            let hp = sc.hp[j].as_slice();
                            let ht = sc.ht[i * n + j].as_mut_slice();
                            for col in 0..6 {
                                let (h, t) = (&hp[col * 9..][..9], &mut ht[col * 6..][..6]);
                                for a in 0..3 {
                                    t[a] += wd * h[6 + a];
                                    t[3 + a] += wn * h[a] + wd * h[3 + a];
                                }
                            }
                        }
                    }
                }
            }
            for i in 0..n {
                for j in 0..i {
                    sc.ht[i * n + j] = sc.ht[j * n + i].transpose();
                }
            }
            // Forces f = Zᵀ ∇Ũ: node k's columns 0..6 of its Jacobian, the reference node's 6..12.
            for f in sc.force[..n].iter_mut() {
                *f = [0.0; 6];
            }
            for k in (0..n).filter(|&k| k != m) {
                for col in 0..12 {
                    let v: f64 = (0..6).map(|a| sc.jac[k][(a, col)] * sc.gz[k][a]).sum();
                    let node = if col < 6 { k } else { m };
                    sc.force[node][col % 6] += v;
                }
            }
            for (k, f) in sc.force[..n].iter().enumerate() {
                for a in 0..6 {
                    out.res[6 * k + a] += f[a];
                }
            }
            let nl = out.n;
            let loc = |k: usize, col: usize| {
                if col < 6 {
                    6 * k + col
                } else {
                    6 * m + col - 6
                }
            };
            // Zᵀ H̃ Z by 3×3 blocks. Node i's Jacobian is Zᵢ = [Aᵢ | Cᵢ] (its own columns, the
            // reference node's) with Aᵢ = diag(P, Dᵢ), Cᵢ = [−P Yᵢ; 0 Eᵢ] (P = Λᵣᵀ for every
            // node, Dᵢ = ∂ψᵢ/∂θᵢ, Yᵢ = ∂yᵢ/∂θᵣ, Eᵢ = ∂ψᵢ/∂θᵣ): block (i, j) is Aᵢᵀ H̃ᵢⱼ Aⱼ,
            // (r, j) Σᵢ Cᵢᵀ H̃ᵢⱼ Aⱼ, (i, r) Σⱼ Aᵢᵀ H̃ᵢⱼ Cⱼ, (r, r) Σᵢⱼ Cᵢᵀ H̃ᵢⱼ Cⱼ; the zero
            // and repeated blocks of A and C halve the work of 6×6 products.
            type M3 = Matrix3<f64>;
            let add3 = |tan: &mut [f64], a: usize, b: usize, blk: &M3| {
                for c in 0..3 {
                    let col = &mut tan[(b + c) * nl + a..][..3];
                    for (t, v) in col.iter_mut().zip(blk.column(c).iter()) {
                        *t += v;
                    }
                }
            };
            let blocks = |k: usize| -> (M3, M3, M3) {
                let z = &sc.jac[k];
                (
                    z.fixed_view::<3, 3>(3, 3).into_owned(),
                    z.fixed_view::<3, 3>(0, 9).into_owned(),
                    z.fixed_view::<3, 3>(3, 9).into_owned(),
                )
            };
            let (p, pt) = (lr.transpose(), lr);
            let (mx, mt) = (6 * m, 6 * m + 3);
            for i in (0..n).filter(|&i| i != m) {
                let (di, yi, ei) = blocks(i);
                let (dit, yit, eit) = (di.transpose(), yi.transpose(), ei.transpose());
                let (ix, it) = (6 * i, 6 * i + 3);
                // Σⱼ H̃ᵢⱼ Cⱼ by blocks: [r11 r12; r21 r22].
                let (mut r11, mut r12, mut r21, mut r22) =
                    (M3::zeros(), M3::zeros(), M3::zeros(), M3::zeros());
                for j in (0..n).filter(|&j| j != m) {
                    let (dj, yj, ej) = blocks(j);
                    let h = &sc.ht[i * n + j];
                    let h11: M3 = h.fixed_view::<3, 3>(0, 0).into_owned();
                    let h12: M3 = h.fixed_view::<3, 3>(0, 3).into_owned();
                    let h21: M3 = h.fixed_view::<3, 3>(3, 0).into_owned();
                    let h22: M3 = h.fixed_view::<3, 3>(3, 3).into_owned();
                    // W = H̃ᵢⱼ Aⱼ.
                    let (w11, w12, w21, w22) = (h11 * p, h12 * dj, h21 * p, h22 * dj);
                    let (a11, a12) = (pt * w11, pt * w12);
                    let (jx, jt) = (6 * j, 6 * j + 3);
                    add3(&mut out.tan, ix, jx, &a11);
                    add3(&mut out.tan, ix, jt, &a12);
                    add3(&mut out.tan, it, jx, &(dit * w21));
                    add3(&mut out.tan, it, jt, &(dit * w22));
                    add3(&mut out.tan, mx, jx, &-a11);
                    add3(&mut out.tan, mx, jt, &-a12);
                    add3(&mut out.tan, mt, jx, &(yit * w11 + eit * w21));
                    add3(&mut out.tan, mt, jt, &(yit * w12 + eit * w22));
                    r11 -= w11;
                    r21 -= w21;
                    r12 += h11 * yj + h12 * ej;
                    r22 += h21 * yj + h22 * ej;
                }
                let (b11, b12) = (pt * r11, pt * r12);
                add3(&mut out.tan, ix, mx, &b11);
                add3(&mut out.tan, ix, mt, &b12);
                add3(&mut out.tan, it, mx, &(dit * r21));
                add3(&mut out.tan, it, mt, &(dit * r22));
                add3(&mut out.tan, mx, mx, &-b11);
                add3(&mut out.tan, mx, mt, &-b12);
                add3(&mut out.tan, mt, mx, &(yit * r11 + eit * r21));
                add3(&mut out.tan, mt, mt, &(yit * r12 + eit * r22));
            }
            // Σₐ (∇Ũ)ₐ ∇²zₐ. ψ: the dual Hessians in (θᵢ, θᵣ). y = Λ⁰ᵣᵀ exp(−θ̃ᵣ) Rᵣᵀ (xᵢ − xᵣ):
            // with u = Λ⁰ᵣ g_y, w = Rᵣᵀ(xᵢ − xᵣ), g_y·y = u·exp(−θ̃ᵣ) w has the Hessian
            // ½(u wᵀ + w uᵀ) − (u·w) I in θᵣ and ũ Rᵣᵀ in (θᵣ, xᵢ) (−ũ Rᵣᵀ in (θᵣ, xᵣ)).
            for k in (0..n).filter(|&k| k != m) {
                let gz = &sc.gz[k];
                let mut sec = SMatrix::<f64, 12, 12>::zeros();
                // Σₐ g_ψₐ ∇²ψₐ in (θᵢ, θᵣ): the derivative at θ = 0 of the gradient of g_ψ·ψ in
                // the additive chart, G(θ) = [T(θᵢ)ᵀ Λ⁰ᵢ T⁻ᵀ(ψ) g_ψ; −T(θᵣ)ᵀ Λ⁰ᵣ exp(ψ̃) T⁻ᵀ(ψ) g_ψ]
                // (`R exp(θ̃ + δ̃) = R exp(θ̃) exp((T(θ)δ)~)`), by 6-direction dual numbers.
                {
                    type D = Dual<6>;
                    let st = &nodes[self.nodes[k]];
                    let (l0, sh) = (&self.lambda0[k], sc.shift[k]);
                    let th = Vector3::from_fn(|a, _| D::var(0.0, a));
                    let thr = Vector3::from_fn(|a, _| D::var(0.0, 3 + a));
                    let zero = Vector3::from_element(D::constant(0.0));
                    let lv = local_vars(&zero, &th, &zero, &thr, &st.r, &sr.r, l0, l0r, sh);
                    let psi = Vector3::new(lv[3], lv[4], lv[5]);
                    let gpsi: Vector3<D> = Vector3::new(gz[3], gz[4], gz[5]).map(D::constant);
                    let w = rotation::mtv(&rotation::tangent_inv(&psi), &gpsi);
                    let gk = rotation::mtv(&rotation::tangent(&th), &rotation::mv(&l0.map(c), &w));
                    let gr = -rotation::mtv(
                        &rotation::tangent(&thr),
                        &rotation::mv(&l0r.map(c), &rotation::mv(&rotation::exp(&psi), &w)),
                    );
                    for r in 0..3 {
                        for col in 0..6 {
                            let cc = col + 3 + 3 * (col / 3);
                            sec[(3 + r, cc)] += gk[r].eps[col];
                            sec[(9 + r, cc)] += gr[r].eps[col];
                        }
                    }
                }
                let gy = Vector3::new(gz[0], gz[1], gz[2]);
                let u = l0r * gy;
                let w = sr.r.transpose() * (nodes[self.nodes[k]].x - sr.x);
                let hrr =
                    (u * w.transpose() + w * u.transpose()) * 0.5 - Matrix3::identity() * u.dot(&w);
                let mix = skew(&u) * sr.r.transpose();
                for r in 0..3 {
                    for c in 0..3 {
                        sec[(9 + r, 9 + c)] += hrr[(r, c)];
                        sec[(9 + r, c)] += mix[(r, c)];
                        sec[(9 + r, 6 + c)] -= mix[(r, c)];
                        sec[(c, 9 + r)] += mix[(r, c)];
                        sec[(6 + c, 9 + r)] -= mix[(r, c)];
                    }
                }
                for col in 0..12 {
                    let cc = loc(k, col);
                    for row in 0..12 {
                        out.tan[cc * nl + loc(k, row)] += sec[(row, col)];
                    }
                }
            }
            // ½ f̃_Θ on the rotation diagonal blocks.
            for (k, f) in sc.force[..n].iter().enumerate() {
                let half = skew(&Vector3::new(f[3], f[4], f[5])) * 0.5;
                out.add_block(rx(k), rx(k), &half);
            }
        })
    }
}
