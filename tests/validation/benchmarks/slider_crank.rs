//! The independent route of the flexible slider-crank (decks/benchmarks/slider_crank_flexible.dat):
//! the rod's transverse deflection in its chord frame, as pinned–pinned modes driven by the
//! mechanism's inertial loading, with the terms of second order in the deflection that the
//! rod's fast vibration makes large. Nothing here uses mecano.
//!
//! **Kinematics.** The crank pin `A = r(cos θ, sin θ)`, θ = ωt (the drive). The rod, axially
//! inextensible, of length `l`, pinned at A and at the slider B on the X axis. Its chord
//! frame `e₁ = (cos φ, sin φ)` (A to B), `e₂ = (−sin φ, cos φ)`; the material point at arc
//! length `s` is at `p = A + ξ e₁ + w e₂` with `ξ = s − u_f`, `u_f(s) = ½∫₀ˢ w'²` the
//! foreshortening (to second order in w'), so the chord is `l_c = l − δ`, `δ = u_f(l)`,
//! and the slider's constraint `r sin θ + l_c sin φ = 0` gives φ, φ̇, φ̈ (with `l̇_c = −δ̇`,
//! `l̈_c = −δ̈`) and `x_B = r cos θ + l_c cos φ`. From `ė₁ = φ̇ e₂`, `ė₂ = −φ̇ e₁`:
//! `a₁ = Ä·e₁ + ξ̈ − ξ φ̇² − 2 ẇ φ̇ − w φ̈` (rigid axial acceleration, foreshortening,
//! centripetal, Coriolis, Euler), `a₂ = Ä·e₂ + ξ φ̈ + 2 ξ̇ φ̇ + ẅ − w φ̇²`.
//!
//! **Rod** (Euler–Bernoulli; `F = F₁e₁ + F₂e₂` the force exerted across a section on the
//! part nearer A, tension positive): `F' = ρA a` and the moment balance
//! `EI w''' = F₂ − w' F₁` (to second order) give
//! `ρA a₂ + EI w'''' − (F₁ w')' = 0`, `F₁(s) = F₁(l) − ρA ∫ₛˡ a₁`.
//! The end values come from the rod's moment balance about A, `l_c F₂(l) = ρA ∫₀ˡ (ξ a₂ −
//! w a₁)`, and the slider's equation `m_s ẍ_B = −(F₁(l) cos φ − F₂(l) sin φ)`.
//!
//! **Galerkin** on `w = Σ qₙ sin(kₙ s)`, `kₙ = nπ/l` (`∫φₙ² = l/2`; `u_f = ½ qᵀG(s)q` with
//! `Gₙₘ(s) = kₙkₘ∫₀ˢ cos(kₙx) cos(kₘx) dx` in closed form; `∫₀ˡ F₁ w' φₙ' =
//! F₁(l) qₙ kₙ² l/2 − ρA ∫₀ˡ a₁ Γₙ`, `Γₙ(s) = Σₘ qₘ Gₘₙ(s)`, by exchanging the integrals):
//! `(ρA l/2) q̈ₙ = −ρA ∫ (a₂ − ẅ) φₙ − EI kₙ⁴ (l/2) qₙ − F₁(l) qₙ kₙ² l/2 + ρA ∫ a₁ Γₙ`.
//! q̈ appears on the right (in ξ̈, δ̈ through φ̈ and ẍ_B, ẅ in F₂(l)): solved by fixed-point
//! iteration at each evaluation (the coupling is a few per cent: converges geometrically).
//! From rest and undeformed (the deck's start); the mid-span deflection is `Σ qₙ sin(nπ/2)`.
//! Integrated by the classical Runge–Kutta method.
//!
//! **Why the second-order terms** (docs/benchmarks.md): the rod vibrates at ω₁ = 829 rad/s,
//! 5.5 times the crank, so a deflection w carries accelerations ω₁² w that are not small
//! against the mechanism's r ω²: (ω₁/ω)² (w/r) ≈ 0.9 at the benchmark's 150 rad/s. The
//! vibration's transverse inertia reaches the slider (F₂(l) sin φ) and so the rod's axial
//! force; with the Coriolis term 2 ẇ φ̇ it changes F₁ by tens of newtons around ≈ 400 N,
//! a stiffness of order 4 % of EI kₙ⁴ modulated at ω₁. `Terms::linear()` leaves them out
//! (the classical linear route: rigid chord, rigid-body axial force): it misses the run by
//! 5 % of the peak at 150 rad/s, 0.2 % at 50.
//!
//! Left out, and why small: shear and the section's rotary inertia (r_g/l = 5e-3:
//! relative 1e-4 on the frequencies), axial strain (F₁/EA < 1e-4), the terms of third
//! order in w/l (relative (w/l)² < 3e-4), the curvature's nonlinearity (w'² < 3e-3 · 1e-1).
//! The truncation to a few modes is measured by the test (3 against 5 modes).

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
    /// Rod ρI (rotary inertia about the bending axis), kg·m.
    pub rho_i: f64,
    /// Rod κGA (shear stiffness), N.
    pub kga: f64,
}

