//! The independent route of the flexible slider-crank (decks/benchmarks/slider_crank_flexible.dat):
//! the rod's transverse deflection in its chord frame, as pinned–pinned modes driven by the
//! rigid mechanism's inertial loading. Nothing here uses mecano.
//!
//! **Rigid kinematics** (crank angle θ = ωt, rod angle φ from the crank pin A to the
//! slider B, slider on the X axis): `A = r(cos θ, sin θ)`, `sin φ = −(r/l) sin θ`,
//! `φ̇ cos φ = −(r/l) ω cos θ`, `φ̈ cos φ − φ̇² sin φ = (r/l) ω² sin θ`,
//! `x_B = r cos θ + l cos φ`, `ẍ_B = −rω² cos θ − l(φ̈ sin φ + φ̇² cos φ)`.
//!
//! **Rod** (Euler–Bernoulli, axially rigid, chord frame `e₁ = (cos φ, sin φ)`,
//! `e₂ = (−sin φ, cos φ)`): a point at `x` along the chord with deflection `w` has the
//! transverse acceleration `Ä·e₂ + x φ̈ + ẅ − φ̇² w` (from `p = A + x e₁ + w e₂`, `ė₁ = φ̇ e₂`,
//! `ė₂ = −φ̇ e₁`), so
//! `ρA (ẅ − φ̇² w) + EI w'''' − (N w')' = −ρA (Ä·e₂ + x φ̈)`,
//! with the axial force (tension) `N(x) = f₁ − ρA [Ä·e₁ (l − x) − φ̇² (l² − x²)/2]` of the
//! rigid rod (`N' = ρA a_∥`, `a_∥ = Ä·e₁ − x φ̇²`), `f₁` its value at B: the slider
//! (`m_s ẍ_B = −F_B·e_X`, `F_B = f₁ e₁ + V_B e₂` the force on the rod at B) gives
//! `f₁ = (V_B sin φ − m_s ẍ_B)/cos φ`, the rod's moment balance about A
//! `V_B = (ρA/l)(Ä·e₂ l²/2 + φ̈ l³/3)`.
//!
//! **Galerkin** on `w = Σ qₙ sin(nπx/l)` (pinned–pinned modes, `∫φₙ² = l/2`):
//! `(ρA l/2) q̈ₙ + Σₘ [ (EI (nπ/l)⁴ − ρA φ̇²) (l/2) δₙₘ + ∫ N φₙ' φₘ' ] qₘ
//!   = −ρA [Ä·e₂ l (1 − (−1)ⁿ)/(nπ) + φ̈ (−1)ⁿ⁺¹ l²/(nπ)]`,
//! from rest and undeformed; the mid-span deflection is `Σ qₙ sin(nπ/2)`. Integrated by
//! the classical Runge–Kutta method.
//!
//! Left out, and why small: shear and the section's rotary inertia (r_g/l = 5e-3:
//! relative 1e-4 on the frequencies), axial strain (N/EA < 1e-4), the terms of second
//! order in w/l (w/l < 0.02) and the Coriolis terms of the axial motion (none: axially
//! rigid). The truncation to a few modes is measured by the test (3 against 5 modes).

/// The mechanism's data.
#[derive(Debug, Clone, Copy)]
pub struct SliderCrank {
    /// Crank length, m.
    pub r: f64,
    /// Rod length, m.
    pub l: f64,
    /// Crank speed, rad/s.
    pub omega: f64,
    /// Rod EI, N·m².
    pub ei: f64,
    /// Rod ρA, kg/m.
    pub rho_a: f64,
    /// Slider mass, kg.
    pub m_s: f64,
}

/// The rigid mechanism at time `t`: `(Ä·e₁, Ä·e₂, φ, φ̇, φ̈, ẍ_B)`.
fn rigid(p: &SliderCrank, t: f64) -> (f64, f64, f64, f64, f64, f64) {
    let (r, l, w) = (p.r, p.l, p.omega);
    let th = w * t;
    let sp = -(r / l) * th.sin();
    let cp = (1.0 - sp * sp).sqrt();
    let phi = sp.atan2(cp);
    let dphi = -(r / l) * w * th.cos() / cp;
    let ddphi = ((r / l) * w * w * th.sin() + dphi * dphi * sp) / cp;
    let xb_dd = -r * w * w * th.cos() - l * (ddphi * sp + dphi * dphi * cp);
    let acc = (-r * w * w * th.cos(), -r * w * w * th.sin());
    let a1 = acc.0 * cp + acc.1 * sp;
    let a2 = -acc.0 * sp + acc.1 * cp;
    (a1, a2, phi, dphi, ddphi, xb_dd)
}

