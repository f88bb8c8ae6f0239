//! The superelement's residual, written once over the scalar (`f64` for the residual,
//! `Dual<2>` for the exact iteration matrix, [`super::Superelement::evaluate`]).
//!
//! Lagrange's equations of `T = ½ νᵀ𝕄(q)ν` ([`super::invariants`]) on `ℝ³ × SO(3) × ℝⁿ`
//! with the frame's material angular velocity `Ω` and `V = Rᵀẋ₀` (Euler–Poincaré form;
//! Géradin & Cardona, *Flexible Multibody Dynamics*, ch. 4; Shabana §5.5), `p = 𝕄ν`:
//!
//! ```text
//!   R (ṗ_V + Ω × p_V)                 − m g             = f_x       (frame node, global)
//!   ṗ_Ω + Ω × p_Ω + V × p_V          − c(q) × Rᵀg      = m_Θ       (frame node, material)
//!   ṗ_q − ∂T/∂q + K q                 − C₁ᵀ Rᵀg          = f_q       (elastic coordinates)
//!   ṗ = 𝕄 ν̇ + 𝕄̇ ν,   ν̇ = [Rᵀẍ₀ − Ω × V; Ω̇; q̈],   ∂T/∂q_k = νᵀ G_k Ω + Ωᵀ Σ_l H_kl q_l Ω
//! ```
//!
//! `V × p_V` is `∂T/∂Θ` through `V = Rᵀẋ₀`; the quadratic velocity terms (`Ω × p`, `𝕄̇ν`,
//! `∂T/∂q`) are the gyroscopic, centrifugal and Coriolis forces of the floating frame.
//! Each other interface node `i` (position `x_i`, rotation `R_i`) is tied to the body by
//!
//! ```text
//!   Φ_t = Rᵀ(x_i − x₀) − s_i − q_{i,t} = 0,     Φ_r = ½ vee(A − Aᵀ) − q_{i,r} = 0,  A = RᵀR_i
//! ```
//!
//! (`½ vee(A − Aᵀ) = sin θ n` for `A = exp(θñ)`: the small interface rotation to second
//! order, the order of a linear elastic body) with the multipliers' forces `Bᵀμ`,
//! `μ = sλ̂ + pΦ`, exactly as a joint's.

use crate::dual::Real;
use crate::elements::EvalContext;
use nalgebra::{Matrix3, Vector3};

use super::invariants::Body;

/// The local layout: the frame node, `nb` other interface nodes, `nm` modal nodes, then
/// `6 nb` multipliers.
#[derive(Debug, Clone, Copy)]
pub struct Layout {
    /// Other interface nodes.
    pub nb: usize,
    /// Modal nodes (three elastic coordinates each).
    pub nm: usize,
}

impl Layout {
    /// Local size.
    pub fn size(&self) -> usize {
        6 * (1 + self.nb + self.nm) + 6 * self.nb
    }
    /// Local row of elastic coordinate `i`.
    pub fn q_row(&self, i: usize) -> usize {
        6 * (1 + self.nb + i / 3) + i % 3
    }
    /// First local row of the multipliers.
    pub fn lambda_row(&self) -> usize {
        6 * (1 + self.nb + self.nm)
    }
}

/// The element's unknowns at a state, in the scalar `S`.
#[derive(Debug, Clone)]
pub struct State<S: Real> {
    /// Frame node: position, rotation, velocity, material angular velocity, their rates.
    pub x0: Vector3<S>,
    /// Frame rotation.
    pub r: Matrix3<S>,
    /// Frame velocity, global.
    pub v0: Vector3<S>,
    /// Frame angular velocity, material.
    pub w: Vector3<S>,
    /// Frame acceleration, global.
    pub a0: Vector3<S>,
    /// Frame angular acceleration, material.
    pub wd: Vector3<S>,
    /// Elastic coordinates and their rates.
    pub q: Vec<S>,
    /// `q̇`.
    pub qd: Vec<S>,
    /// `q̈`.
    pub qdd: Vec<S>,
    /// Other interface nodes' positions.
    pub xi: Vec<Vector3<S>>,
    /// Other interface nodes' rotations.
    pub ri: Vec<Matrix3<S>>,
    /// Scaled multipliers `λ̂`.
    pub lam: Vec<S>,
}

