//! The sparse shift-invert Lanczos path of `mecano-rs modes` (issue 24 §3; src/modes/sparse.rs)
//! against the dense path on the same models, and against the cantilever's closed form.

use crate::common;

use mecano::app::modes::{About, analyse_model_using, load};
use mecano::model::Model;
use mecano::modes::{Method, ModalAnalysis, ModeKind, Solver};

fn modes(model: &Model, count: usize, solver: Solver) -> ModalAnalysis {
    analyse_model_using(model, About::Initial, count, solver)
        .map_err(|f| f.message)
        .expect("modal analysis")
        .1
}

fn model_from(text: &str) -> Model {
    mecano::deck::parse_deck(text, "test.dat").expect("valid deck")
}

/// A clamped steel beam along X hinged (about Z) at its tip to a second beam along Y whose
/// far end is pinned to the ground by a spherical joint: 306 nodal unknowns and 8
/// constraint equations (the saddle point of the sparse path), no mechanism, no load.
const FRAME: &str = "TITLE clamped beam hinged to a pinned beam
MATERIALS
  1 E 2.1e11 NU 0.3 RHO 7800
SECTIONS
  1 A 9e-4 I2 8.3e-8 I3 1.2e-7 J 4.15e-8 K 0.8333333333333334
NODES
  1 0 0 0 FIX ALL
  2 1 0 0
  3 1 0 0
  4 1 1.3 0
  5 1 1.3 0 FIX ALL
ELEMENTS
  1 BEAM 1 2 MAT 1 SEC 1 AXIS2 0 0 1 DIVIDE 25
  2 HINGE 2 3 AXIS 0 0 1
  3 BEAM 3 4 MAT 1 SEC 1 AXIS2 0 0 1 DIVIDE 25
  4 SPHERICAL 4 5
  5 MASS 2 M 1
ANALYSIS DYNAMIC STEP 1e-4 END 1e-3
OUTPUT NODES 2 ELEMENTS NONE
";

/// `max_i |a_i − s b_i| / max |b|` with the sign `s` that makes it smallest.
fn shape_difference(a: &[f64], b: &[f64]) -> f64 {
    let big = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let d = |s: f64| {
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - s * y).abs()))
    };
    d(1.0).min(d(-1.0)) / big
}

#[test]
fn sparse_lanczos_agrees_with_the_dense_solve_on_a_constrained_frame() {
    let model = model_from(FRAME);
    let count = 12;
    let dense = modes(&model, count, Solver::Dense);
    let sparse = modes(&model, count, Solver::Sparse);
    assert_eq!(dense.method, Method::Symmetric);
    assert_eq!(sparse.method, Method::SparseSymmetric);
    assert_eq!(dense.free_unknowns, 306 - 8);
    assert_eq!(sparse.free_unknowns, dense.free_unknowns);
    assert_eq!(sparse.constraints, dense.constraints);
    assert_eq!((dense.rigid_modes, sparse.rigid_modes), (0, 0));
    for (i, (d, s)) in dense.modes.iter().zip(&sparse.modes).enumerate() {
        let rel = (s.natural_hz - d.natural_hz).abs() / d.natural_hz;
        eprintln!(
            "mode {}: dense {:.12e} Hz, sparse {:.12e} Hz, relative {rel:.2e}",
            i + 1,
            d.natural_hz,
            s.natural_hz
        );
        // The 1e-8: both solve the same assembled matrices (the same element
        // evaluations, summed in the same order); what differs is each solver's round-off,
        // ε times the condition of the shifted operator on these modes.
        assert!(rel < 1e-8, "mode {}: {rel:e}", i + 1);
        assert_eq!(s.kind, ModeKind::Elastic);
    }
    // Shapes (mass-normalised by both) where the mode is separated from its neighbours by
    // more than 1 %: a shape's error is its residual over the gap, ≤ 1e-9/1e-2.
    for i in 0..count {
        let f = |k: usize| dense.modes[k].natural_hz;
        let gap = [i.wrapping_sub(1), i + 1]
            .iter()
            .filter(|&&k| k < dense.modes.len())
            .map(|&k| (f(k) - f(i)).abs() / f(i))
            .fold(f64::INFINITY, f64::min);
        if gap < 1e-2 {
            continue;
        }
        let diff = shape_difference(&sparse.modes[i].shape, &dense.modes[i].shape);
        assert!(diff < 1e-6, "mode {}: shape differs by {diff:e}", i + 1);
    }
    // Energy shares computed from the same element matrices.
    for (d, s) in dense.modes.iter().zip(&sparse.modes) {
        for (a, b) in d.kinetic_share.iter().zip(&s.kinetic_share) {
            assert!((a - b).abs() < 1e-6);
        }
    }
}

