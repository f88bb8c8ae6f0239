//! Numerical damping: HHT's spectral radius and period error against the closed form.

use super::*;

/// HHT on a linear spring–mass (`decks/stab_spring_mass.dat`, ω = 100 rad/s): measured
/// spectral radius and period error against the closed forms, for α = 0, −0.1, −1/3, at
/// Ω = ωh = 0.5 and 1.0.
///
/// **Closed form.** The integrator (Arnold–Brüls form with α_m = 0, α_f = −α, β = (1−α)²/4,
/// γ = ½ − α; linearly identical to Hilber–Hughes–Taylor 1977) applied to `ẍ = −ω² x`
/// advances `(x, v, a)` (a the pseudo-acceleration) by
/// ```text
/// x₁ = x₀ + h v₀ + h²(½ − β) a₀ + h² β a₁
/// v₁ = v₀ + h(1 − γ) a₀ + h γ a₁
/// a₁ = (1 − α_f) ẍ₁ + α_f ẍ₀,   ẍ = −ω² x
/// ```
/// i.e. `A y₁ = B y₀` with, for y = (x, h v, h² a) and Ω = ωh,
/// `A = [[1, 0, −β], [0, 1, −γ], [(1−α_f)Ω², 0, 1]]`,
/// `B = [[1, 1, ½−β], [0, 1, 1−γ], [−α_f Ω², 0, 0]]`. The amplification matrix `A⁻¹B` has
/// a pair of principal roots `ρ e^{±iΩ̄}` and a spurious root; the spectral radius is ρ and
/// the relative period error `Ω/Ω̄ − 1`. (Hilber et al.: ρ → (1+α)/(1−α)·… as Ω → ∞,
/// ρ = 1 for α = 0; the period error of the trapezoidal rule is ≈ Ω²/12.)
///
/// **Measured.** Over 20 periods: ρ from the energy `½(v² + ω² x²)` at the first and last
/// upward zero crossings, `(E_N / E_0)^{1/(2 n)}` with n the steps between them; the period
/// from the mean spacing of upward zero crossings (linear interpolation). Both agree with
/// the closed form within 2e-3 (ρ) and 1e-3 + 3 % (period error; the zero-crossing
/// interpolation at 6 steps per period is the limit, at α = −1/3, Ω = 1).
#[test]
fn hht_spectral_radius_and_period_error_match_the_closed_form() {
    if scheme_override().is_some() {
        return;
    }
    let w: f64 = 100.0;
    for alpha in [0.0, -0.1, -1.0 / 3.0] {
        for big_omega in [0.5, 1.0] {
            let h = big_omega / w;
            let (af, beta, gamma) = (-alpha, (1.0 - alpha) * (1.0 - alpha) / 4.0, 0.5 - alpha);
            let o2 = big_omega * big_omega;
            let a = Matrix3::new(1.0, 0.0, -beta, 0.0, 1.0, -gamma, (1.0 - af) * o2, 0.0, 1.0);
            let b = Matrix3::new(
                1.0,
                1.0,
                0.5 - beta,
                0.0,
                1.0,
                1.0 - gamma,
                -af * o2,
                0.0,
                0.0,
            );
            let amp = a.try_inverse().unwrap() * b;
            let ev: Vec<Complex<f64>> = amp.complex_eigenvalues().iter().copied().collect();
            let principal = ev
                .iter()
                .filter(|z| z.im > 1e-12)
                .max_by(|p, q| p.norm().total_cmp(&q.norm()))
                .copied()
                .expect("complex principal roots");
            let rho = principal.norm();
            let period_err = big_omega / principal.arg() - 1.0;

            let periods = 20.0;
            let mut model = deck("stab_spring_mass.dat");
            set_steps(&mut model, h, periods * 2.0 * PI / w, Some(alpha));
            let (r, rec) = run(
                &model,
                Rec {
                    keep_nodes: true,
                    ..Default::default()
                },
            );
            assert!(r.failure.is_none());
            let x: Vec<f64> = rec.nodes.iter().map(|n| n[1].x.x - 1.0).collect();
            let v: Vec<f64> = rec.nodes.iter().map(|n| n[1].v.x).collect();
            let (rho_meas, period_err_meas) =
                common::oscillator::radius_and_period_error(&rec.t, &x, &v, h, w);
            println!(
                "alpha = {alpha:.4}, Omega = {big_omega}: rho {rho_meas:.5} (closed form {rho:.5}), period error {period_err_meas:.5} (closed form {period_err:.5})"
            );
            assert!((rho_meas - rho).abs() < 2e-3, "rho {rho_meas} vs {rho}");
            assert!(
                (period_err_meas - period_err).abs() < 1e-3 + 0.03 * period_err,
                "period error {period_err_meas} vs {period_err}"
            );
        }
    }
}