/// The deformation-dependent inertia terms, `O(n²)` to form: `G(q)`, `G(q̇)` (`(6 + n) × 3`)
/// and `HQ_k = Σ_l H_kl q_l`. Formed once in `f64` per evaluation; a tangent pass seeded on
/// one coordinate adds its derivative (`G_j`, `c_v G_j`, `H_kj`) in `O(n)`
/// ([`Pre::seeded`]), so that a tangent costs `O(n)` passes of `O(n²)`, not `O(n³)` each.
#[derive(Debug, Clone)]
pub struct Pre<S: Real> {
    /// `G(q)`, by row of `ν`.
    pub gq: Vec<Vector3<S>>,
    /// `G(q̇)`.
    pub gqd: Vec<Vector3<S>>,
    /// `HQ_k`.
    pub hq: Vec<Matrix3<S>>,
    /// `ν`, `ν̇` at the evaluation's state, and `𝕄₀ν`, `𝕄₀ν̇`, `Gᵀν` (`3n`) there: a pass
    /// adds only what its seeded direction changes (`O(n)` per changed entry).
    pub base: Base,
}

/// `f64` products at the evaluation's state ([`Pre::base`]).
#[derive(Debug, Clone, Default)]
pub struct Base {
    nu: Vec<f64>,
    nud: Vec<f64>,
    m0nu: Vec<f64>,
    m0nud: Vec<f64>,
    gtn: Vec<f64>,
}

/// `Aᵀ x` for `x` near `xb`, `Aᵀ xb = ab` known (as [`times_near`]).
fn times_near_t<S: Real>(a: &nalgebra::DMatrix<f64>, x: &[S], xb: &[f64], ab: &[f64]) -> Vec<S> {
    let mut y: Vec<S> = ab.iter().map(|v| S::cst(*v)).collect();
    for (i, (xi, xbi)) in x.iter().zip(xb).enumerate() {
        let d = *xi - S::cst(*xbi);
        if d.is_zero() {
            continue;
        }
        for (k, yk) in y.iter_mut().enumerate() {
            *yk += S::cst(a[(i, k)]) * d;
        }
    }
    y
}

/// `ν = [Rᵀẋ₀; Ω; q̇]` and `ν̇ = [Rᵀẍ₀ − Ω × V; Ω̇; q̈]` of a state.
fn velocities<S: Real>(st: &State<S>) -> (Vec<S>, Vec<S>) {
    let rt = st.r.transpose();
    let vv = rt * st.v0;
    let mut nu = Vec::with_capacity(6 + st.qd.len());
    nu.extend(vv.iter().copied());
    nu.extend(st.w.iter().copied());
    nu.extend(st.qd.iter().copied());
    let vdot = rt * st.a0 - st.w.cross(&vv);
    let mut nud = Vec::with_capacity(6 + st.qd.len());
    nud.extend(vdot.iter().copied());
    nud.extend(st.wd.iter().copied());
    nud.extend(st.qdd.iter().copied());
    (nu, nud)
}

/// `A x` for `x` near `xb`, `A xb = ab` known: `ab + Σ_{j: x_j ≠ xb_j} A[:, j](x_j − xb_j)`.
fn times_near<S: Real>(a: &nalgebra::DMatrix<f64>, x: &[S], xb: &[f64], ab: &[f64]) -> Vec<S> {
    let mut y: Vec<S> = ab.iter().map(|v| S::cst(*v)).collect();
    for (j, (xj, xbj)) in x.iter().zip(xb).enumerate() {
        let d = *xj - S::cst(*xbj);
        if d.is_zero() {
            continue;
        }
        for (i, yi) in y.iter_mut().enumerate() {
            *yi += S::cst(a[(i, j)]) * d;
        }
    }
    y
}