/// The Timoshenko frequencies of the cantilever with a 1 kg tip mass (tests/modes/main.rs).
const TIMOSHENKO_HZ: [f64; 3] = [22.19447, 148.11007, 426.61513];

#[test]
fn cantilever_frequencies_through_the_sparse_path() {
    // decks/cantilever_modes.dat with its beam cut into 8 beams of order 12 (8·12 nodes,
    // 576 unknowns): the sparse path, the frequencies to the 1e-6.
    let model = load(&common::deck_path("cantilever_modes.dat"), &[], 8, None).unwrap();
    let a = modes(&model, 8, Solver::Sparse);
    assert_eq!(a.method, Method::SparseSymmetric);
    assert_eq!(a.free_unknowns, 8 * 12 * 6);
    let f: Vec<f64> = a.modes.iter().map(|m| m.natural_hz).collect();
    eprintln!("cantilever, sparse: {f:?}");
    for target in TIMOSHENKO_HZ {
        // 1e-6 relative plus half a unit of the reference's last digit; each twice (two
        // bending planes, I2 = I3: the block finds both copies). Between them lie axial
        // and torsional modes (402 Hz), as in the dense solve.
        let tol = 1e-6 * target + 0.5e-5;
        let hits = f.iter().filter(|x| (*x - target).abs() <= tol).count();
        assert_eq!(hits, 2, "{target} Hz in {f:?}");
    }
}

#[test]
fn free_free_beam_through_the_sparse_path_has_six_rigid_modes() {
    // A free steel beam, 10 m, 4 elements of order 8 (tests/modes/beams.rs's): the block of six
    // finds the six rigid motions (θ = 1/|σ|, ω² exact to ε|σ|), then the elastic modes as
    // the dense path does.
    let deck = "TITLE free-free beam
MATERIALS
  1 E 2.1e11 NU 0.3 RHO 7800
SECTIONS
  1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8 K 0.8333333333333334
NODES
  1 0 0 0
  2 10 0 0
ELEMENTS
  1 BEAM 1 2 MAT 1 SEC 1 DIVIDE 4 ORDER 8
ANALYSIS DYNAMIC ALPHA -0.1 STEP 1e-3 END 1
";
    let model = model_from(deck);
    let dense = modes(&model, 10, Solver::Dense);
    let sparse = modes(&model, 10, Solver::Sparse);
    assert_eq!((dense.rigid_modes, sparse.rigid_modes), (6, 6));
    for (d, s) in dense.modes.iter().zip(&sparse.modes).skip(6) {
        let rel = (s.natural_hz - d.natural_hz).abs() / d.natural_hz;
        eprintln!(
            "free-free: dense {} Hz, sparse {} Hz",
            d.natural_hz, s.natural_hz
        );
        assert!(rel < 1e-8, "{} vs {} Hz", s.natural_hz, d.natural_hz);
    }
}

/// [`FRAME`] with its material made a Kelvin–Voigt solid of damping coefficient `eta`
/// (grammar.md, `DAMPING`).
fn damped_frame(eta: f64) -> String {
    FRAME.replace(
        "1 E 2.1e11 NU 0.3 RHO 7800",
        &format!("1 E 2.1e11 NU 0.3 RHO 7800 DAMPING {eta}"),
    )
}

