//! What each integrator does to a mode: ESDIRK3's and ESDIRK5's closed forms, and
//! `--check`'s comparison of three integrators.

use super::*;

/// ESDIRK3 (Kennedy & Carpenter ESDIRK3(2)4L[2]SA, order p = 3, L-stable) on the
/// undamped oscillator: `R(iθ) = e^{iθ} + c₄(iθ)⁴ + c₅(iθ)⁵ + …`. The real θ⁴ term changes
/// the modulus, `|R| − 1 = c₄θ⁴ + O(θ⁶)`, so `ξ̄ = −ln|R|/arg R = −c₄θ³(1 + O(θ²))`; the
/// phase moves at `O(θ⁵)`, so the period error `θ/arg R − 1 = O(θ⁴)`. Halving θ therefore
/// divides ξ̄ by 8 and the period error by 16, to relative O(θ²) = 1e-4 at θ = 1e-2
/// (1e-3 asserted: the O(θ²) coefficient is a ratio of error constants; round-off: R
/// carries ε, so arg R carries ε and the period error ε/θ = 2e-14 against its 1.5e-10
/// at θ = 1e-2 (c₅ − c₄ ≈ 0.015 measured on the cantilever's rows): 1.5e-4 relative;
/// ξ̄'s |R| − 1 ≈ 2.6e-10 carries ε: 1e-6 relative). L-stable and stiffly accurate:
/// `R(z) = O(1/z)` as `z → ∞`, so the radius falls by 1e3 from Ω = 1e3 to 1e6 (1 %
/// tolerance for the O(1/z²) term) and is below 1e-5 at 1e6.
#[test]
fn esdirk3_spectral_properties_match_its_order_and_l_stability() {
    use mecano::model::Scheme;
    use mecano::modes::hht::spectral;
    let e = Scheme::Esdirk3;
    let (a1, a2) = (spectral(&e, 2e-2), spectral(&e, 1e-2));
    let (rd, rp) = (a1.damping / a2.damping, a1.period_error / a2.period_error);
    eprintln!("ESDIRK3 Ω = 1e-2: {a2:?}; ratios: damping {rd}, period {rp}");
    assert!(a2.damping > 0.0, "dissipative: {a2:?}");
    assert!((rd - 8.0).abs() < 8e-3, "damping ratio {rd}");
    assert!((rp - 16.0).abs() < 16e-3, "period ratio {rp}");
    let (r3, r6) = (spectral(&e, 1e3).radius, spectral(&e, 1e6).radius);
    eprintln!("ESDIRK3 radius: Ω = 1e3 {r3:e}, Ω = 1e6 {r6:e}");
    assert!((r3 / r6 / 1e3 - 1.0).abs() < 1e-2, "{r3} {r6}");
    assert!(r6 < 1e-5);
    // The comparison of `--check` lists four schemes whatever the deck's.
    for deck in [
        Scheme::Esdirk3,
        Scheme::Esdirk5,
        Scheme::default(),
        Scheme::GeneralizedAlpha { rho_inf: 0.3 },
    ] {
        let v = mecano::modes::hht::compared_schemes(&deck);
        let mut names: Vec<&str> = v.iter().map(|s| s.name()).collect();
        assert_eq!(v[0], deck);
        names.sort_unstable();
        assert_eq!(names, ["esdirk3", "esdirk5", "genalpha", "hht"], "{v:?}");
    }
}