impl Pre<f64> {
    /// The terms at the state `st`.
    pub fn new(body: &Body, st: &State<f64>) -> Self {
        let (q, qd) = (&st.q, &st.qd);
        let n = body.n;
        let mut gq = vec![Vector3::zeros(); 6 + n];
        let mut gqd = vec![Vector3::zeros(); 6 + n];
        for (i, (a, b)) in gq.iter_mut().zip(gqd.iter_mut()).enumerate() {
            for k in 0..n {
                for j in 0..3 {
                    let gv = body.g[(i, 3 * k + j)];
                    a[j] += gv * q[k];
                    b[j] += gv * qd[k];
                }
            }
        }
        let mut hq = vec![Matrix3::zeros(); n];
        for (k, hk) in hq.iter_mut().enumerate() {
            for (l, ql) in q.iter().enumerate() {
                if *ql != 0.0 {
                    *hk += body.h.fixed_view::<3, 3>(3 * k, 3 * l) * *ql;
                }
            }
        }
        let (nu, nud) = velocities(st);
        let mv = |x: &[f64]| {
            (&body.m0 * nalgebra::DVector::from_column_slice(x))
                .as_slice()
                .to_vec()
        };
        let gtn = (body.g.transpose() * nalgebra::DVector::from_column_slice(&nu))
            .as_slice()
            .to_vec();
        let base = Base {
            m0nu: mv(&nu),
            m0nud: mv(&nud),
            gtn,
            nu,
            nud,
        };
        Pre { gq, gqd, hq, base }
    }

    /// The terms in `Dual<2>` for a pass seeded on coordinate `j` (`ε₀` on `q_j`, `ε₁ c_v`
    /// on `q̇_j`), or on no coordinate (`None`: constants).
    pub fn seeded(&self, body: &Body, j: Option<usize>, c_v: f64) -> Pre<crate::dual::Dual<2>> {
        use crate::dual::Dual;
        let v = |x: &Vector3<f64>| x.map(Dual::<2>::constant);
        let mut p = Pre {
            gq: self.gq.iter().map(v).collect(),
            gqd: self.gqd.iter().map(v).collect(),
            hq: self.hq.iter().map(|m| m.map(Dual::<2>::constant)).collect(),
            base: self.base.clone(),
        };
        if let Some(j) = j {
            for (i, (a, b)) in p.gq.iter_mut().zip(p.gqd.iter_mut()).enumerate() {
                for c in 0..3 {
                    let gv = body.g[(i, 3 * j + c)];
                    a[c].eps[0] += gv;
                    b[c].eps[1] += c_v * gv;
                }
            }
            for (k, hk) in p.hq.iter_mut().enumerate() {
                let hkj = body.h.fixed_view::<3, 3>(3 * k, 3 * j);
                for r in 0..3 {
                    for c in 0..3 {
                        hk[(r, c)].eps[0] += hkj[(r, c)];
                    }
                }
            }
        }
        p
    }
}

fn vee<S: Real>(a: &Matrix3<S>) -> Vector3<S> {
    Vector3::new(a[(2, 1)], a[(0, 2)], a[(1, 0)])
}

