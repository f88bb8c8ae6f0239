//! Clearance joints: a hard impact over the step range, and one that cannot be cut.

use super::failures::fails_cleanly;
use super::*;

/// A hard impact in a steel clearance joint (`decks/stab_clearance_impact.dat`: 1 kg at
/// 5 m/s, Hertz K = 6.61e10, LN e = 0.9, rattling wall to wall for 2 ms) at base steps
/// h = 1e-3 … 1e-6 s, the joint's events cutting the steps at each impact: every run
/// completes; `E − W_ext` never rises above E(0) (+1e-6 of it: the impacts only
/// dissipate); the deepest penetration (the first impact's) agrees with the impact ODE
/// integrated by RK4 (`common::impact`) within `(π/N)²/4`, N = 10 steps per impact (the
/// resolution's error, tests/clearance.rs) — from the coarsest base step to the finest.
/// The unresolvable case is `clearance_impact_that_cannot_be_cut_fails_cleanly`.
#[test]
fn clearance_joint_hard_impact_over_the_step_range() {
    let mut pens = Vec::new();
    for h in [1e-3, 1e-4, 1e-5, 1e-6] {
        let mut model = deck("stab_clearance_impact.dat");
        set_steps(&mut model, h, 2e-3, None);
        let mut integ = solver::prepare(&model).expect("prepare");
        let mut rec = Rec::default();
        let rep = solver::run_prepared(&model, &mut integ, &mut rec).expect("run starts");
        assert!(rep.failure.is_none(), "h = {h}: {:?}", rep.failure);
        let s = integ.sys.elements[0].summary().expect("summary");
        let pen = s["max_penetration"].as_f64().unwrap();
        let e0 = rec.e[0];
        println!(
            "clearance impact, h = {h:e}: {} steps ({} refused, smallest {:.2e} s), {:.2} it/step, {} impacts, penetration {pen:.4e} m, rise {:.2e} J of E0 {e0} J",
            rep.stats.steps,
            rep.stats.rejected_steps,
            rep.stats.min_step,
            it_per_step(&rep),
            s["impacts"],
            rise(&rec)
        );
        assert!(rise(&rec) <= 1e-6 * e0, "energy created");
        assert_eq!(s["unresolved_steps"], 0, "every impact resolved");
        pens.push(pen);
    }
    // The same impact with steps that may not be cut (MINSTEP = STEP = 1e-4 s, 3 steps per
    // crossing of the clearance and none per impact). Accepting the joint's refused steps
    // created 76 J of 12.5 J (stop 24's measurement): a wrong answer. The run must stop at
    // the first impact with the diagnosis naming the joint and the step it needs, with
    // the histories up to there and no energy created before it.
    let mut model = deck("stab_clearance_impact.dat");
    set_steps(&mut model, 1e-4, 2e-3, None);
    if let mecano::model::Analysis::Dynamic { min_step, .. } = &mut model.analysis {
        *min_step = 1e-4;
    }
    let mut integ = solver::prepare(&model).expect("prepare");
    let mut rec = Rec::default();
    let rep = solver::run_prepared(&model, &mut integ, &mut rec).expect("run starts");
    let f = rep
        .failure
        .as_ref()
        .expect("an unresolvable impact stops the run");
    println!(
        "clearance impact, h = MINSTEP = 1e-4: stops at t = {:.3e} s after {} steps: {f}",
        f.time, rep.stats.steps
    );
    let id = integ.sys.elements[0].id();
    match f.reason {
        solver::FailureReason::EventUnresolved { element, asks } => {
            assert_eq!(element, id);
            assert!(asks < 1e-4, "asks for a shorter step: {asks}");
        }
        ref r => panic!("expected EventUnresolved, got {r:?}"),
    }
    assert!(
        f.to_string().contains("MINSTEP"),
        "the message says what to change"
    );
    // The journal starts at the centre, 0.5 mm from the wall, at 5 m/s
    // (it reaches the wall at t = 1e-4 s; the refused step starts there or one step later).
    assert!(
        f.time <= 2e-4 + 1e-12,
        "stops at the first impact, t = {}",
        f.time
    );
    assert!(
        rise(&rec) <= 1e-6 * rec.e[0],
        "no energy created before the stop"
    );
    let (m, v0, k) = (1.0, 5.0, 6.61e10f64);
    let hertz = (5.0 * m * v0 * v0 / (4.0 * k)).powf(0.4);
    let law = common::impact::lankarani_nikravesh(k, 1.5, 0.9, v0);
    let (_, deepest) = common::impact::impact_ode(m, v0, law, 3.0 * hertz / v0, 20_000);
    let tol = (PI / 10.0).powi(2) / 4.0;
    for p in &pens {
        println!(
            "penetration {p:.5e} m, impact ODE {deepest:.5e} m, relative error {:.2e} (tol {tol:.2e})",
            (p - deepest).abs() / deepest
        );
        assert!((p - deepest).abs() <= tol * deepest);
    }
}

/// `decks/stab_clearance_nocut.dat`: a 50 m/s impact inside one step that may not be cut
/// (MINSTEP = STEP, MAXIT 10): the run fails cleanly (`fails_cleanly`).
#[test]
fn clearance_impact_that_cannot_be_cut_fails_cleanly() {
    fails_cleanly("stab_clearance_nocut");
}