#[test]
fn proportionally_damped_frame_through_the_sparse_state_space_path() {
    // Material damping alone: at the unstressed initial state the damping matrix is
    // η times the material stiffness, C = ηK (grammar.md, DAMPING), so each undamped mode
    // (K φ = ω² M φ) is a damped one with λ² + ηω²λ + ω² = 0: |λ| = ω and ζ = ηω/2
    // exactly. The reference ω comes from the conservative sparse solve of the same frame
    // (which agrees with the dense one to 2.8e-12, above). η = 1e-5 s gives ζ from 1e-3 to
    // a few 1e-2 over the 12 modes.
    let eta = 1e-5;
    let reference = modes(&model_from(FRAME), 12, Solver::Sparse);
    let damped = modes(&model_from(&damped_frame(eta)), 12, Solver::Sparse);
    assert_eq!(reference.method, Method::SparseSymmetric);
    assert_eq!(damped.method, Method::SparseStateSpace);
    assert_eq!(damped.free_unknowns, 306 - 8);
    for (i, (r, d)) in reference.modes.iter().zip(&damped.modes).enumerate() {
        let w = 2.0 * std::f64::consts::PI * r.natural_hz;
        let zeta = eta * w / 2.0;
        let rel = (d.natural_hz - r.natural_hz).abs() / r.natural_hz;
        eprintln!(
            "mode {}: {:.10e} Hz, ζ {:.6e} (reference ζ = ηω/2 = {zeta:.6e}), |λ| relative {rel:.2e}",
            i + 1,
            d.natural_hz,
            d.damping_ratio
        );
        // The Arnoldi pair's Krylov residual is below 1e-9 |μ| and, the damping being
        // proportional, the first-order operator is diagonalised by the undamped modes
        // (eigenvalue condition 1/√(1 − ζ²) ≈ 1): |δμ|/|μ| ≤ ~1e-9, and
        // |δλ|/|λ| = |δμ|/|μ| · |λ − σ|/|λ| ≤ 2e-9 with σ < |λ| here. 1e-8 leaves a factor 5.
        assert!(rel < 1e-8, "mode {}: |λ| {rel:e}", i + 1);
        // ζ = −Re λ/|λ|: its error is at most |δλ|/|λ|.
        assert!(
            (d.damping_ratio - zeta).abs() < 1e-8,
            "mode {}: ζ {} vs {zeta}",
            i + 1,
            d.damping_ratio
        );
        // Damped frequency ω√(1 − ζ²).
        let fd = r.natural_hz * (1.0 - zeta * zeta).sqrt();
        assert!((d.frequency_hz - fd).abs() < 1e-8 * fd);
        assert_eq!(d.kind, ModeKind::Elastic);
    }
}

/// The lowest `n` modes compared: natural frequencies relative, damping ratios absolute.
fn compare(dense: &ModalAnalysis, sparse: &ModalAnalysis, tol: f64, what: &str) -> f64 {
    let mut worst: f64 = 0.0;
    let el = |a: &ModalAnalysis| -> Vec<(f64, f64, f64)> {
        a.modes
            .iter()
            .filter(|m| m.kind == ModeKind::Elastic)
            .map(|m| (m.natural_hz, m.frequency_hz, m.damping_ratio))
            .collect()
    };
    let (d, s) = (el(dense), el(sparse));
    assert!(d.len() >= 8 && s.len() >= 8, "{what}: {d:?} {s:?}");
    for (i, (a, b)) in d.iter().zip(&s).enumerate() {
        let rel = (a.0 - b.0).abs() / a.0;
        let rd = (a.1 - b.1).abs() / a.0;
        let dz = (a.2 - b.2).abs();
        eprintln!(
            "{what} mode {}: dense {:.10e} Hz ζ {:.6e}, sparse {:.10e} Hz ζ {:.6e}: {rel:.1e} {rd:.1e} {dz:.1e}",
            i + 1,
            a.0,
            a.2,
            b.0,
            b.2
        );
        worst = worst.max(rel).max(rd).max(dz);
        assert!(rel < tol && rd < tol && dz < tol, "{what} mode {}", i + 1);
    }
    worst
}

/// A chain of `n` rigid bodies (1 kg, inertias 0.01–0.03 kg m²) 0.1 m apart along X on
/// BUSHINGs (direction-dependent stiffnesses), the first to the ground; every fifth
/// bushing a dashpot (non-proportional damping); `spin` rad/s about X on every body.
fn chain(n: usize, spin: f64) -> String {
    let mut d = String::from(
        "TITLE chain of bodies on bushings\nMATERIALS\n  1 E 2.1e11 NU 0.3 RHO 7800\nNODES\n  1000 0 0 0 FIX ALL\n",
    );
    for i in 1..=n {
        d += &format!("  {i} {} 0 0\n", 0.1 * i as f64);
    }
    d += "ELEMENTS\n";
    for i in 1..=n {
        let prev = if i == 1 { 1000 } else { i - 1 };
        let c = if i % 5 == 0 {
            " C 5 8 3 0.02 0.05 0.01"
        } else {
            ""
        };
        d += &format!("  {i} BUSHING {prev} {i} K 1e4 2e4 3e4 100 200 300{c}\n");
        d += &format!("  {} MASS {i} M 1 INERTIA 0.03 0.01 0.02\n", 1000 + i);
    }
    if spin != 0.0 {
        d += &format!("INITIAL\n  1 TO {n} W {spin} 0 0\n");
    }
    d += "ANALYSIS DYNAMIC STEP 1e-3 END 1e-2\nOUTPUT NODES 1 ELEMENTS NONE\n";
    d
}

