//! What a time step resolves: the spectral properties of HHT-α on the undamped
//! oscillator `ẍ + ω²x = 0`, and the table of samples per period, numerical damping and
//! period error for the modes of a model at a deck's step.
//!
//! In the linear case the project's Lie-group HHT (Arnold & Brüls 2007, `α_m = 0`,
//! `α_f = −α`) is Hilber, Hughes & Taylor's (1977) scheme: with `X = x`, `V = h v`,
//! `A = h² a` and `Ω = ω h`,
//! `A₁ + Ω²[(1 − α_f) X₁ + α_f X₀] = 0`, `X₁ = X₀ + V₀ + (½ − β) A₀ + β A₁`,
//! `V₁ = V₀ + (1 − γ) A₀ + γ A₁`, i.e. `L u₁ = R u₀` and the amplification matrix
//! `𝐀 = L⁻¹R`. Its principal pair `λ = exp(Ω̄(−ξ̄ ± i))` gives the numerical damping
//! ratio `ξ̄ = −ln|λ| / Ω̄` and the relative period error `T̄/T − 1 = Ω/Ω̄ − 1`
//! (Hughes, *The Finite Element Method*, §9.3.2); the spectral radius at `Ω → ∞` is
//! `ρ∞ = (1 + α)/(1 − α)`.

use crate::solver::integrator::HhtParams;
use nalgebra::Matrix3;

/// HHT's spectral properties at one `Ω = ωh`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Spectral {
    /// `Ω = ω h`.
    pub omega_h: f64,
    /// Spectral radius `max |λ|` of the amplification matrix.
    pub radius: f64,
    /// Numerical damping ratio `ξ̄ = −ln|λ₁| / Ω̄` of the principal pair (0 when the pair
    /// has become real: the step does not resolve the mode at all).
    pub damping: f64,
    /// Relative period error `T̄/T − 1 = Ω/Ω̄ − 1` (infinite when the pair is real).
    pub period_error: f64,
}

/// The amplification matrix of HHT-α for `Ω = ωh` (module docs).
pub fn amplification(alpha: f64, omega_h: f64) -> Matrix3<f64> {
    let p = HhtParams::new(alpha);
    let (af, b, g) = (p.alpha_f, p.beta, p.gamma);
    let w2 = omega_h * omega_h;
    #[rustfmt::skip]
    let l = Matrix3::new(
        1.0, 0.0, -b,
        0.0, 1.0, -g,
        w2 * (1.0 - af), 0.0, 1.0,
    );
    #[rustfmt::skip]
    let r = Matrix3::new(
        1.0, 1.0, 0.5 - b,
        0.0, 1.0, 1.0 - g,
        -w2 * af, 0.0, 0.0,
    );
    // det L = 1 + βΩ²(1 − α_f) > 0: always invertible.
    l.try_inverse().expect("det L = 1 + βΩ²(1 − α_f) > 0") * r
}

/// HHT's numerical damping ratio and period error at `Ω = ωh` (module docs).
pub fn spectral(alpha: f64, omega_h: f64) -> Spectral {
    let ev = amplification(alpha, omega_h).complex_eigenvalues();
    let radius = ev.iter().map(|z| z.norm()).fold(0.0, f64::max);
    // The principal root: the one of largest positive argument (the spurious root is real).
    let principal = ev
        .iter()
        .filter(|z| z.im > 0.0)
        .max_by(|a, b| a.norm().total_cmp(&b.norm()));
    match principal {
        Some(z) => {
            let arg = z.im.atan2(z.re);
            Spectral {
                omega_h,
                radius,
                damping: -z.norm().ln() / arg,
                period_error: omega_h / arg - 1.0,
            }
        }
        None => Spectral {
            omega_h,
            radius,
            damping: 0.0,
            period_error: f64::INFINITY,
        },
    }
}

