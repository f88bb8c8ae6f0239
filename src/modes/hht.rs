//! What a time step resolves: the spectral properties of the time integration scheme
//! (HHT-α, generalized-α) on the undamped oscillator `ẍ + ω²x = 0`, and the table of
//! samples per period, numerical damping and period error for the modes of a model at a
//! deck's step.
//!
//! In the linear case the project's Lie-group schemes of the α family (Arnold & Brüls
//! 2007) are Chung & Hulbert's (1993) generalized-α, HHT being `α_m = 0`, `α_f = −α`: with
//! `X = x`, `V = h v`, `A = h² a` (pseudo-acceleration), `Ā = h² v̇` and `Ω = ω h`,
//! `Ā₁ = −Ω² X₁`, `(1 − α_m) A₁ + α_m A₀ = (1 − α_f) Ā₁ + α_f Ā₀`,
//! `X₁ = X₀ + V₀ + (½ − β) A₀ + β A₁`, `V₁ = V₀ + (1 − γ) A₀ + γ A₁`; eliminating `Ā`:
//! `(1 − α_m) A₁ + Ω²(1 − α_f) X₁ = −α_m A₀ − Ω² α_f X₀`, i.e. `L u₁ = R u₀` on
//! `u = (X, V, A)` and the amplification matrix `𝐀 = L⁻¹R` (Chung & Hulbert 1993, eq. 15).
//! Its principal pair `λ = exp(Ω̄(−ξ̄ ± i))` gives the numerical damping ratio
//! `ξ̄ = −ln|λ| / Ω̄` and the relative period error `T̄/T − 1 = Ω/Ω̄ − 1` (Hughes, *The
//! Finite Element Method*, §9.3.2); the spectral radius at `Ω → ∞` is the scheme's `ρ∞`
//! (HHT: `(1 + α)/(1 − α)`).
//!
//! Another scheme plugs in with an arm in [`spectral`]: its own amplification matrix (any
//! size) and principal root.

use crate::model::Scheme;
use crate::solver::integrator::AlphaParams;
use nalgebra::Matrix3;

/// A scheme's spectral properties at one `Ω = ωh`.
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

/// The amplification matrix of the α family for `Ω = ωh` (module docs).
pub fn amplification(p: &AlphaParams, omega_h: f64) -> Matrix3<f64> {
    let (am, af, b, g) = (p.alpha_m, p.alpha_f, p.beta, p.gamma);
    let w2 = omega_h * omega_h;
    #[rustfmt::skip]
    let l = Matrix3::new(
        1.0, 0.0, -b,
        0.0, 1.0, -g,
        w2 * (1.0 - af), 0.0, 1.0 - am,
    );
    #[rustfmt::skip]
    let r = Matrix3::new(
        1.0, 1.0, 0.5 - b,
        0.0, 1.0, 1.0 - g,
        -w2 * af, 0.0, -am,
    );
    // det L = (1 − α_m) + βΩ²(1 − α_f) > 0 (α_m ≤ ½, α_f < 1): always invertible.
    l.try_inverse()
        .expect("det L = (1 − α_m) + βΩ²(1 − α_f) > 0")
        * r
}

/// The numerical damping ratio and period error of `scheme` at `Ω = ωh` (module docs).
pub fn spectral(scheme: &Scheme, omega_h: f64) -> Spectral {
    // Ω² not a number (an overflowed frequency): the limit Ω → ∞, the scheme's ρ∞ (the
    // matrices below would hold infinities; the ESDIRK phase loop would never end).
    if !(omega_h * omega_h).is_finite() {
        return Spectral {
            omega_h,
            radius: scheme.rho_inf(),
            damping: 0.0,
            period_error: f64::INFINITY,
        };
    }
    match scheme {
        Scheme::Hht { .. } | Scheme::GeneralizedAlpha { .. } => {
            principal_of(&amplification(&AlphaParams::of(scheme), omega_h), omega_h)
        }
        Scheme::Esdirk3 | Scheme::Esdirk5 => {
            // A Runge–Kutta scheme's amplification of the mode is R(iΩ) (module docs of
            // `solver::integrator::esdirk`), its conjugate pair the mode's other root.
            let tab = crate::solver::integrator::esdirk::tableau_of(scheme)
                .expect("an ESDIRK scheme has a tableau");
            // The phase of R(iΩ) followed continuously from Ω = 0 (R is smooth in Ω):
            // beyond Ω = π `arg R` wraps, which read as "no damping, unresolved" for modes
            // the scheme keeps (ESDIRK5 keeps 99 % per step up to Ω ≈ 8) and for modes it
            // damps. Increments of at most 0.05 and 1 % of Ω keep each phase change far
            // below π (measured: the unwrapped phase rises monotonically to 3π/2 for ESDIRK3
            // and ≈ 3.5π for ESDIRK5 as Ω → ∞).
            // At most 100 + ln(Ω/5)/ln(1.01) < 71,500 increments for any finite Ω.
            let r = |w: f64| tab.stability(nalgebra::Complex::new(0.0, w));
            let (mut w, mut z, mut arg) = (0.0f64, r(0.0), 0.0f64);
            while w < omega_h {
                let next = (w + 0.05f64.max(0.01 * w)).min(omega_h);
                let zn = r(next);
                let d = zn / z;
                arg += d.im.atan2(d.re);
                (w, z) = (next, zn);
            }
            Spectral {
                omega_h,
                radius: z.norm(),
                damping: if arg > 0.0 {
                    -z.norm().ln() / arg + 0.0
                } else {
                    0.0
                },
                // Fewer than two steps per period (Ω ≥ π): the period is not resolved.
                period_error: if arg > 0.0 && omega_h < std::f64::consts::PI {
                    omega_h / arg - 1.0
                } else {
                    f64::INFINITY
                },
            }
        }
    }
}