/// The residual at `st` into `out` (local size, zeroed by the caller).
pub fn residual<S: Real>(
    body: &Body,
    lay: Layout,
    st: &State<S>,
    pre: &Pre<S>,
    ctx: &EvalContext,
    out: &mut [S],
) {
    let n = body.n;
    let c = S::cst;
    let zero = S::zero();
    let rt = st.r.transpose();
    let mut f_x = Vector3::repeat(zero);
    let mut f_t = Vector3::repeat(zero);
    let mut f_q = vec![zero; n];
    if ctx.dynamic {
        let w = st.w;
        let (nu, nud) = velocities(st);
        let vv = Vector3::new(nu[0], nu[1], nu[2]);
        let (gq, gqd, hq) = (&pre.gq, &pre.gqd, &pre.hq);
        let mut hqq = Matrix3::repeat(zero);
        let mut hdq = Matrix3::repeat(zero);
        for k in 0..n {
            hqq += hq[k] * st.q[k];
            hdq += hq[k] * st.qd[k];
        }
        let b = &pre.base;
        let mv = |x: &[S], xb: &[f64], m0xb: &[f64]| -> Vec<S> {
            let xw = Vector3::new(x[3], x[4], x[5]);
            let mut y = times_near(&body.m0, x, xb, m0xb);
            for (i, yi) in y.iter_mut().enumerate() {
                *yi += gq[i].dot(&xw);
            }
            let mut gtx = Vector3::repeat(zero);
            for (i, xi) in x.iter().enumerate() {
                gtx += gq[i] * *xi;
            }
            let hx = hqq * xw;
            for j in 0..3 {
                y[3 + j] += gtx[j] + hx[j];
            }
            y
        };
        let p = mv(&nu, &b.nu, &b.m0nu);
        let mut pd = mv(&nud, &b.nud, &b.m0nud);
        // Gᵀν (3n), near its value at the state.
        let gtn = times_near_t(&body.g, &nu, &b.nu, &b.gtn);
        // 𝕄̇ν.
        let mut gdtn = Vector3::repeat(zero);
        for (i, ni) in nu.iter().enumerate() {
            pd[i] += gqd[i].dot(&w);
            gdtn += gqd[i] * *ni;
        }
        let hw = (hdq + hdq.transpose()) * w;
        for j in 0..3 {
            pd[3 + j] += gdtn[j] + hw[j];
        }
        let pv = Vector3::new(p[0], p[1], p[2]);
        let pw = Vector3::new(p[3], p[4], p[5]);
        let pdv = Vector3::new(pd[0], pd[1], pd[2]);
        let pdw = Vector3::new(pd[3], pd[4], pd[5]);
        f_x += st.r * (pdv + w.cross(&pv));
        f_t += pdw + w.cross(&pw) + vv.cross(&pv);
        for k in 0..n {
            // ∂T/∂q_k = νᵀ G_k Ω + Ωᵀ HQ_k Ω.
            let mut dt = w.dot(&(hq[k] * w));
            for j in 0..3 {
                dt += gtn[3 * k + j] * w[j];
            }
            f_q[k] += pd[6 + k] - dt;
        }
    }
    // Stiffness.
    for (k, fk) in f_q.iter_mut().enumerate() {
        for l in 0..n {
            *fk += c(body.k[(k, l)]) * st.q[l];
        }
    }
    // Gravity: U = −gᵀ(m x₀ + R c(q)).
    let g = ctx.gravity;
    if g != Vector3::zeros() {
        let gs = Vector3::new(c(g.x), c(g.y), c(g.z));
        let gl = rt * gs;
        let mut cq = Vector3::new(c(body.c0.x), c(body.c0.y), c(body.c0.z));
        for k in 0..n {
            for i in 0..3 {
                cq[i] += c(body.m0[(i, 6 + k)]) * st.q[k];
            }
        }
        f_x -= gs * c(body.mass);
        f_t -= cq.cross(&gl);
        for (k, fk) in f_q.iter_mut().enumerate() {
            for i in 0..3 {
                *fk -= c(body.m0[(i, 6 + k)]) * gl[i];
            }
        }
    }
    // Interface constraints.
    let s = c(ctx.constraint_scale);
    let pen = c(ctx.penalty);
    let lrow = lay.lambda_row();
    let half = c(0.5);
    for b in 0..lay.nb {
        let d = st.xi[b] - st.x0;
        let rd = rt * d;
        let sb = &body.s_iface[b];
        let qt = Vector3::new(st.q[6 * b], st.q[6 * b + 1], st.q[6 * b + 2]);
        let qr = Vector3::new(st.q[6 * b + 3], st.q[6 * b + 4], st.q[6 * b + 5]);
        let phit = rd - Vector3::new(c(sb.x), c(sb.y), c(sb.z)) - qt;
        let a = rt * st.ri[b];
        let phir = vee(&(a - a.transpose())) * half - qr;
        let lt = Vector3::new(st.lam[6 * b], st.lam[6 * b + 1], st.lam[6 * b + 2]);
        let lr = Vector3::new(st.lam[6 * b + 3], st.lam[6 * b + 4], st.lam[6 * b + 5]);
        let mut_ = lt * s + phit * pen;
        let mur = lr * s + phir * pen;
        let tr = a[(0, 0)] + a[(1, 1)] + a[(2, 2)];
        let rmu = st.r * mut_;
        let node = 6 * (1 + b);
        // x_i, Θ_i rows.
        let ri_force = (Matrix3::identity() * tr - a) * mur * half;
        for j in 0..3 {
            out[node + j] += rmu[j];
            out[node + 3 + j] += ri_force[j];
        }
        f_x -= rmu;
        f_t += mut_.cross(&rd) - (Matrix3::identity() * tr - a.transpose()) * mur * half;
        for j in 0..3 {
            f_q[6 * b + j] -= mut_[j];
            f_q[6 * b + 3 + j] -= mur[j];
            out[lrow + 6 * b + j] += s * phit[j];
            out[lrow + 6 * b + 3 + j] += s * phir[j];
        }
    }
    for j in 0..3 {
        out[j] += f_x[j];
        out[3 + j] += f_t[j];
    }
    for (k, fk) in f_q.into_iter().enumerate() {
        out[lay.q_row(k)] += fk;
    }
}
