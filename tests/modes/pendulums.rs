//! Pendulums against closed forms and an independent minimal-coordinate model: the seed's
//! double pendulum hanging at rest, the simple and the spherical pendulum, a model without
//! mass.

use super::*;

/// The linearised frequencies (Hz) of the seed's double pendulum hanging at rest, from
/// an independent minimal-coordinate model: bars of mass m_b = ρAL and end inertia
/// J = m_b L²/3 + ρIL (the sections' rotary inertia), tip masses m₁ = m₂ = 1 kg. In the
/// swing plane (θ₁ of bar 1 about O, θ₂ of bar 2 about node 12)
/// M = [J + (m_b + m₁ + m₂)L², (m_b/2 + m₂)L²; ·, J + m₂L²],
/// K = gL diag(3m_b/2 + m₁ + m₂, m_b/2 + m₂); out of the plane, bar 2 about the universal
/// joint's second axis: ω² = gL(m_b/2 + m₂)/(J + m₂L²).
fn double_pendulum_minimal_coordinates() -> Vec<f64> {
    let (rho, area, inertia, l, g, m1, m2) = (
        7800.0f64, 9e-4f64, 8.3e-8f64, 1.0f64, 9.81f64, 1.0f64, 1.0f64,
    );
    let mb = rho * area * l;
    let j = mb * l * l / 3.0 + rho * inertia * l;
    let (a11, a12, a22) = (
        j + (mb + m1 + m2) * l * l,
        (mb / 2.0 + m2) * l * l,
        j + m2 * l * l,
    );
    let (k1, k2) = (g * l * (1.5 * mb + m1 + m2), g * l * (mb / 2.0 + m2));
    // det(K − ω²M) = 0: (a11 a22 − a12²) ω⁴ − (k1 a22 + k2 a11) ω² + k1 k2 = 0.
    let (qa, qb, qc) = (a11 * a22 - a12 * a12, -(k1 * a22 + k2 * a11), k1 * k2);
    let disc = (qb * qb - 4.0 * qa * qc).sqrt();
    let mut f: Vec<f64> = [
        (-qb - disc) / (2.0 * qa),
        (-qb + disc) / (2.0 * qa),
        k2 / (j + m2 * l * l),
    ]
    .iter()
    .map(|w2| w2.sqrt() / (2.0 * PI))
    .collect();
    f.sort_by(f64::total_cmp);
    f
}

/// Checks the three pendulum modes of the hanging deck with Young's modulus `e`.
fn check_hanging_pendulum(e: &str) {
    let text = std::fs::read_to_string(deck("pendulum_rigid_hanging.dat")).unwrap();
    let model = model_from(&text.replace("E 2.1e15", &format!("E {e}")));
    let a = modes(&model, About::Static, 4);
    let f: Vec<f64> = a.modes.iter().map(|m| m.natural_hz).collect();
    let exact = double_pendulum_minimal_coordinates();
    eprintln!(
        "hanging pendulum, E = {e}: {f:?} Hz; minimal coordinates {exact:?} Hz; highest {:.3e} Hz",
        a.highest_hz
    );
    assert_eq!(a.rigid_modes, 0);
    // Tolerance, derived: (1) the round-off of the assembled stiffness, ZERO_FACTOR ε ω²_max
    // relative to ω² (a worst case over mode shapes; the stiff bars make it large);
    // (2) the bars' compliance, which lowers a pendulum frequency by about (f/f_e)²/2 with
    // f_e the lowest elastic frequency (mode 4): we allow (f/f_e)².
    let wmax2 = (2.0 * PI * a.highest_hz).powi(2);
    for (fi, ei) in f[..3].iter().zip(&exact) {
        let w2 = (2.0 * PI * ei).powi(2);
        let tol =
            mecano::modes::dense::ZERO_FACTOR * f64::EPSILON * wmax2 / w2 + (fi / f[3]).powi(2);
        let rel = (fi - ei).abs() / ei;
        eprintln!("  {fi} vs {ei}: relative {rel:.2e} (tolerance {tol:.2e})");
        assert!(rel < tol, "E = {e}: {fi} vs {ei}");
    }
}

#[test]
fn rigid_seed_pendulum_about_its_hanging_equilibrium_matches_minimal_coordinates() {
    // decks/pendulum_rigid_hanging.dat: the seed's double pendulum (rigid case,
    // E = 2.1e15) hanging at rest, linearised about the static equilibrium under gravity.
    check_hanging_pendulum("2.1e15");
    // The rigid case's bars are so stiff (f_max ≈ 5e6 Hz) that the round-off bound is loose
    // (1.5e-2 on the out-of-plane mode); at E = 2.1e13 it is 100 times tighter while the
    // compliance stays small, and the same independent model is met to it.
    check_hanging_pendulum("2.1e13");
}