/// Spectral radius, damping and period error from an amplification matrix whose
/// principal pair is its complex pair of largest modulus (the α family's spurious root is
/// real).
fn principal_of(a: &Matrix3<f64>, omega_h: f64) -> Spectral {
    let ev = a.complex_eigenvalues();
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
                damping: -z.norm().ln() / arg + 0.0,
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
    /// The scheme's numerical damping ratio at `ωh` (the name dates from HHT alone; kept
    /// for the files that carry it).
    pub hht_damping: f64,
    /// The scheme's relative period error at `ωh` (`None` when the step does not resolve the
    /// mode: the principal pair is real, or `ωh > π`).
    pub period_error: Option<f64>,
    /// The scheme's spectral radius at `ωh`: the amplitude left of the mode after one step.
    pub radius: f64,
}

/// Spectral radius at or below which a mode is reported "annihilated": the step leaves at
/// most a tenth of it, so after 16 steps at most 1e-16, below round-off of the state; its
/// damping ratio and period (of a pair that is real or past `ωh = π`) mean nothing. Reached
/// by ESDIRK3 (`R(∞) = 0`, L-stable) and generalized-α of small `ρ∞`; never by HHT
/// (`ρ∞ ≥ ½`).
pub const ANNIHILATED_RADIUS: f64 = 0.1;

impl Resolution {
    /// The step leaves at most [`ANNIHILATED_RADIUS`] of the mode.
    pub fn annihilated(&self) -> bool {
        self.radius <= ANNIHILATED_RADIUS
    }
}

/// The resolution of a mode of `frequency_hz` by `scheme` with step `h`.
pub fn resolution(scheme: &Scheme, h: f64, frequency_hz: f64) -> Resolution {
    let omega_h = 2.0 * std::f64::consts::PI * frequency_hz * h;
    let s = spectral(scheme, omega_h);
    Resolution {
        frequency_hz,
        samples_per_period: 1.0 / (frequency_hz * h),
        hht_damping: s.damping,
        period_error: s.period_error.is_finite().then_some(s.period_error),
        radius: s.radius,
    }
}