/// ESDIRK5's closed form (`R(iθ)` of `ESDIRK5(4)7L[2]SA2`, the scheme of fifth order):
/// `R(iθ) − e^{iθ} = O(θ⁶)`, so `1 − |R| = O(θ⁶)` and `ξ̄ = −ln|R|/arg R = O(θ⁵)`, and
/// `arg R − θ = O(θ⁷)`, so the period error `θ/arg R − 1 = O(θ⁶)`: halving θ from 0.1 to
/// 0.05 divides ξ̄ by 32 and the period error by 64, to relative O(θ²) (measured 0.6 % at
/// θ = 0.2 → 0.1, so ~0.15 % here) plus round-off (ε/(1 − |R|) = 2e-16/7e-13 = 3e-4 at
/// θ = 0.05): 1 % asserted. It keeps the resolved modes: ξ̄ ≤ 1e-9 at θ = 0.1 where
/// ESDIRK3's is 2.6e-5. L-stable: the radius falls by 1e3 from Ω = 1e3 to 1e6.
#[test]
fn esdirk5_spectral_properties_match_its_order_and_l_stability() {
    use mecano::model::Scheme;
    use mecano::modes::hht::spectral;
    let e = Scheme::Esdirk5;
    let (a1, a2) = (spectral(&e, 0.1), spectral(&e, 0.05));
    let (rd, rp) = (a1.damping / a2.damping, a1.period_error / a2.period_error);
    eprintln!("ESDIRK5 Ω = 0.1: {a1:?}; ratios: damping {rd}, period {rp}");
    assert!(a2.damping > 0.0, "dissipative: {a2:?}");
    assert!((rd - 32.0).abs() < 0.32, "damping ratio {rd}");
    assert!((rp - 64.0).abs() < 0.64, "period ratio {rp}");
    assert!(a1.damping < 1e-9 && spectral(&Scheme::Esdirk3, 0.1).damping > 1e-5);
    let (r3, r6) = (spectral(&e, 1e3).radius, spectral(&e, 1e6).radius);
    assert!((r3 / r6 / 1e3 - 1.0).abs() < 1e-2, "{r3} {r6}");
    assert!(r6 < 1e-4);
    // Beyond Ω = π the phase of R wraps; the damping is that of the phase followed from
    // Ω = 0 (review: it read 0, "unresolved", for the modes ESDIRK5 keeps and those it
    // damps). |R| = exp(−ξ̄ φ) with the phase φ between π and 4π (it rises to ≈ 3.5π), so
    // ξ̄ lies between −ln|R|/4π and −ln|R|/π; the period is not resolved (Ω ≥ π).
    for w in [4.0, 8.0, 20.0, 50.0] {
        let a = spectral(&e, w);
        let l = -a.radius.ln();
        assert!(
            a.damping >= l / (4.0 * PI) && a.damping <= l / PI && a.damping > 0.0,
            "Ω = {w}: {a:?}"
        );
        assert!(a.period_error.is_infinite(), "Ω = {w}: {a:?}");
    }
}

/// `--check` on an ESDIRK3 deck compares HHT and generalized-α too and names the highest
/// mode, which ESDIRK3 annihilates (|R| ≤ 0.1 per step), "annihilated"; the sparse path
/// (`--order 1 --refine 64`, 390 unknowns) does not call its last computed mode "highest".
#[test]
fn check_compares_three_integrators_and_sparse_does_not_invent_the_highest() {
    let base = common::TempDir::new("modes_review");
    let _ = std::fs::remove_dir_all(&base);
    std::fs::create_dir_all(&base).unwrap();
    let original = std::fs::read_to_string(deck("cantilever_modes.dat")).unwrap();
    let dynamic = "ANALYSIS DYNAMIC ALPHA 0 STEP 2e-4 END 0.3";
    assert!(original.contains(dynamic));
    let p = base.join("esdirk.dat");
    std::fs::write(
        &p,
        original.replace(dynamic, "ANALYSIS DYNAMIC ESDIRK3 STEP 2e-4 END 0.3"),
    )
    .unwrap();
    let out = mecano(&["--check", p.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    eprintln!("{text}");
    let table = text
        .split("what each integrator does")
        .nth(1)
        .expect("comparison table");
    let head = table.lines().nth(1).unwrap();
    for s in ["esdirk3", "hht:-0.1", "genalpha:0.8182"] {
        assert!(head.contains(s), "{head}");
    }
    let last = table
        .lines()
        .find(|l| l.ends_with("highest"))
        .expect("highest row");
    assert!(last.contains("annihilated"), "{last}");
    assert!(!table.contains("0.000e0 unresolved"), "{table}");
    // Sparse: no "highest" row, a line saying it was not computed.
    let out = mecano(&[
        "modes",
        deck("cantilever_modes.dat").to_str().unwrap(),
        "--order",
        "1",
        "--refine",
        "64",
        "--count",
        "4",
        "-o",
        base.join("sparse").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    eprintln!("{text}");
    assert!(text.contains("SparseSymmetric"), "{text}");
    assert!(!text.lines().any(|l| l.ends_with("highest")), "{text}");
    assert!(text.contains("highest frequency not computed"), "{text}");
    let _ = std::fs::remove_dir_all(&base);
}
