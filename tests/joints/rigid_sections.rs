//! RIGID sections: the double pendulum and the seed's rigid case against rigid bodies.

use super::planar::double_pendulum_errors;
use super::*;

// ---------------------------------------------------------------- RIGID sections

/// A model with every section made `RIGID` (the bars keep their shape; mass and inertia
/// from ρA and ρI, `elements/rigid_bar.rs`).
fn with_rigid_sections(mut model: Model) -> Model {
    for s in model.sections.values_mut() {
        s.rigid = true;
    }
    model
}

/// `decks/double_pendulum_beams.dat` with its section `RIGID`: the 2-DOF Lagrange solution.
///
/// The rigid bars carry exactly the rigid bodies of the RIGID + MASS deck (mass ρAL,
/// centroidal inertia ρAL³/12 + ρI₃L: the consistent mass integrates a rigid motion's
/// kinetic energy exactly), so their error is the time discretisation's, which the rigid
/// body deck measures at the same step as 4.8e-5 and 8.1e-5 rad; the only other
/// difference is where the bodies are referenced (every node of the bar instead of its
/// middle), which changes the O(h²) error, not its size. Tolerance: 2e-4 rad (twice the
/// rigid-body deck's 1e-4 bound); a wrong mass or inertia of a bar shows as 1e-2 rad.
#[test]
fn double_pendulum_of_rigid_sections_follows_the_lagrange_solution() {
    let model = with_rigid_sections(deck("double_pendulum_beams.dat"));
    let (report, recs) = run(&model);
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let (e1, e2) = double_pendulum_errors(&model, &recs, 12, 23);
    let viol = recs.iter().map(|r| r.violation).fold(0.0, f64::max);
    println!(
        "double pendulum (RIGID sections, h = 1e-3): max angle errors {e1:.3e}, {e2:.3e} rad; max violation {viol:.2e}"
    );
    assert!(viol < 1e-10, "violation {viol:e}");
    assert!(e1 < 2e-4 && e2 < 2e-4, "angle errors {e1:e}, {e2:e} rad");
}

/// The seed's rigid case (`decks/pendulum_rigid.dat`) with its sections `RIGID` against the
/// same scene of rigid bodies (`decks/pendulum_rigid_body.dat`: RIGID joints and MASS
/// elements with the bars' mass and inertia) over the swing before the impact (0–0.3 s,
/// the deck's h = 1e-4 s, through the torque pulse). Both are the same rigid multibody
/// system in different coordinates; the seed's case itself (E = 2.1e15) differs from it by
/// the bars' O(1/E) flexibility. Tolerance: the rigid case's h-vs-h/2 difference in
/// 0–0.5 s is 5.2e-7 m (`tests/pendulum.rs`), i.e. its time error is ~7e-7 m; two runs
/// with errors of that size differ by at most 1.4e-6 m: 3e-6 m (the position scale is
/// 1 m; a wrong inertia shows as 1e-3 m and more). The seed's case as run (stiff beams)
/// is held to the same bound. Measured: 4.5e-9 m against the rigid bodies, 2.6e-7 m
/// against the stiff beams.
#[test]
fn seed_rigid_case_with_rigid_sections_matches_the_rigid_bodies() {
    let mut a = with_rigid_sections(deck("pendulum_rigid.dat"));
    let mut b = deck("pendulum_rigid_body.dat");
    set_steps(&mut a, 1e-4, 0.3);
    set_steps(&mut b, 1e-4, 0.3);
    let (ra, xa) = run(&a);
    let (rb, xb) = run(&b);
    assert!(ra.failure.is_none() && rb.failure.is_none());
    assert_eq!(xa.len(), xb.len(), "both runs take the same fixed steps");
    let mut err = 0.0f64;
    for (p, q) in xa.iter().zip(&xb) {
        assert!((p.t - q.t).abs() < 1e-12);
        for id in [12, 23] {
            err = err.max((p.x[node(&a, id)] - q.x[node(&b, id)]).norm());
        }
    }
    let viol = xa.iter().map(|r| r.violation).fold(0.0, f64::max);
    // And the seed's case as it is run (stiff beams, E = 2.1e15).
    let mut c = deck("pendulum_rigid.dat");
    set_steps(&mut c, 1e-4, 0.3);
    let (rc, xc) = run(&c);
    assert!(rc.failure.is_none());
    let mut err_c = 0.0f64;
    for (p, q) in xa.iter().zip(&xc) {
        for id in [12, 23] {
            err_c = err_c.max((p.x[node(&a, id)] - q.x[node(&c, id)]).norm());
        }
    }
    println!(
        "seed rigid case, RIGID sections vs rigid bodies (0-0.3 s, h = 1e-4): max |dx| nodes 12, 23 = {err:.2e} m; \
         vs the stiff beams (E = 2.1e15) {err_c:.2e} m; max violation {viol:.2e}"
    );
    assert!(err < 3e-6, "{err:e} m");
    assert!(err_c < 3e-6, "{err_c:e} m");
}