/// The schemes whose action on each mode `--check` and a run's summary set side by side:
/// the deck's first, then each of HHT, generalized-α, ESDIRK3 and ESDIRK5 that is not the
/// deck's.
/// HHT and generalized-α at the deck's spectral radius at infinity `ρ∞` where it is in
/// their range (the same damping of the unresolved modes, so that the rows differ in what
/// they do to the resolved ones): HHT with `α = (ρ∞ − 1)/(ρ∞ + 1)` when `ρ∞ ≥ ½`, else
/// the default `α = −0.1`; generalized-α with the deck's `ρ∞`, or HHT's when the deck is
/// an ESDIRK scheme (`ρ∞ = 0`). The ESDIRK schemes have no parameter.
pub fn compared_schemes(deck: &Scheme) -> Vec<Scheme> {
    let hht = match *deck {
        Scheme::Hht { .. } => *deck,
        _ => {
            let rho = deck.rho_inf();
            let alpha = (rho - 1.0) / (rho + 1.0);
            if Scheme::alpha_ok(alpha) {
                Scheme::Hht { alpha }
            } else {
                Scheme::default()
            }
        }
    };
    let ga = match *deck {
        Scheme::GeneralizedAlpha { .. } => *deck,
        Scheme::Hht { .. } => Scheme::GeneralizedAlpha {
            rho_inf: deck.rho_inf(),
        },
        Scheme::Esdirk3 | Scheme::Esdirk5 => Scheme::GeneralizedAlpha {
            rho_inf: hht.rho_inf(),
        },
    };
    let mut v = vec![*deck];
    for s in [hht, ga, Scheme::Esdirk3, Scheme::Esdirk5] {
        if s.name() != deck.name() {
            v.push(s);
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An overflowed Ω (a stiffness of 1e308) gives the limit Ω → ∞ of every scheme at
    /// once: the ESDIRK phase loop never ended on it, the α family's 3×3 inverse panicked.
    #[test]
    fn an_overflowed_frequency_gives_the_limit_at_once() {
        for scheme in [
            Scheme::Hht { alpha: -0.1 },
            Scheme::GeneralizedAlpha { rho_inf: 0.8 },
            Scheme::Esdirk3,
            Scheme::Esdirk5,
        ] {
            for w in [f64::INFINITY, 1e200, f64::NAN] {
                let s = spectral(&scheme, w);
                assert_eq!(s.radius, scheme.rho_inf(), "{scheme} Ω {w}");
                assert_eq!(s.period_error, f64::INFINITY);
            }
        }
    }

    #[test]
    fn trapezoidal_rule_is_undamped_with_the_closed_form_period() {
        // α = 0 is the trapezoidal rule: |λ| = 1 exactly and Ω̄ = 2 atan(Ω/2)
        // (λ = (1 − Ω²/4 ± iΩ)/(1 + Ω²/4)). Tolerances: a few ε of the 3×3 eigen-solve.
        for w in [1e-2, 0.1, 0.5, 1.0, 2.0, 10.0] {
            let s = spectral(&Scheme::Hht { alpha: 0.0 }, w);
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
            let hht = Scheme::Hht { alpha };
            // ρ∞ = (1 + α)/(1 − α) (Hilber et al. 1977): at Ω = 1e6 the radius is within
            // O(1/Ω²) = 1e-12 of its limit; 1e-9 leaves room for the eigen-solve.
            let rho = spectral(&hht, 1e6).radius;
            let limit = (1.0 + alpha) / (1.0 - alpha);
            assert!((rho - limit).abs() < 1e-9, "α {alpha}: {rho} vs {limit}");
            // Small steps: HHT is second-order accurate with dissipation of third order
            // (Hilber et al. 1977): ξ̄ = c₁Ω³ + O(Ω⁵), T̄/T − 1 = c₂Ω² + O(Ω⁴), so halving Ω
            // divides ξ̄ by 8 and the period error by 4, to relative O(Ω²) = 1e-4 at
            // Ω = 1e-2 (tolerance 1e-3 for the round-off ε/Ω³ ≈ 2e-10 relative).
            let (a1, a2) = (spectral(&hht, 2e-2), spectral(&hht, 1e-2));
            let (rd, rp) = (a1.damping / a2.damping, a1.period_error / a2.period_error);
            assert!((rd - 8.0).abs() < 8e-3, "α {alpha}: damping ratio {rd}");
            assert!((rp - 4.0).abs() < 4e-3, "α {alpha}: period ratio {rp}");
            let s = a2;
            // The scheme damps more as Ω grows, and never amplifies.
            assert!(spectral(&hht, 1.0).damping > s.damping);
            assert!(spectral(&hht, 1.0).radius <= 1.0 + 1e-12);
        }
    }

    #[test]
    fn generalized_alpha_damps_the_resolved_modes_less_than_hht_at_the_same_rho_inf() {
        // Chung & Hulbert (1993, §4): for one ρ∞, generalized-α's low-frequency damping
        // is the smallest of the family; HHT's is larger. Both have the limit ρ∞ (to
        // O(Ω^(−2/3)) ≈ 1e-4 at Ω = 1e6 for generalized-α, whose three roots meet at −ρ∞).
        // (At ρ∞ = ½, α_m = 0: generalized-α is HHT with α = −1/3, the same scheme.)
        for rho in [0.6, 0.8, 0.9] {
            let [hht, ga] = [
                Scheme::Hht {
                    alpha: (rho - 1.0) / (rho + 1.0),
                },
                Scheme::GeneralizedAlpha { rho_inf: rho },
            ];
            assert_eq!(
                compared_schemes(&ga),
                vec![ga, hht, Scheme::Esdirk3, Scheme::Esdirk5]
            );
            for w in [0.05, 0.2, 0.5] {
                let (a, b) = (spectral(&hht, w), spectral(&ga, w));
                assert!(b.damping < a.damping, "ρ∞ {rho}, Ω {w}: {b:?} vs {a:?}");
            }
            assert!((spectral(&ga, 1e6).radius - rho).abs() < 1e-3);
            assert!((spectral(&hht, 1e6).radius - rho).abs() < 1e-9);
        }
        // ρ∞ < ½ has no HHT counterpart: HHT's default α = −0.1.
        let ga = Scheme::GeneralizedAlpha { rho_inf: 0.2 };
        assert_eq!(
            compared_schemes(&ga),
            vec![ga, Scheme::default(), Scheme::Esdirk3, Scheme::Esdirk5]
        );
    }

    #[test]
    fn resolution_counts_samples_per_period() {
        let r = resolution(&Scheme::default(), 1e-3, 10.0);
        assert!((r.samples_per_period - 100.0).abs() < 1e-9);
        assert!(r.hht_damping > 0.0 && r.period_error.is_some());
    }
}
