//! The α schemes' bound on a run of steps (`docs/stability.md`, "The energy guard's bound"):
//! how far the physical energy of a linear mode can rise along the scheme's own orbit.
//!
//! One step of the α family (Arnold & Brüls' form of `integrator::AlphaParams`) on the
//! oscillator `ẍ + ω²x = 0`, in the scaled state `(X, V, Y) = (ωx, v, h a)` (`a` the
//! pseudo-acceleration, the true one `v̇ = −ω²x` at both ends), is a 3×3 matrix `A(Ω)` of
//! `Ω = ωh` alone. Its principal pair `λ, λ̄` (`|λ| ≤ 1`) spans the states the scheme
//! reaches once the third (spurious) root has decayed; along that orbit the state is
//! `|λ|^k (cos ψ_k b₁ − sin ψ_k b₂)` (`b₁ + i b₂` the eigenvector), so the physical energy
//! `E = ½(X² + V²)` stays within the ratio `r(Ω) = μ_max/μ_min` of the 2×2 Gram matrix of
//! `b₁, b₂` (their `X, V` parts) of its value at any earlier step, and the rise over a
//! run of steps is at most `(r − 1) E`. Summed over the modes of a linear(ised) system:
//! `E(t) − E(s) ≤ g E(s)` with `g = sup (r(Ω) − 1)`, the supremum over the modes the step
//! represents as oscillations, `Ω ≤ π` (beyond, a step is longer than half a period: the
//! mode is aliased; retrying the step shorter brings it back under π). Where the two
//! largest roots are real (none for `Ω ≤ π` in the family's usual range) the same Gram
//! ratio bounds the energy of any combination of the two decaying eigenvectors.
//! The trapezoidal rule (`α = 0`) gives `g = 0`: it conserves the energy of a linear
//! system exactly. The stage schemes (ESDIRK) have no pseudo-acceleration: on a linear
//! system `E_{n+1} = |R(iΩ)|² E_n ≤ E_n` mode by mode, `g = 0`.

use crate::solver::AlphaParams;
use nalgebra::{Complex, Matrix3, Vector3};
use std::f64::consts::PI;

/// `A(Ω)` of the module docs: the scaled state after one step from each unit state.
pub fn amplification(p: &AlphaParams, om: f64) -> Matrix3<f64> {
    let step = |s: Vector3<f64>| -> Vector3<f64> {
        // h = 1, ω = Ω.
        let (x0, v0, a0) = (s[0] / om, s[1], s[2]);
        let w2 = om * om;
        // (1 − α_m) a₁ + α_m a₀ = (1 − α_f) v̇₁ + α_f v̇₀, v̇ = −ω² x,
        // x₁ = x₀ + v₀ + (½ − β) a₀ + β a₁.
        let free = x0 + v0 + (0.5 - p.beta) * a0;
        let a1 = (-p.alpha_m * a0 - (1.0 - p.alpha_f) * w2 * free - p.alpha_f * w2 * x0)
            / ((1.0 - p.alpha_m) + (1.0 - p.alpha_f) * w2 * p.beta);
        let x1 = free + p.beta * a1;
        let v1 = v0 + (1.0 - p.gamma) * a0 + p.gamma * a1;
        Vector3::new(om * x1, v1, a1)
    };
    Matrix3::from_columns(&[step(Vector3::x()), step(Vector3::y()), step(Vector3::z())])
}

/// `r(Ω) − 1` of the module docs: the largest relative rise of the physical energy along
/// the scheme's principal orbit at `Ω`.
pub fn orbit_rise(p: &AlphaParams, om: f64) -> f64 {
    let a = amplification(p, om);
    let ev = a.complex_eigenvalues();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| ev[j].norm().total_cmp(&ev[i].norm()));
    let lam = ev[order[0]];
    let (b1, b2) = if lam.im.abs() > 1e-12 * lam.norm().max(1e-300) {
        let v = null_vector(&a, lam);
        (v.map(|c| c.re), v.map(|c| c.im))
    } else {
        // Two real roots: their (real) eigenvectors.
        let v1 = null_vector(&a, Complex::new(ev[order[0]].re, 0.0)).map(|c| c.re);
        let v2 = null_vector(&a, Complex::new(ev[order[1]].re, 0.0)).map(|c| c.re);
        (v1, v2)
    };
    // Gram matrix of the X, V parts.
    let g11 = b1[0] * b1[0] + b1[1] * b1[1];
    let g22 = b2[0] * b2[0] + b2[1] * b2[1];
    let g12 = b1[0] * b2[0] + b1[1] * b2[1];
    let mean = 0.5 * (g11 + g22);
    let dev = (0.25 * (g11 - g22).powi(2) + g12 * g12).sqrt();
    let (hi, lo) = (mean + dev, mean - dev);
    if lo <= 0.0 || !(hi / lo).is_finite() {
        return f64::INFINITY;
    }
    hi / lo - 1.0
}

