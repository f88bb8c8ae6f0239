//! The sparse shift-invert Lanczos path of `mecano-rs modes` (issue 24 §3; src/modes/sparse.rs)
//! against the dense path on the same models, and against the cantilever's closed form.

mod common;

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

/// The Timoshenko frequencies of the cantilever with a 1 kg tip mass (tests/modes.rs).
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
    // A free steel beam, 10 m, 4 elements of order 8 (tests/modes.rs's): the block of six
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