/// Which terms of second order in the deflection the route keeps.
#[derive(Debug, Clone, Copy)]
pub struct Terms {
    /// The foreshortening `u_f` (in ξ, and the chord's shortening δ in φ and x_B).
    pub foreshortening: bool,
    /// The Coriolis and Euler terms `−2ẇφ̇ − wφ̈` of the axial acceleration.
    pub coriolis: bool,
    /// The deflection's share of the rod's end force `F₂(l)` (its transverse inertia).
    pub end_force: bool,
    /// The curvature's third-order term: `κ = w''(1 + ½w'²)`, bending energy
    /// `½EI∫w''²(1 + w'²)`.
    pub curvature: bool,
    /// Shear and rotary inertia (Timoshenko) on each mode, to first order in `(kₙ r_g)²`.
    pub timoshenko: bool,
}

impl Terms {
    /// Every term (the route of the test).
    pub fn all() -> Self {
        Terms {
            foreshortening: true,
            coriolis: true,
            end_force: true,
            curvature: true,
            timoshenko: true,
        }
    }
    /// None: the linear route (rigid chord, rigid-body axial force).
    pub fn linear() -> Self {
        Terms {
            foreshortening: false,
            coriolis: false,
            end_force: false,
            curvature: false,
            timoshenko: false,
        }
    }
}

/// Quadrature points and weights on [0, l]: 8-point Gauss–Legendre on `panels` panels
/// (the integrands are trigonometric polynomials of a few wavelengths over l, times
/// polynomials of low degree: exact to round-off with 8 panels for 5 modes: 16 change the result by 3e-15 of l).
fn quadrature(l: f64, panels: usize) -> Vec<(f64, f64)> {
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
    let hp = l / panels as f64;
    let mut out = Vec::with_capacity(8 * panels);
    for k in 0..panels {
        let mid = (k as f64 + 0.5) * hp;
        for (x, w) in X.iter().zip(&W) {
            out.push((mid - 0.5 * hp * x, 0.5 * hp * w));
            out.push((mid + 0.5 * hp * x, 0.5 * hp * w));
        }
    }
    out
}

/// `kₙkₘ ∫₀ˢ cos(kₙx) cos(kₘx) dx` (closed form).
fn g_entry(kn: f64, km: f64, s: f64) -> f64 {
    let part = |a: f64| if a == 0.0 { s } else { (a * s).sin() / a };
    kn * km * 0.5 * (part(kn - km) + part(kn + km))
}

/// The route's fixed data: modes at the quadrature points.
struct Basis {
    /// (s, weight).
    pts: Vec<(f64, f64)>,
    /// φₙ(s), φₙ'(s) per point, per mode (φₙ'' = −kₙ² φₙ).
    phi: Vec<Vec<f64>>,
    dphi: Vec<Vec<f64>>,
    /// G(s) per point (modes × modes, row-major), and G(l).
    g: Vec<Vec<f64>>,
    g_end: Vec<f64>,
    k: Vec<f64>,
}

impl Basis {
    fn new(modes: usize, l: f64) -> Self {
        use std::f64::consts::PI;
        let pts = quadrature(l, 8);
        let k: Vec<f64> = (1..=modes).map(|n| n as f64 * PI / l).collect();
        let gm = |s: f64| -> Vec<f64> {
            let mut g = vec![0.0; modes * modes];
            for n in 0..modes {
                for m in 0..modes {
                    g[n * modes + m] = g_entry(k[n], k[m], s);
                }
            }
            g
        };
        Basis {
            phi: pts
                .iter()
                .map(|(s, _)| k.iter().map(|kn| (kn * s).sin()).collect())
                .collect(),
            dphi: pts
                .iter()
                .map(|(s, _)| k.iter().map(|kn| kn * (kn * s).cos()).collect())
                .collect(),
            g: pts.iter().map(|(s, _)| gm(*s)).collect(),
            g_end: gm(l),
            pts,
            k,
        }
    }
}