/// A null vector of `A − λI` (λ an eigenvalue): the cross product of the two rows that
/// give the largest one (rows of a rank-2 matrix; the bilinear cross product is
/// orthogonal to both, so `(A − λI) v = 0`).
fn null_vector(a: &Matrix3<f64>, lam: Complex<f64>) -> Vector3<Complex<f64>> {
    let m = a.map(|x| Complex::new(x, 0.0)) - Matrix3::from_diagonal_element(lam);
    let row = |i: usize| Vector3::new(m[(i, 0)], m[(i, 1)], m[(i, 2)]);
    let cross = |u: Vector3<Complex<f64>>, w: Vector3<Complex<f64>>| {
        Vector3::new(
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        )
    };
    let cands = [
        cross(row(0), row(1)),
        cross(row(0), row(2)),
        cross(row(1), row(2)),
    ];
    let norm = |v: &Vector3<Complex<f64>>| v.iter().map(|c| c.norm_sqr()).sum::<f64>();
    let best = cands
        .iter()
        .max_by(|u, w| norm(u).total_cmp(&norm(w)))
        .copied()
        .unwrap_or_else(Vector3::zeros);
    let n = norm(&best).sqrt();
    if n > 0.0 {
        best / Complex::new(n, 0.0)
    } else {
        best
    }
}

/// Points of the grid of `Ω` the supremum is taken on, less one.
const GRID: usize = 2000;
/// Every `COARSE`-th point of the grid is searched first ([`run_bound`]).
const COARSE: usize = 10;

/// Point `k` of the grid of `Ω` the supremum is taken on: 2001 points, geometric from 1e-4
/// to π (the rise is `O(Ω²)` below; the grid's relative spacing 0.46 % moves a smooth
/// maximum by `O(1e-5)` of itself).
fn grid_point(k: usize) -> f64 {
    PI * 10f64.powf(-4.0 * (1.0 - k as f64 / GRID as f64))
}

/// The grid of `Ω` the supremum is taken on ([`grid_point`]).
pub fn grid() -> impl Iterator<Item = f64> {
    (0..=GRID).map(grid_point)
}

