//! Independent routes for the planar loops: the one-degree-of-freedom Lagrange equations
//! of the four-bar and the slider-crank, from their closure equations solved exactly here
//! (no mecano code), and a fine fixed-step RK4 for the four-bar's motion.
//!
//! With `θ` the crank's absolute angle and every body's position and angle functions of
//! it, `T = ½ J(θ) θ̇²` with `J = Σ m |G′|² + Σ I φ′²` and the equation of motion is
//! `J θ̈ + Q θ̇² + V′(θ) = τ`, `Q = ½ J′ = Σ m G′·G″ + Σ I φ′ φ″` (primes: d/dθ). The velocity
//! and acceleration coefficients `φ′, φ″` of the loop's other angles follow from the
//! derivatives of the closure equation, two linear 2×2 systems.

use std::f64::consts::FRAC_PI_2;

type V2 = [f64; 2];

fn e(t: f64) -> V2 {
    [t.cos(), t.sin()]
}

fn ep(t: f64) -> V2 {
    [-t.sin(), t.cos()]
}

fn dot(a: V2, b: V2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The generalized inertia and forces of a one-degree-of-freedom mechanism at `θ`.
#[derive(Debug, Clone, Copy)]
pub struct Lagrange {
    /// `J(θ)`, kg·m².
    pub j: f64,
    /// `Q(θ) = ½ J′(θ)`, kg·m².
    pub q: f64,
    /// Gravity's `V′(θ)`, N·m.
    pub vg: f64,
    /// Gravity's `V″(θ)`, N·m.
    pub vgg: f64,
}

/// A body of the loop: mass at a point `G(θ)`, rotary inertia about Z, angle `φ(θ)`:
/// `(G′, G″, φ′, φ″)`.
type BodyRates = (V2, V2, f64, f64);

fn lagrange(bodies: &[(f64, f64, BodyRates)], g: f64) -> Lagrange {
    let mut out = Lagrange {
        j: 0.0,
        q: 0.0,
        vg: 0.0,
        vgg: 0.0,
    };
    for &(m, i, (gp, gpp, fp, fpp)) in bodies {
        out.j += m * dot(gp, gp) + i * fp * fp;
        out.q += m * dot(gp, gpp) + i * fp * fpp;
        out.vg += m * g * gp[1];
        out.vgg += m * g * gpp[1];
    }
    out
}

/// The planar four-bar of `decks/four_bar_hinges.dat`: ground pivots A = (0, 0) and
/// D = (2, 0), crank A–B of length 1 (B = (0, 1) at θ = π/2), coupler B–C, rocker D–C
/// (C = (2.2, 1.2) at the start), each a 1 kg mass at its centre with I = 0.1 kg·m².
#[derive(Debug, Clone, Copy)]
pub struct FourBar {
    /// Crank, coupler and rocker lengths, m.
    pub a: f64,
    /// Coupler length, m.
    pub b: f64,
    /// Rocker length, m.
    pub c: f64,
    /// Ground pivot D's x, m.
    pub d: f64,
    /// Mass of each bar, kg.
    pub m: f64,
    /// Rotary inertia of each bar about its centre, kg·m².
    pub i: f64,
    /// Gravity (along −Y), m/s².
    pub g: f64,
    /// The torsional spring on the crank's hinge, N·m/rad, and its unloaded hinge angle, rad.
    pub k: f64,
    /// Unloaded angle of the spring (relative to the deck's geometry), rad.
    pub theta0: f64,
}

impl FourBar {
    /// The deck's four-bar with gravity `g` and the spring `k`, `theta0`.
    pub fn deck(g: f64, k: f64, theta0: f64) -> Self {
        FourBar {
            a: 1.0,
            b: (2.2f64 * 2.2 + 0.2 * 0.2).sqrt(),
            c: (0.2f64 * 0.2 + 1.2 * 1.2).sqrt(),
            d: 2.0,
            m: 1.0,
            i: 0.1,
            g,
            k,
            theta0,
        }
    }

    /// The coupler's and the rocker's angles (β, γ) at crank angle `th`, by Newton on the
    /// closure `a e(θ) + b e(β) − D − c e(γ) = 0` from `guess` (the branch followed).
    pub fn closure(&self, th: f64, guess: (f64, f64)) -> (f64, f64) {
        let (mut be, mut ga) = guess;
        for _ in 0..60 {
            let fx = self.a * th.cos() + self.b * be.cos() - self.d - self.c * ga.cos();
            let fy = self.a * th.sin() + self.b * be.sin() - self.c * ga.sin();
            let (j11, j12) = (-self.b * be.sin(), self.c * ga.sin());
            let (j21, j22) = (self.b * be.cos(), -self.c * ga.cos());
            let det = j11 * j22 - j12 * j21;
            let dbe = (fx * j22 - fy * j12) / det;
            let dga = (j11 * fy - j21 * fx) / det;
            be -= dbe;
            ga -= dga;
            if dbe.abs() + dga.abs() < 1e-15 {
                break;
            }
        }
        (be, ga)
    }

    /// The start's coupler and rocker angles.
    pub fn start_angles(&self) -> (f64, f64) {
        (0.2f64.atan2(2.2), 1.2f64.atan2(0.2))
    }

    /// Lagrange's terms at crank angle `th` (closure branch from `guess`), and the angles.
    pub fn at(&self, th: f64, guess: (f64, f64)) -> (Lagrange, (f64, f64)) {
        let (be, ga) = self.closure(th, guess);
        let (a, b, c) = (self.a, self.b, self.c);
        // [b e⊥(β), −c e⊥(γ)] [β′; γ′] = −a e⊥(θ), and the same matrix for the second.
        let m = [[-b * be.sin(), c * ga.sin()], [b * be.cos(), -c * ga.cos()]];
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        let solve = |r: V2| -> V2 {
            [
                (r[0] * m[1][1] - m[0][1] * r[1]) / det,
                (m[0][0] * r[1] - m[1][0] * r[0]) / det,
            ]
        };
        let [bp, gp] = solve([a * th.sin(), -a * th.cos()]);
        let [bpp, gpp] = solve([
            a * th.cos() + b * be.cos() * bp * bp - c * ga.cos() * gp * gp,
            a * th.sin() + b * be.sin() * bp * bp - c * ga.sin() * gp * gp,
        ]);
        let add = |x: V2, y: V2| [x[0] + y[0], x[1] + y[1]];
        let sc = |s: f64, x: V2| [s * x[0], s * x[1]];
        let crank = (sc(0.5 * a, ep(th)), sc(-0.5 * a, e(th)), 1.0, 0.0);
        let coupler = (
            add(sc(a, ep(th)), sc(0.5 * b * bp, ep(be))),
            add(
                sc(-a, e(th)),
                add(sc(0.5 * b * bpp, ep(be)), sc(-0.5 * b * bp * bp, e(be))),
            ),
            bp,
            bpp,
        );
        let rocker = (
            sc(0.5 * c * gp, ep(ga)),
            add(sc(0.5 * c * gpp, ep(ga)), sc(-0.5 * c * gp * gp, e(ga))),
            gp,
            gpp,
        );
        let l = lagrange(
            &[
                (self.m, self.i, crank),
                (self.m, self.i, coupler),
                (self.m, self.i, rocker),
            ],
            self.g,
        );
        (l, (be, ga))
    }

    /// The spring's torque derivative terms: `V′` of gravity and spring at `th`.
    pub fn potential_gradient(&self, l: &Lagrange, th: f64) -> f64 {
        l.vg + self.k * (th - FRAC_PI_2 - self.theta0)
    }

    /// The crank's hinge angle (θ − π/2) from rest at the deck's geometry, sampled every
    /// `every` s up to `end`, by RK4 with step `dt` (its error ~ dt⁴: 1e-20 relative for
    /// dt = 1e-5 s on this motion, far below any integrator's error compared with it).
    pub fn motion(&self, end: f64, dt: f64, every: f64) -> Vec<(f64, f64)> {
        let mut guess = self.start_angles();
        let mut f = |th: f64, w: f64| -> (f64, f64) {
            let (l, ang) = self.at(th, guess);
            guess = ang;
            (w, -(l.q * w * w + self.potential_gradient(&l, th)) / l.j)
        };
        let (mut th, mut w) = (FRAC_PI_2, 0.0);
        let n = (end / dt).round() as usize;
        let k_every = (every / dt).round() as usize;
        let mut out = vec![(0.0, 0.0)];
        for s in 0..n {
            let k1 = f(th, w);
            let k2 = f(th + 0.5 * dt * k1.0, w + 0.5 * dt * k1.1);
            let k3 = f(th + 0.5 * dt * k2.0, w + 0.5 * dt * k2.1);
            let k4 = f(th + dt * k3.0, w + dt * k3.1);
            th += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            w += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
            if (s + 1) % k_every == 0 {
                out.push(((s + 1) as f64 * dt, th - FRAC_PI_2));
            }
        }
        out
    }

    /// The static equilibrium's crank angle by Newton on `V′(θ) = 0` from `th`.
    pub fn equilibrium(&self, mut th: f64) -> f64 {
        let mut guess = self.start_angles();
        // Follow the closure's branch from the start in small steps.
        let n = 200;
        let th_start = FRAC_PI_2;
        for k in 1..=n {
            let t = th_start + (th - th_start) * k as f64 / n as f64;
            guess = self.closure(t, guess);
        }
        for _ in 0..100 {
            let (l, ang) = self.at(th, guess);
            guess = ang;
            let d = self.potential_gradient(&l, th) / (l.vgg + self.k);
            th -= d;
            if d.abs() < 1e-15 {
                break;
            }
        }
        th
    }

    /// The frequency of small oscillations about the equilibrium `th`, Hz:
    /// `√(V″/J) / 2π`.
    pub fn frequency(&self, th: f64, guess: (f64, f64)) -> f64 {
        let (l, _) = self.at(th, guess);
        ((l.vgg + self.k) / l.j).sqrt() / std::f64::consts::TAU
    }
}

/// The slider-crank of `decks/slider_crank_hinges.dat`: crank of length `r` about the
/// origin, rod of length `l`, slider on the X axis; masses at the crank's and the rod's
/// centres and on the slider; the crank driven at constant speed `ω` from `θ₀`.
#[derive(Debug, Clone, Copy)]
pub struct SliderCrank {
    /// Crank length, m.
    pub r: f64,
    /// Rod length, m.
    pub l: f64,
    /// Crank mass (at its centre), kg, and rotary inertia about Z, kg·m².
    pub m1: f64,
    /// Crank's rotary inertia about its centre, kg·m².
    pub i1: f64,
    /// Rod mass (at its centre), kg.
    pub m2: f64,
    /// Rod's rotary inertia about its centre, kg·m².
    pub i2: f64,
    /// Slider mass, kg.
    pub m3: f64,
    /// Gravity (along −Y), m/s².
    pub g: f64,
}

impl SliderCrank {
    /// The slider's position `x(θ)`, m.
    pub fn slider(&self, th: f64) -> f64 {
        self.r * th.cos() + (self.l * self.l - (self.r * th.sin()).powi(2)).sqrt()
    }

    /// The driving torque at constant crank speed `w` (θ̈ = 0): `τ = Q ω² + V′`.
    pub fn torque(&self, th: f64, w: f64) -> f64 {
        let (r, l) = (self.r, self.l);
        let (s, c) = (th.sin(), th.cos());
        let root = (l * l - r * r * s * s).sqrt();
        let u = r * r * s * c;
        let up = r * r * (2.0 * th).cos();
        let rp = -u / root;
        let rpp = -up / root - u * u / root.powi(3);
        // Crank pin P = r e(θ); slider S = (r cos θ + root, 0).
        let p = (ep(th), e(th));
        let (pp, ppp) = ([r * p.0[0], r * p.0[1]], [-r * p.1[0], -r * p.1[1]]);
        let sp = [-r * s + rp, 0.0];
        let spp = [-r * c + rpp, 0.0];
        // Rod angle ψ = atan2(−r sin θ, root): ψ′ = (x y′ − y x′)/l², ψ″ by its derivative.
        let (x, y) = (root, -r * s);
        let (xp, yp) = (rp, -r * c);
        let (xpp, ypp) = (rpp, r * s);
        let psi_p = (x * yp - y * xp) / (l * l);
        let psi_pp = (x * ypp - y * xpp) / (l * l);
        let half = |a: V2, b: V2| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        let crank = (
            [0.5 * pp[0], 0.5 * pp[1]],
            [0.5 * ppp[0], 0.5 * ppp[1]],
            1.0,
            0.0,
        );
        let rod = (half(pp, sp), half(ppp, spp), psi_p, psi_pp);
        let slider = (sp, spp, 0.0, 0.0);
        let lg = lagrange(
            &[
                (self.m1, self.i1, crank),
                (self.m2, self.i2, rod),
                (self.m3, 0.0, slider),
            ],
            self.g,
        );
        lg.q * w * w + lg.vg
    }
}