/// `G x` for a row-major square `g`, into `out`.
fn mat_vec(g: &[f64], x: &[f64], out: &mut [f64]) {
    let n = x.len();
    for (i, o) in out.iter_mut().enumerate() {
        *o = (0..n).map(|j| g[i * n + j] * x[j]).sum();
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// What the fixed-point iteration needs at one quadrature point, from (q, q̇) alone.
struct Point {
    w: f64,
    wd: f64,
    /// `G q` (= Γ).
    gq: Vec<f64>,
    /// u_f, u̇_f and the part `q̇ᵀGq̇` of ü_f.
    uf: f64,
    uf_d: f64,
    uf_vv: f64,
}

/// q̈ of the Galerkin model at (t, q, q̇), by fixed-point iteration on its implicit terms
/// from the guess `qdd` (the last evaluation's).
fn accel(
    p: &SliderCrank,
    terms: Terms,
    b: &Basis,
    t: f64,
    q: &[f64],
    v: &[f64],
    mut qdd: Vec<f64>,
) -> Vec<f64> {
    let modes = q.len();
    let (r, l, w, rho_a) = (p.r, p.l, p.omega, p.rho_a);
    let th = w * t;
    let fs = terms.foreshortening;
    let pts: Vec<Point> = b
        .pts
        .iter()
        .enumerate()
        .map(|(i, _)| {
            // Γ = G q is the geometric stiffness's (always); u_f and its rates only with
            // the foreshortening.
            let (mut gq, mut gv) = (vec![0.0; modes], vec![0.0; modes]);
            mat_vec(&b.g[i], q, &mut gq);
            let (uf, uf_d, uf_vv) = if fs {
                mat_vec(&b.g[i], v, &mut gv);
                (0.5 * dot(q, &gq), dot(q, &gv), dot(v, &gv))
            } else {
                (0.0, 0.0, 0.0)
            };
            Point {
                w: dot(q, &b.phi[i]),
                wd: dot(v, &b.phi[i]),
                uf,
                uf_d,
                uf_vv,
                gq,
            }
        })
        .collect();
    let (mut gq_end, mut gv_end) = (vec![0.0; modes], vec![0.0; modes]);
    if fs {
        mat_vec(&b.g_end, q, &mut gq_end);
        mat_vec(&b.g_end, v, &mut gv_end);
    }
    // Forces that do not depend on q̈: the curvature's cubic term,
    // ∂/∂qₙ of ½EI∫w''² w'² = EI∫(w''φₙ'' w'² + w''² w' φₙ'), and the elastic stiffness
    // with Timoshenko's first-order correction.
    let mut elastic = vec![0.0; modes];
    if terms.curvature {
        for (i, (_, ws)) in b.pts.iter().enumerate() {
            let w1 = dot(q, &b.dphi[i]);
            let w2: f64 = (0..modes)
                .map(|m| -b.k[m] * b.k[m] * q[m] * b.phi[i][m])
                .sum();
            for (n, e) in elastic.iter_mut().enumerate() {
                let phi2 = -b.k[n] * b.k[n] * b.phi[i][n];
                *e += ws * p.ei * (w2 * phi2 * w1 * w1 + w2 * w2 * w1 * b.dphi[i][n]);
            }
        }
    }
    // Timoshenko, to first order in (kₙ r_g)²: the mode's mass ρA(1 + (kₙ r_g)²) (rotary
    // inertia), its stiffness EI kₙ⁴/(1 + EI kₙ²/κGA) (shear).
    let mut mass = vec![rho_a * l / 2.0; modes];
    for n in 0..modes {
        let kn = b.k[n];
        let soft = if terms.timoshenko {
            mass[n] *= 1.0 + p.rho_i / rho_a * kn * kn;
            1.0 / (1.0 + p.ei * kn * kn / p.kga)
        } else {
            1.0
        };
        elastic[n] += p.ei * kn.powi(4) * soft * l / 2.0 * q[n];
    }
    let mut a1s = vec![0.0; pts.len()];
    let mut force_a2r = vec![0.0; modes];
    for _ in 0..100 {
        // The chord's shortening δ = u_f(l) and its rates.
        let (dl, dl_d, dl_dd) = if fs {
            (
                0.5 * dot(q, &gq_end),
                dot(q, &gv_end),
                dot(v, &gv_end) + dot(&qdd, &gq_end),
            )
        } else {
            (0.0, 0.0, 0.0)
        };
        let (lc, lc_d, lc_dd) = (l - dl, -dl_d, -dl_dd);
        let sp = -r * th.sin() / lc;
        let cp = (1.0 - sp * sp).sqrt();
        let dph = (-r * w * th.cos() - lc_d * sp) / (lc * cp);
        let ddph = (r * w * w * th.sin() - lc_dd * sp - 2.0 * lc_d * cp * dph
            + lc * sp * dph * dph)
            / (lc * cp);
        let xb_dd = -r * w * w * th.cos() + lc_dd * cp
            - 2.0 * lc_d * sp * dph
            - lc * (cp * dph * dph + sp * ddph);
        let (ax, ay) = (-r * w * w * th.cos(), -r * w * w * th.sin());
        let (a_1, a_2) = (ax * cp + ay * sp, -ax * sp + ay * cp);
        // Accelerations at the points; F₂(l) and the modal forces.
        let mut f2 = 0.0;
        force_a2r.iter_mut().for_each(|f| *f = 0.0);
        for (i, ((s, ws), pt)) in b.pts.iter().zip(&pts).enumerate() {
            let wdd = dot(&qdd, &b.phi[i]);
            let uf_dd = if fs {
                pt.uf_vv + dot(&qdd, &pt.gq)
            } else {
                0.0
            };
            let xi = s - pt.uf;
            let mut a1 = a_1 - uf_dd - xi * dph * dph;
            if terms.coriolis {
                a1 -= 2.0 * pt.wd * dph + pt.w * ddph;
            }
            let a2r = a_2 + xi * ddph - 2.0 * pt.uf_d * dph - pt.w * dph * dph;
            f2 += ws
                * if terms.end_force {
                    xi * (a2r + wdd) - pt.w * a1
                } else {
                    s * (a_2 + s * ddph)
                };
            for (f, ph) in force_a2r.iter_mut().zip(&b.phi[i]) {
                *f += ws * a2r * ph;
            }
            a1s[i] = a1;
        }
        let f2 = rho_a / lc * f2;
        let f1 = (f2 * sp - p.m_s * xb_dd) / cp;
        let next: Vec<f64> = (0..modes)
            .map(|n| {
                let kn = b.k[n];
                // ρA ∫ a₁ Γₙ, Γₙ(s) = (G(s) q)ₙ (G symmetric).
                let tail: f64 = b
                    .pts
                    .iter()
                    .zip(&pts)
                    .zip(&a1s)
                    .map(|(((_, ws), pt), a1)| ws * a1 * pt.gq[n])
                    .sum();
                let rhs = -rho_a * force_a2r[n] - elastic[n] - f1 * q[n] * kn * kn * l / 2.0
                    + rho_a * tail;
                rhs / mass[n]
            })
            .collect();
        let change = next
            .iter()
            .zip(&qdd)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let size = next.iter().map(|a| a.abs()).fold(1.0, f64::max);
        qdd = next;
        if change <= 1e-13 * size {
            break;
        }
    }
    qdd
}

/// The mid-span deflection `w(l/2, t)` (m) of the Galerkin model with `modes` modes and
/// the second-order `terms`, at the times `0, dt, 2dt, …` up to `end`, integrated by RK4
/// with step `dt`; every `every`-th value is returned as `(t, w)`.
pub fn mid_span(
    p: &SliderCrank,
    terms: Terms,
    modes: usize,
    end: f64,
    dt: f64,
    every: usize,
) -> Vec<(f64, f64)> {
    use std::f64::consts::PI;
    let b = Basis::new(modes, p.l);
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
    let mut guess = vec![0.0; modes];
    for k in 0..steps {
        let t = k as f64 * dt;
        let a1 = accel(p, terms, &b, t, &q, &v, guess);
        let (q2, v2) = (axpy(&q, dt / 2.0, &v), axpy(&v, dt / 2.0, &a1));
        let a2 = accel(p, terms, &b, t + dt / 2.0, &q2, &v2, a1.clone());
        let (q3, v3) = (axpy(&q, dt / 2.0, &v2), axpy(&v, dt / 2.0, &a2));
        let a3 = accel(p, terms, &b, t + dt / 2.0, &q3, &v3, a2.clone());
        let (q4, v4) = (axpy(&q, dt, &v3), axpy(&v, dt, &a3));
        let a4 = accel(p, terms, &b, t + dt, &q4, &v4, a3.clone());
        guess = a4.clone();
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