/// `g` of the module docs for an α scheme: `sup_{Ω ≤ π} (r(Ω) − 1)` on the grid. The rise
/// is a smooth function of `Ω` with a single maximum (interior or at π), so the grid's
/// largest value lies between the neighbours of the largest of every tenth point: those
/// 201 points, then the 18 grid points between the neighbours, give the same value as the
/// 2001 (a test compares the two over the α family) in a ninth of the time — 2.4 ms of
/// every run's start on this machine (each point is a 3 × 3 eigenproblem).
pub fn run_bound(p: &AlphaParams) -> f64 {
    let (mut best, mut at) = (0.0f64, 0);
    for k in (0..=GRID).step_by(COARSE) {
        let r = orbit_rise(p, grid_point(k));
        if r > best {
            (best, at) = (r, k);
        }
    }
    let lo = at.saturating_sub(COARSE - 1);
    let hi = (at + COARSE - 1).min(GRID);
    (lo..=hi)
        .filter(|k| k % COARSE != 0)
        .map(|k| orbit_rise(p, grid_point(k)))
        .fold(best, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The physical energy along the scheme's own orbit, iterated with the scalar
    /// recurrence (not the matrix): the largest `E_{n+k}/E_n − 1` over 4000 steps after
    /// 400 steps that let the spurious root decay, each step's ratio divided by `decay`
    /// (`|λ|²`: what the orbit loses per turn, so that the shape alone is measured).
    fn brute_rise(p: &AlphaParams, om: f64, decay: f64) -> f64 {
        let (mut x, mut v, mut a) = (1.0 / om, 0.3, -0.7);
        let w2 = om * om;
        let energy = |x: f64, v: f64| 0.5 * (w2 * x * x + v * v);
        // Growth factors E_{k+1}/E_k, the state renormalised to E = 1 after each step.
        let mut factors = Vec::new();
        for k in 0..4400 {
            let e0 = energy(x, v);
            let free = x + v + (0.5 - p.beta) * a;
            let a1 = (-p.alpha_m * a - (1.0 - p.alpha_f) * w2 * free - p.alpha_f * w2 * x)
                / ((1.0 - p.alpha_m) + (1.0 - p.alpha_f) * w2 * p.beta);
            v += (1.0 - p.gamma) * a + p.gamma * a1;
            x = free + p.beta * a1;
            a = a1;
            let e1 = energy(x, v);
            if k >= 400 {
                factors.push(e1 / e0 / decay);
            }
            let s = e1.sqrt();
            (x, v, a) = (x / s, v / s, a / s);
        }
        // Largest E_k/E_j − 1 over j ≤ k.
        let (mut best, mut log_e, mut log_min) = (0.0f64, 0.0f64, 0.0f64);
        for f in factors {
            log_e += f.ln();
            best = best.max((log_e - log_min).exp() - 1.0);
            log_min = log_min.min(log_e);
        }
        best
    }

    /// The bound is the sharp supremum of what the recurrence does: at each Ω the rise
    /// along the orbit never exceeds `r − 1` (to 1e-9), and with the orbit's decay `|λ|²`
    /// per step taken out it comes within 2 % of it (4000 steps sweep the orbit's phases);
    /// the trapezoidal rule rises by nothing (round-off).
    #[test]
    fn orbit_rise_matches_the_recurrence() {
        for p in [
            AlphaParams::new(-0.1),
            AlphaParams::new(-1.0 / 3.0),
            AlphaParams::generalized(0.8),
        ] {
            for om in [0.3, 1.0, 2.0, 3.0, PI] {
                let r = orbit_rise(&p, om);
                let b = brute_rise(&p, om, 1.0);
                assert!(b <= r + 1e-9, "{p:?} Ω = {om}: brute {b} > bound {r}");
                let lam = amplification(&p, om)
                    .complex_eigenvalues()
                    .iter()
                    .map(|c| c.norm())
                    .fold(0.0, f64::max);
                let shape = brute_rise(&p, om, lam * lam);
                assert!(
                    shape <= r * 1.0001 + 1e-9 && shape >= 0.98 * r,
                    "{p:?} Ω = {om}: orbit shape {shape} against {r}"
                );
            }
        }
        let trap = AlphaParams::new(0.0);
        assert!(run_bound(&trap) < 1e-10, "{}", run_bound(&trap));
    }

    /// The coarse-then-fine search of [`run_bound`] finds the largest value of the whole
    /// grid, bit for bit, over the α family: HHT α from −1/3 to 0 and generalized-α ρ∞ from
    /// 0 to 1.
    #[test]
    fn the_coarse_then_fine_search_finds_the_grids_largest_value() {
        let hht = (0..=40).map(|i| AlphaParams::new(-f64::from(i) / 120.0));
        let galpha = (0..=40).map(|i| AlphaParams::generalized(f64::from(i) / 40.0));
        for p in hht.chain(galpha) {
            let whole = grid().map(|om| orbit_rise(&p, om)).fold(0.0, f64::max);
            assert_eq!(run_bound(&p), whole, "{p:?}");
        }
    }

    /// The values docs/stability.md quotes (HHT α = −0.1, −0.05, −1/3; generalized-α
    /// ρ∞ = 0.8), and the supremum is at an interior Ω or at π (printed).
    #[test]
    fn run_bounds_of_the_usual_schemes() {
        for (name, p) in [
            ("hht -0.1", AlphaParams::new(-0.1)),
            ("hht -0.05", AlphaParams::new(-0.05)),
            ("hht -1/3", AlphaParams::new(-1.0 / 3.0)),
            ("genalpha 0.8", AlphaParams::generalized(0.8)),
        ] {
            let g = run_bound(&p);
            println!("{name}: g = {g:.4}");
            assert!(g.is_finite() && g > 0.0 && g < 1.0, "{name}: {g}");
        }
        let g = run_bound(&AlphaParams::new(-0.1));
        assert!((g - orbit_rise(&AlphaParams::new(-0.1), PI)).abs() <= 1e-12 || g > 0.2);
    }
}