/// The simple pendulum (decks/simple_pendulum.dat: 1 kg at the end of a 1 m massless link,
/// released with the link horizontal): about that state gravity gives no restoring moment
/// (`∂(m g L cos θ)/∂θ = 0` at θ = 90° from the vertical), so its one mode is a zero, not a
/// round-off frequency of 2e-13 Hz called unstable with ζ = −1. Hanging (node 2 moved below
/// the pivot), its mode is `ω² = g/L`: f = √9.81 / 2π = 0.498488 Hz, to the Rayleigh
/// quotient's round-off (1e-12 relative; 1e-9 asserted).
#[test]
fn simple_pendulum_single_mode_is_a_zero_or_its_closed_form() {
    let model = load(&deck("simple_pendulum.dat"), &[], 1, None).unwrap();
    let a = modes(&model, About::Initial, 1);
    eprintln!(
        "simple pendulum, horizontal: {:?}, highest {} Hz",
        a.modes
            .iter()
            .map(|m| (m.kind, m.natural_hz, m.damping_ratio))
            .collect::<Vec<_>>(),
        a.highest_hz
    );
    assert_eq!(a.modes.len(), 1);
    assert_eq!(a.modes[0].kind, ModeKind::Rigid);
    assert_eq!(a.rigid_modes, 1);
    assert_eq!(a.highest_hz, 0.0, "no finite frequency");
    // Hanging.
    let text = std::fs::read_to_string(deck("simple_pendulum.dat")).unwrap();
    assert!(text.contains("\n  2  1 0 0\n"));
    let hanging = model_from(&text.replace("\n  2  1 0 0\n", "\n  2  0 -1 0\n"));
    let a = modes(&hanging, About::Initial, 1);
    let exact = 9.81f64.sqrt() / (2.0 * PI);
    eprintln!(
        "simple pendulum, hanging: {} Hz (exact {exact}), kind {:?}, ζ {}",
        a.modes[0].natural_hz, a.modes[0].kind, a.modes[0].damping_ratio
    );
    assert_eq!(a.modes[0].kind, ModeKind::Elastic);
    assert!((a.modes[0].natural_hz - exact).abs() <= 1e-9 * exact);
    assert_eq!(a.rigid_modes, 0);
}

/// A model without mass refuses any count as "nothing to vibrate", not as too many modes
/// of a made-up finite count: the simple pendulum without its MASS.
#[test]
fn massless_model_is_refused_before_the_count() {
    let text = std::fs::read_to_string(deck("simple_pendulum.dat")).unwrap();
    assert!(text.contains("  2  MASS 2 M 1\n"));
    let model = model_from(&text.replace("  2  MASS 2 M 1\n", ""));
    let err = analyse_model(&model, About::Initial, 10)
        .map(|_| ())
        .expect_err("no mass");
    eprintln!("massless: {}", err.message);
    assert!(err.message.contains("no mass"), "{}", err.message);
}

/// A spherical pendulum hanging at rest (decks/spherical_pendulum_modes.dat: 1 kg on a rigid
/// 1 m link, rotary inertia I = 1e-3 kg·m² about each axis, SPHERICAL at the pivot): two
/// swings at `ω² = m g L/(m L² + I)` (the link turns with the mass: its rotary inertia adds
/// to `m L²`), f = 0.49824 Hz, and the spin about the vertical link, which nothing resists:
/// a zero, "rigid". It was listed as an elastic (or, negative, "unstable") mode of
/// ω² = 1.9e-13 1/s²: round-off of a stiffness of norm ~10 N·m seen through the spin's mass
/// I = 1e-3 (src/modes/mod.rs, the per-mode zero threshold). The swings to the Rayleigh
/// quotient's round-off (1e-9 relative asserted, as the simple pendulum's).
#[test]
fn spherical_pendulum_spin_is_rigid_and_its_swings_match_the_closed_form() {
    let model = load(&deck("spherical_pendulum_modes.dat"), &[], 1, None).unwrap();
    let a = modes(&model, About::Initial, 3);
    let z: Vec<(ModeKind, f64)> = a.modes.iter().map(|m| (m.kind, m.natural_hz)).collect();
    let exact = (9.81f64 / (1.0 + 1e-3)).sqrt() / (2.0 * PI);
    eprintln!("spherical pendulum: {z:?} (swing exact {exact} Hz)");
    assert_eq!(a.modes.len(), 3);
    assert_eq!(a.rigid_modes, 1, "{z:?}");
    assert_eq!(a.modes[0].kind, ModeKind::Rigid, "{z:?}");
    assert_eq!(a.modes[0].natural_hz, 0.0, "{z:?}");
    for m in &a.modes[1..] {
        assert_eq!(m.kind, ModeKind::Elastic, "{z:?}");
        assert!((m.natural_hz - exact).abs() <= 1e-9 * exact, "{z:?}");
    }
}