/// One row of the step-resolution table: a mode at the deck's step.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Resolution {
    /// Frequency, Hz.
    pub frequency_hz: f64,
    /// Steps per period `1 / (f h)`.
    pub samples_per_period: f64,
    /// HHT's numerical damping ratio at `ωh`.
    pub hht_damping: f64,
    /// HHT's relative period error at `ωh` (`None` when the step does not resolve the
    /// mode: the principal pair is real, or `ωh > π`).
    pub period_error: Option<f64>,
}

/// The resolution of a mode of `frequency_hz` by HHT-α with step `h`.
pub fn resolution(alpha: f64, h: f64, frequency_hz: f64) -> Resolution {
    let omega_h = 2.0 * std::f64::consts::PI * frequency_hz * h;
    let s = spectral(alpha, omega_h);
    Resolution {
        frequency_hz,
        samples_per_period: 1.0 / (frequency_hz * h),
        hht_damping: s.damping,
        period_error: s.period_error.is_finite().then_some(s.period_error),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoidal_rule_is_undamped_with_the_closed_form_period() {
        // α = 0 is the trapezoidal rule: |λ| = 1 exactly and Ω̄ = 2 atan(Ω/2)
        // (λ = (1 − Ω²/4 ± iΩ)/(1 + Ω²/4)). Tolerances: a few ε of the 3×3 eigen-solve.
        for w in [1e-2, 0.1, 0.5, 1.0, 2.0, 10.0] {
            let s = spectral(0.0, w);
            let exact = w / (2.0 * (w / 2.0).atan()) - 1.0;
            assert!(s.damping.abs() < 1e-12, "Ω {w}: ξ {}", s.damping);
            assert!((s.radius - 1.0).abs() < 1e-12);
            assert!(
                (s.period_error - exact).abs() < 1e-11 * (1.0 + exact.abs()),
                "Ω {w}: {} vs {exact}",
                s.period_error
            );
        }
    }

    #[test]
    fn hht_limits_spectral_radius_and_small_step_damping() {
        // (α = −1/3 is left out: there the three roots meet as Ω → ∞ and the radius reaches
        // its limit only as a fractional power of 1/Ω.)
        for alpha in [-0.05, -0.1, -0.2, -0.3] {
            // ρ∞ = (1 + α)/(1 − α) (Hilber et al. 1977): at Ω = 1e6 the radius is within
            // O(1/Ω²) = 1e-12 of its limit; 1e-9 leaves room for the eigen-solve.
            let rho = spectral(alpha, 1e6).radius;
            let limit = (1.0 + alpha) / (1.0 - alpha);
            assert!((rho - limit).abs() < 1e-9, "α {alpha}: {rho} vs {limit}");
            // Small steps: HHT is second-order accurate with dissipation of third order
            // (Hilber et al. 1977): ξ̄ = c₁Ω³ + O(Ω⁵), T̄/T − 1 = c₂Ω² + O(Ω⁴), so halving Ω
            // divides ξ̄ by 8 and the period error by 4, to relative O(Ω²) = 1e-4 at
            // Ω = 1e-2 (tolerance 1e-3 for the round-off ε/Ω³ ≈ 2e-10 relative).
            let (a1, a2) = (spectral(alpha, 2e-2), spectral(alpha, 1e-2));
            let (rd, rp) = (a1.damping / a2.damping, a1.period_error / a2.period_error);
            assert!((rd - 8.0).abs() < 8e-3, "α {alpha}: damping ratio {rd}");
            assert!((rp - 4.0).abs() < 4e-3, "α {alpha}: period ratio {rp}");
            let s = a2;
            // The scheme damps more as Ω grows, and never amplifies.
            assert!(spectral(alpha, 1.0).damping > s.damping);
            assert!(spectral(alpha, 1.0).radius <= 1.0 + 1e-12);
        }
    }

    #[test]
    fn resolution_counts_samples_per_period() {
        let r = resolution(-0.1, 1e-3, 10.0);
        assert!((r.samples_per_period - 100.0).abs() < 1e-9);
        assert!(r.hht_damping > 0.0 && r.period_error.is_some());
    }
}