/// `∫₀ˡ xᵏ φₙ' φₘ' dx` for k = 0, 1, 2, by Gauss–Legendre quadrature of 8 points on each
/// of 48 panels (the integrands are smooth: exact to round-off).
fn moments(modes: usize, l: f64) -> [Vec<f64>; 3] {
    // 8-point Gauss–Legendre on [−1, 1].
    const X: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let panels = 48;
    let mut out = [
        vec![0.0; modes * modes],
        vec![0.0; modes * modes],
        vec![0.0; modes * modes],
    ];
    let hp = l / panels as f64;
    for k in 0..panels {
        let mid = (k as f64 + 0.5) * hp;
        for (x, w) in X
            .iter()
            .flat_map(|x| [*x, -*x])
            .zip(W.iter().flat_map(|w| [*w, *w]))
        {
            let s = mid + 0.5 * hp * x;
            let ws = 0.5 * hp * w;
            for n in 0..modes {
                let kn = (n + 1) as f64 * std::f64::consts::PI / l;
                for m in 0..modes {
                    let km = (m + 1) as f64 * std::f64::consts::PI / l;
                    let f = kn * (kn * s).cos() * km * (km * s).cos() * ws;
                    out[0][n * modes + m] += f;
                    out[1][n * modes + m] += f * s;
                    out[2][n * modes + m] += f * s * s;
                }
            }
        }
    }
    out
}

/// The mid-span deflection `w(l/2, t)` (m) of the Galerkin model with `modes` modes at
/// the times `0, dt, 2dt, …` up to `end`, integrated by RK4 with step `dt`; every
/// `every`-th value is returned as `(t, w)`.
pub fn mid_span(p: &SliderCrank, modes: usize, end: f64, dt: f64, every: usize) -> Vec<(f64, f64)> {
    use std::f64::consts::PI;
    let l = p.l;
    let mo = moments(modes, l);
    let mass = p.rho_a * l / 2.0;
    // q̈ = f(t, q).
    let accel = |t: f64, q: &[f64]| -> Vec<f64> {
        let (a1, a2, phi, dphi, ddphi, xb_dd) = rigid(p, t);
        let vb = p.rho_a / l * (a2 * l * l / 2.0 + ddphi * l * l * l / 3.0);
        let f1 = (vb * phi.sin() - p.m_s * xb_dd) / phi.cos();
        // N(x) = c0 + c1 x + c2 x².
        let c0 = f1 - p.rho_a * (a1 * l - dphi * dphi * l * l / 2.0);
        let c1 = p.rho_a * a1;
        let c2 = -p.rho_a * dphi * dphi / 2.0;
        (0..modes)
            .map(|n| {
                let nn = (n + 1) as f64;
                let kn = nn * PI / l;
                let sign = if (n + 1) % 2 == 1 { 1.0 } else { -1.0 };
                let force = -p.rho_a
                    * (a2 * l * (1.0 - (-sign)) / (nn * PI) + ddphi * sign * l * l / (nn * PI));
                let mut stiff = (p.ei * kn.powi(4) - p.rho_a * dphi * dphi) * (l / 2.0) * q[n];
                for (m, qm) in q.iter().enumerate() {
                    let i = n * modes + m;
                    stiff += (c0 * mo[0][i] + c1 * mo[1][i] + c2 * mo[2][i]) * qm;
                }
                (force - stiff) / mass
            })
            .collect()
    };
    let mid = |q: &[f64]| -> f64 {
        (0..modes)
            .map(|n| q[n] * ((n + 1) as f64 * PI / 2.0).sin())
            .sum()
    };
    let steps = (end / dt).round() as usize;
    let (mut q, mut v) = (vec![0.0; modes], vec![0.0; modes]);
    let mut out = vec![(0.0, 0.0)];
    let axpy = |a: &[f64], s: f64, b: &[f64]| -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| x + s * y).collect()
    };
    for k in 0..steps {
        let t = k as f64 * dt;
        let a1 = accel(t, &q);
        let (q2, v2) = (axpy(&q, dt / 2.0, &v), axpy(&v, dt / 2.0, &a1));
        let a2 = accel(t + dt / 2.0, &q2);
        let (q3, v3) = (axpy(&q, dt / 2.0, &v2), axpy(&v, dt / 2.0, &a2));
        let a3 = accel(t + dt / 2.0, &q3);
        let (q4, v4) = (axpy(&q, dt, &v3), axpy(&v, dt, &a3));
        let a4 = accel(t + dt, &q4);
        for n in 0..modes {
            q[n] += dt / 6.0 * (v[n] + 2.0 * v2[n] + 2.0 * v3[n] + v4[n]);
            v[n] += dt / 6.0 * (a1[n] + 2.0 * a2[n] + 2.0 * a3[n] + a4[n]);
        }
        if (k + 1) % every == 0 {
            out.push(((k + 1) as f64 * dt, mid(&q)));
        }
    }
    out
}
