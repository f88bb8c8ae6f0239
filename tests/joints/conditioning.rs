//! The iteration matrix as the step shrinks, and redundant constraints found and named.

use super::*;

// ---------------------------------------------------------------- conditioning

/// The rigid double pendulum with h = 1e-2 … 1e-6 (50 steps each): every run converges
/// with at most 4 matrix factorisations per step on average (the costly part of a Newton
/// iteration) and a bounded number of (modified) Newton iterations — at least a factor 4
/// per iteration, from a residual ≤ 1 to the 1e-8 tolerance, is ≤ 14 — and the count does
/// not grow as h shrinks (the constraint scaling keeps the iteration matrix conditioned).
#[test]
fn conditioning_does_not_degrade_as_the_step_shrinks() {
    let mut per_step = Vec::new();
    for k in 2..=6 {
        let h = 10f64.powi(-k);
        let mut model = deck("double_pendulum_rigid.dat");
        set_steps(&mut model, h, 50.0 * h);
        let (report, recs) = run(&model);
        assert!(report.failure.is_none(), "h = {h:e}: {:?}", report.failure);
        assert_eq!(report.stats.steps, 50, "h = {h:e}");
        assert_eq!(report.stats.rejected_steps, 0, "h = {h:e}");
        let it = report.stats.newton_iterations as f64 / report.stats.steps as f64;
        let viol = recs.iter().map(|r| r.violation).fold(0.0, f64::max);
        let fact = report.stats.factorizations as f64 / report.stats.steps as f64;
        println!(
            "h = {h:.0e}: {it:.2} Newton iterations/step, {fact:.2} factorisations/step, max violation {viol:.1e}"
        );
        assert!(it <= 14.0, "h = {h:e}: {it} iterations per step");
        assert!(fact <= 4.0, "h = {h:e}: {fact} factorisations per step");
        per_step.push(it);
    }
    for w in per_step.windows(2) {
        assert!(
            w[1] <= w[0] + 0.5,
            "iterations grow as h shrinks: {per_step:?}"
        );
    }
}

// ---------------------------------------------------------------- redundant constraints

/// A planar four-bar of spatial hinges has 3 redundant equations: the solver removes
/// them (those of the loop-closing hinge, element 7, listed last: the z translation and
/// the two rotations about the in-plane normals), says so, and runs to the end with the
/// loop closed. The rank-revealing check names the same equations at any position of the
/// loop (a structural redundancy).
#[test]
fn four_bar_redundant_hinges_are_removed_and_named() {
    let model = deck("four_bar.dat");
    let integ = solver::prepare(&model).expect("builds");
    let r = mecano::solver::redundancy::detect(&integ.sys, &integ.nodes, 0.0);
    let named: Vec<(u32, usize)> = r.removed.iter().map(|x| (x.id.0, x.equation + 1)).collect();
    assert_eq!(named, vec![(7, 3), (7, 4), (7, 5)]);
    let text = r.describe().join("; ");
    println!("{text}");
    assert!(text.contains("element 7: its equations 3, 4, 5"), "{text}");
    let (report, recs) = run(&model);
    assert!(report.failure.is_none(), "{:?}", report.failure);
    assert_eq!(report.stats.steps, 1000);
    assert!(!recs.is_empty());
    assert!(
        report.stats.max_constraint_violation < 1e-9,
        "the loop stays closed: {}",
        report.stats.max_constraint_violation
    );
}

/// The spatial pendulum and the double pendulums have independent constraints.
#[test]
fn well_posed_mechanisms_have_no_redundant_constraints() {
    for d in [
        "pendulum_nocontact.dat",
        "double_pendulum_rigid.dat",
        "double_pendulum_beams.dat",
        "simple_pendulum.dat",
    ] {
        let model = deck(d);
        let integ = solver::prepare(&model).expect("builds");
        assert!(
            mecano::solver::redundancy::detect(&integ.sys, &integ.nodes, 0.0).is_empty(),
            "{d}"
        );
    }
}