/// The relative accuracy of the dense state-space path on its lowest mode: faer's QR
/// algorithm is backward stable, `|δλ| ≲ ε ‖A‖ κ(λ)`, with `‖A‖ ≈ ω²_max` in SI units (the
/// `M⁻¹K` block; the highest frequency) and κ of order 1 for light damping: relative
/// `ε ω²_max / |λ|`, times 10 for the algorithm's dimension factor. (The frame's 4 cm
/// beams, ω²_max ~ 1e13 1/s², gave 2.3e-5 on their 18 Hz mode, ε ω²_max/|λ| = 2e-5: the
/// dense path's error — the sparse value there agrees with the proportional case's to
/// 1e-11 —, so the dense comparison needs a model of moderate ω_max: the chain of bodies.)
fn dense_accuracy(dense: &ModalAnalysis) -> f64 {
    let w2max = (2.0 * std::f64::consts::PI * dense.highest_hz).powi(2);
    let lmin = dense
        .modes
        .iter()
        .filter(|m| m.kind == ModeKind::Elastic)
        .map(|m| 2.0 * std::f64::consts::PI * m.natural_hz)
        .fold(f64::INFINITY, f64::min);
    10.0 * f64::EPSILON * w2max / lmin
}

#[test]
fn non_proportionally_damped_chain_sparse_against_dense() {
    // 60 bodies: 360 unknowns; 12 dashpots. Both paths solve the same matrices: agreement
    // within the dense path's accuracy (derived above, printed) plus the sparse one's
    // (Krylov residual 1e-9 |μ|, eigenvalue condition ~1 for ζ ≪ 1: ~1e-9): 1e-8.
    let model = model_from(&chain(60, 0.0));
    let dense = modes(&model, 12, Solver::Dense);
    let sparse = modes(&model, 12, Solver::Sparse);
    assert_eq!(dense.method, Method::StateSpace);
    assert_eq!(sparse.method, Method::SparseStateSpace);
    assert_eq!(sparse.free_unknowns, 360);
    let bound = dense_accuracy(&dense);
    eprintln!("dense accuracy bound {bound:.1e}");
    // The tolerance holds the dense bound plus the sparse path's ~1e-9.
    assert!(bound + 1e-9 < 1e-8, "{bound:e}");
    let worst = compare(&dense, &sparse, 1e-8, "chain");
    eprintln!("worst difference {worst:.2e}");
    // Non-proportional: the damping ratios are not those of any ηω/2 law, and some modes
    // are damped at all (ζ > 1e-4).
    assert!(sparse.modes.iter().any(|m| m.damping_ratio > 1e-4));
}

#[test]
fn spinning_chain_gyroscopic_sparse_against_dense() {
    // The same chain spinning at 20 rad/s about its axis: the bodies' gyroscopic terms
    // (J ω × ·) split the bending pairs into forward and backward whirls. The free spin
    // of the chain about its axis is resisted by the first bushing, so no zero mode.
    let model = model_from(&chain(60, 20.0));
    let dense = modes(&model, 12, Solver::Dense);
    let sparse = modes(&model, 12, Solver::Sparse);
    assert_eq!(dense.method, Method::StateSpace);
    assert_eq!(sparse.method, Method::SparseStateSpace);
    let bound = dense_accuracy(&dense);
    eprintln!("dense accuracy bound {bound:.1e}");
    // The tolerance holds the dense bound plus the sparse path's ~1e-9.
    assert!(bound + 1e-9 < 1e-8, "{bound:e}");
    let worst = compare(&dense, &sparse, 1e-8, "spinning chain");
    eprintln!("worst difference {worst:.2e}");
}
