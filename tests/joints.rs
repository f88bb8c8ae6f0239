//! Joint verification (issue 4): pendulums against independent Runge–Kutta solutions of
//! their Lagrange equations, constraint satisfaction, conditioning of the iteration
//! matrix as the step shrinks, energy of the spatial pendulum, redundant constraints.
//!
//! (The tangent checks of every joint type are unit tests in `src/elements/joints.rs`:
//! the finite-difference harness is crate-private.)

mod common;

use common::deck;
use mecano::model::{Analysis, Model, NodeId};
use mecano::solver::{self, Observer, RunReport, Snapshot};
use nalgebra::Vector3;
use std::f64::consts::PI;

/// One accepted state.
#[derive(Debug, Clone)]
struct Rec {
    t: f64,
    x: Vec<Vector3<f64>>,
    violation: f64,
    /// Kinetic + strain + gravity − work of the applied loads.
    energy: f64,
    kinetic: f64,
}

#[derive(Default)]
struct Collect {
    recs: Vec<Rec>,
}

impl Observer for Collect {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let i = snap.integ;
        let e = i.energies();
        self.recs.push(Rec {
            t: i.t,
            x: i.nodes.iter().map(|s| s.x).collect(),
            violation: i.constraint_violation(),
            energy: e.kinetic + e.strain + e.gravity - i.external_work,
            kinetic: e.kinetic,
        });
        Ok(())
    }
}

fn set_steps(model: &mut Model, h: f64, end: f64) {
    if let Analysis::Dynamic {
        step,
        end: e,
        min_step,
        max_step,
        ..
    } = &mut model.analysis
    {
        *step = h;
        *e = end;
        *min_step = h / 1024.0;
        *max_step = h;
    } else {
        panic!("dynamic deck expected");
    }
}

fn run(model: &Model) -> (RunReport, Vec<Rec>) {
    let mut obs = Collect::default();
    let report = solver::run(model, &mut obs).expect("run starts");
    (report, obs.recs)
}

fn node(model: &Model, id: u32) -> usize {
    model.nodes.get_index_of(&NodeId(id)).expect("node exists")
}

fn rk4<const N: usize>(f: impl Fn(&[f64; N]) -> [f64; N], y: &[f64; N], dt: f64) -> [f64; N] {
    let add = |a: &[f64; N], b: &[f64; N], s: f64| std::array::from_fn(|i| a[i] + s * b[i]);
    let k1 = f(y);
    let k2 = f(&add(y, &k1, dt / 2.0));
    let k3 = f(&add(y, &k2, dt / 2.0));
    let k4 = f(&add(y, &k3, dt));
    std::array::from_fn(|i| y[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// Integrates `y' = f(y)` with RK4 at step `dt`, sampled at the times `ts` (increasing).
fn rk4_at<const N: usize>(
    f: impl Fn(&[f64; N]) -> [f64; N],
    y0: [f64; N],
    ts: &[f64],
    dt: f64,
) -> Vec<[f64; N]> {
    let (mut t, mut y) = (0.0, y0);
    let mut out = Vec::with_capacity(ts.len());
    for &tt in ts {
        while t < tt - 1e-12 {
            let h = dt.min(tt - t);
            y = rk4(&f, &y, h);
            t += h;
        }
        out.push(y);
    }
    out
}

/// Continuous angle of `v` in the XY plane, unwrapped against `prev`.
fn angle(v: &Vector3<f64>, prev: f64) -> f64 {
    let a = v.y.atan2(v.x);
    let mut d = (a - prev) % (2.0 * PI);
    if d > PI {
        d -= 2.0 * PI;
    } else if d < -PI {
        d += 2.0 * PI;
    }
    prev + d
}

const G: f64 = 9.81;

// ---------------------------------------------------------------- simple pendulum (A01)

/// IFToMM A01: with θ the angle of the link from +X (counter-clockwise, about +Z), the
/// mass is at `L(cos θ, sin θ)`, its potential `m g L sin θ`, and Lagrange's equation is
/// `m L² θ'' = −m g L cos θ`, i.e. `θ'' = −(g/L) cos θ`, θ(0) = θ'(0) = 0.
#[test]
fn simple_pendulum_follows_the_rk4_solution_for_10_s() {
    let model = deck("simple_pendulum.dat");
    let (report, recs) = run(&model);
    assert!(report.failure.is_none(), "{:?}", report.failure);
    assert!((report.time - 10.0).abs() < 1e-9);
    let n2 = node(&model, 2);
    let ts: Vec<f64> = recs.iter().map(|r| r.t).collect();
    let l = 1.0;
    let sol = rk4_at(
        |y: &[f64; 2]| [y[1], -G / l * y[0].cos()],
        [0.0, 0.0],
        &ts,
        1e-4,
    );
    let mut err: f64 = 0.0;
    for (r, y) in recs.iter().zip(&sol) {
        let exact = Vector3::new(l * y[0].cos(), l * y[0].sin(), 0.0);
        err = err.max((r.x[n2] - exact).norm());
        assert!(
            r.violation < 1e-10,
            "violation {:e} at t = {}",
            r.violation,
            r.t
        );
    }
    println!("simple pendulum: max position error over 10 s = {err:.3e} m");
    assert!(err < 1e-3, "max position error {err:e} m");
}

// ---------------------------------------------------------------- double pendulum

/// The planar double pendulum of `decks/double_pendulum_*.dat`, by Lagrange's equations.
/// Bars of length L, mass m each (uniform), centroidal inertia `J = m L²/12 + ρ I₃ L`
/// (the beams' lumped rotary inertia), tip masses M₁, M₂; θᵢ = angle of bar i from +X.
/// `T = ½ M₁₁ θ₁'² + ½ M₂₂ θ₂'² + a cos(θ₁−θ₂) θ₁'θ₂'` with
/// `M₁₁ = m L²/4 + J + (M₁ + m + M₂) L²`, `M₂₂ = m L²/4 + J + M₂ L²`, `a = (m/2 + M₂) L²`;
/// `V = g L [(m/2 + M₁ + m + M₂) sin θ₁ + (m/2 + M₂) sin θ₂]`.
fn double_pendulum_rk4(ts: &[f64]) -> Vec<[f64; 4]> {
    let (l, rho, area, i3) = (1.0, 7800.0, 9e-4, 8.3e-8);
    let m = rho * area * l;
    let j = m * l * l / 12.0 + rho * i3 * l;
    let (m1, m2) = (1.0, 1.0);
    let m11 = m * l * l / 4.0 + j + (m1 + m + m2) * l * l;
    let m22 = m * l * l / 4.0 + j + m2 * l * l;
    let a = (m / 2.0 + m2) * l * l;
    let g1 = G * l * (m / 2.0 + m1 + m + m2);
    let g2 = G * l * (m / 2.0 + m2);
    let f = move |y: &[f64; 4]| {
        let (t1, t2, w1, w2) = (y[0], y[1], y[2], y[3]);
        let (s, c) = (t1 - t2).sin_cos();
        // [m11, a c; a c, m22] [θ1''; θ2''] = [−a s w2² − g1 cos θ1; a s w1² − g2 cos θ2]
        let r1 = -a * s * w2 * w2 - g1 * t1.cos();
        let r2 = a * s * w1 * w1 - g2 * t2.cos();
        let det = m11 * m22 - a * a * c * c;
        [
            w1,
            w2,
            (m22 * r1 - a * c * r2) / det,
            (m11 * r2 - a * c * r1) / det,
        ]
    };
    rk4_at(f, [0.0; 4], ts, 1e-5)
}

/// Largest angle errors (bar 1, bar 2) over the run against the RK4 solution.
fn double_pendulum_errors(model: &Model, recs: &[Rec], tip1: u32, tip2: u32) -> (f64, f64) {
    let (n1, n2) = (node(model, tip1), node(model, tip2));
    let ts: Vec<f64> = recs.iter().map(|r| r.t).collect();
    let sol = double_pendulum_rk4(&ts);
    let (mut p1, mut p2, mut e1, mut e2) = (0.0, 0.0, 0.0f64, 0.0f64);
    for (r, y) in recs.iter().zip(&sol) {
        p1 = angle(&r.x[n1], p1);
        p2 = angle(&(r.x[n2] - r.x[n1]), p2);
        e1 = e1.max((p1 - y[0]).abs());
        e2 = e2.max((p2 - y[1]).abs());
    }
    (e1, e2)
}

/// 10 beams per bar with E = 2.1e15 against the 2-DOF Lagrange equations.
///
/// Tolerance: measured at h = 1e-3 s (HHT α = −0.05), the largest errors over 2 s are
/// 6.0e-5 rad (bar 1) and 1.0e-4 rad (bar 2); the rigid-body deck, same step, gives 4.8e-5
/// and 8.1e-5 rad, so the beam discretisation adds little and the error is the time
/// discretisation's. 1e-3 rad is ten times that, while a modelling error (a wrong mass,
/// inertia or constraint) shows as 1e-2 rad and more. (The h/2 run that would confirm the
/// O(h²) decay has not been done yet.)
#[test]
fn double_pendulum_of_stiff_beams_follows_the_lagrange_solution() {
    let model = deck("double_pendulum_beams.dat");
    let (report, recs) = run(&model);
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let (e1, e2) = double_pendulum_errors(&model, &recs, 12, 23);
    let viol = recs.iter().map(|r| r.violation).fold(0.0, f64::max);
    println!(
        "double pendulum (beams, h = 1e-3): max angle errors {e1:.3e}, {e2:.3e} rad; max violation {viol:.2e}; {:.2} it/step",
        report.stats.newton_iterations as f64 / report.stats.steps as f64
    );
    assert!(e1 < 1e-3 && e2 < 1e-3, "angle errors {e1:e}, {e2:e} rad");
}

/// The same scene with RIGID bars: within 1e-4 rad.
#[test]
fn double_pendulum_of_rigid_bodies_follows_the_lagrange_solution() {
    let model = deck("double_pendulum_rigid.dat");
    let (report, recs) = run(&model);
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let (e1, e2) = double_pendulum_errors(&model, &recs, 4, 7);
    let viol = recs.iter().map(|r| r.violation).fold(0.0, f64::max);
    println!(
        "double pendulum (rigid, h = 1e-3): max angle errors {e1:.3e}, {e2:.3e} rad; max violation {viol:.2e}"
    );
    assert!(viol < 1e-10, "violation {viol:e}");
    assert!(e1 < 1e-4 && e2 < 1e-4, "angle errors {e1:e}, {e2:e} rad");
}

/// The rigid double pendulum with generalized-α (issue 26), ρ∞ = 0.8 and 0.9, at the
/// deck's h = 1e-3 s and at h/2: the angle errors against the Lagrange solution are below
/// the HHT test's 1e-4 rad (measured 7.5e-5 rad at ρ∞ = 0.8; ρ∞ = 0.5, which is HHT with
/// α = −1/3, gives 1.06e-4: more dissipation, more error), and halving the step divides
/// them by 4 (measured 4.00; order 2; band
/// 3.2–4.8, i.e. an observed order of 1.7–2.3: the errors are maxima over the run, whose
/// place may move between the two runs).
#[test]
fn double_pendulum_of_rigid_bodies_with_generalized_alpha_is_second_order() {
    for rho_inf in [0.8, 0.9] {
        let mut errs = Vec::new();
        for h in [1e-3, 5e-4] {
            let mut model = deck("double_pendulum_rigid.dat");
            assert!(model.set_fixed_step(
                h,
                2.0,
                Some(mecano::model::Scheme::GeneralizedAlpha { rho_inf })
            ));
            let (report, recs) = run(&model);
            assert!(report.failure.is_none(), "{:?}", report.failure);
            let (e1, e2) = double_pendulum_errors(&model, &recs, 4, 7);
            println!(
                "double pendulum (rigid, genalpha {rho_inf}, h = {h:e}): {e1:.3e}, {e2:.3e} rad"
            );
            errs.push(e1.max(e2));
        }
        assert!(errs[0] < 1e-4, "rho_inf {rho_inf}: {:e} rad", errs[0]);
        let ratio = errs[0] / errs[1];
        assert!(
            (3.2..=4.8).contains(&ratio),
            "rho_inf {rho_inf}: ratio {ratio}"
        );
    }
}

/// The rigid double pendulum with ESDIRK3 (issue 26), the twin of the generalized-α test:
/// h = 8e-3, 4e-3, 2e-3 s over 2 s against the Lagrange solution (RK4 at 1e-5 s, whose own
/// error, ~1e-5⁴ × the solution's fourth derivative, is ≲ 1e-12 rad).
///
/// Measured (2026-11-25): largest angle errors (bar 1, bar 2) 8.62e-5, 1.47e-4 rad at 8e-3;
/// 1.09e-5, 1.86e-5 at 4e-3; 1.37e-6, 2.34e-6 at 2e-3 (constraint violation ≤ 2e-13):
/// ratios 7.91 and 7.96, observed order 2.98 and 2.99.
///
/// Tolerances: the observed order log₂(e(h)/e(h/2)) of each pair is in 2.7–3.3 — the same
/// ±0.3 band as the second-order test, for the same reason (the errors are maxima over the
/// run, whose place may move between runs; the h⁴ term changes the ratio by ~1 %, the
/// difference of the two measured ratios). The band excludes order 2 (ratio 4) and 4
/// (ratio 16), so a lost stage or a first-order stage predictor fails it. The finest error
/// is below 1e-5 rad: a tenth of the 1e-4 rad the HHT/generalized-α tests allow at h = 1e-3,
/// reached here with twice the step; the Newton tolerance (1e-8 on the scaled residual)
/// and the reference's error are orders below that. Every error is below 1e-3 rad, where a
/// modelling error (mass, inertia, constraint) shows as 1e-2 rad and more.
#[test]
fn double_pendulum_of_rigid_bodies_with_esdirk3_is_third_order() {
    let errs = double_pendulum_third_order(mecano::model::Scheme::Esdirk3);
    for (h, e) in [8e-3, 4e-3, 2e-3].iter().zip(&errs) {
        assert!(*e < 1e-3, "h = {h:e}: angle error {e:e} rad");
    }
    assert!(errs[2] < 1e-5, "error at h = 2e-3: {:e} rad", errs[2]);
}

/// The rigid double pendulum with a stage scheme at h = 8e-3, 4e-3, 2e-3 s over 2 s against
/// the Lagrange solution: the largest angle errors, each pair's observed order asserted in
/// 2.7–3.3 and the constraints held (≤ 1e-10) — the part the ESDIRK3 and ESDIRK5 tests
/// share.
fn double_pendulum_third_order(scheme: mecano::model::Scheme) -> Vec<f64> {
    let steps = [8e-3, 4e-3, 2e-3];
    let mut errs = Vec::new();
    for h in steps {
        let mut model = deck("double_pendulum_rigid.dat");
        assert!(model.set_fixed_step(h, 2.0, Some(scheme)));
        let (report, recs) = run(&model);
        assert!(report.failure.is_none(), "{:?}", report.failure);
        let (e1, e2) = double_pendulum_errors(&model, &recs, 4, 7);
        let viol = recs.iter().map(|r| r.violation).fold(0.0, f64::max);
        println!(
            "double pendulum (rigid, {scheme}, h = {h:e}): {e1:.3e}, {e2:.3e} rad; max violation {viol:.2e}; {} steps, {} Newton iterations",
            report.stats.steps, report.stats.newton_iterations
        );
        assert!(viol < 1e-10, "h = {h:e}: violation {viol:e}");
        errs.push(e1.max(e2));
    }
    for k in 0..2 {
        let order = (errs[k] / errs[k + 1]).log2();
        println!(
            "observed order between h = {:e} and {:e}: {order:.3}",
            steps[k],
            steps[k + 1]
        );
        assert!(
            (2.7..=3.3).contains(&order),
            "{scheme}: observed order {order} between h = {:e} and {:e}",
            steps[k],
            steps[k + 1]
        );
    }
    errs
}

// ---------------------------------------------------------------- spatial pendulum

/// `decks/pendulum_nocontact.dat` (ground HINGE, UJOINT between the bars): the hinge and
/// universal-joint equations hold to < 1e-10 (m, rad) at every step (first 0.3 s, through
/// the torque pulse, to keep CI fast), and node 2 stays at the origin.
#[test]
fn spatial_pendulum_constraints_hold_at_every_step() {
    let mut model = deck("pendulum_nocontact.dat");
    set_steps(&mut model, 1e-4, 0.3);
    // Default Newton settings: the solver meets constraint equations to an absolute
    // 1e-11 (m, rad), below the 1e-10 this test demands.
    let (report, recs) = run(&model);
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let n2 = node(&model, 2);
    let viol = recs.iter().map(|r| r.violation).fold(0.0, f64::max);
    let drift = recs.iter().map(|r| r.x[n2].norm()).fold(0.0, f64::max);
    println!(
        "spatial pendulum 0.3 s: {} steps, max constraint violation {viol:.2e}, max |x(node 2)| {drift:.2e} m, {:.2} it/step",
        report.stats.steps,
        report.stats.newton_iterations as f64 / report.stats.steps as f64
    );
    assert!(viol < 1e-10, "violation {viol:e}");
    assert!(drift < 1e-10, "node 2 moved by {drift:e} m");
}

/// Energy of the spatial pendulum: `E = T + U + V_g − W_ext` (work of the torque pulse)
/// never rises by more than 1e-4 of the largest kinetic energy; its loss is reported.
/// HHT α = −0.1 (the deck's) at h = 2.5e-4 s (the pulse is resolved by 80 steps; steps land
/// on its kinks), over 2 s. "Rise" is measured against the lowest energy reached so far
/// (stricter than against E(0)).
#[test]
fn spatial_pendulum_energy_does_not_rise() {
    let mut model = deck("pendulum_nocontact.dat");
    set_steps(&mut model, 2.5e-4, 2.0);
    let (report, recs) = run(&model);
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let tmax = recs.iter().map(|r| r.kinetic).fold(0.0, f64::max);
    let (mut lowest, mut rise, mut t_rise) = (f64::INFINITY, 0.0f64, 0.0);
    for r in &recs {
        lowest = lowest.min(r.energy);
        if r.energy - lowest > rise {
            rise = r.energy - lowest;
            t_rise = r.t;
        }
    }
    let rise0 = recs
        .iter()
        .map(|r| r.energy - recs[0].energy)
        .fold(0.0f64, f64::max);
    println!(
        "largest rise at t = {t_rise:.4} s; largest E(t) - E(0) = {:.2e} (relative)",
        rise0 / tmax
    );
    let last = recs.last().unwrap();
    let n2 = node(&model, 2);
    let drift = recs.iter().map(|r| r.x[n2].norm()).fold(0.0, f64::max);
    let viol = recs.iter().map(|r| r.violation).fold(0.0, f64::max);
    println!(
        "spatial pendulum 2 s (h = 2.5e-4, alpha = -0.1): max kinetic {tmax:.4e} J, largest rise {:.2e} (relative), \
         loss at 2 s {:.4e} J ({:.2e} relative), max violation {viol:.2e}, |x(node 2)| {drift:.1e} m, {:.2} it/step",
        rise / tmax,
        -(last.energy - recs[0].energy),
        -(last.energy - recs[0].energy) / tmax,
        report.stats.newton_iterations as f64 / report.stats.steps as f64
    );
    assert!(
        rise <= 1e-4 * tmax,
        "energy rose by {rise:e} J (max kinetic {tmax:e} J)"
    );
    assert!(drift < 1e-10);
}

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

// ---------------------------------------------------------------- heavy top

/// Energy and vertical angular momentum about the pivot of the heavy top
/// (`decks/heavy_top.dat`), sampled at every step: largest relative drifts over the run.
fn heavy_top_drifts(h: f64) -> (f64, f64, RunReport) {
    struct Top {
        node: usize,
        m: f64,
        j0: nalgebra::Matrix3<f64>,
        e: Vec<f64>,
        ly: Vec<f64>,
    }
    impl Observer for Top {
        fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
            let i = snap.integ;
            let s = &i.nodes[self.node];
            let en = i.energies();
            self.e
                .push(en.kinetic + en.strain + en.gravity - i.external_work);
            // L = m x × v + R J₀ Ω about the pivot (the origin); node 2 is massless.
            let l = self.m * s.x.cross(&s.v) + s.r * (self.j0 * s.w);
            self.ly.push(l.y);
            Ok(())
        }
    }
    let mut model = deck("heavy_top.dat");
    set_steps(&mut model, h, 5.0);
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let e = Vector3::new(s, c, 0.0);
    let j0 = nalgebra::Matrix3::identity() * 0.005 + e * e.transpose() * 0.005;
    let mut obs = Top {
        node: node(&model, 3),
        m: 1.0,
        j0,
        e: vec![],
        ly: vec![],
    };
    let report = solver::run(&model, &mut obs).expect("run starts");
    assert!(report.failure.is_none(), "h = {h}: {:?}", report.failure);
    let de = obs
        .e
        .iter()
        .map(|x| (x - obs.e[0]).abs())
        .fold(0.0, f64::max)
        / obs.e[0].abs();
    let dl = obs
        .ly
        .iter()
        .map(|x| (x - obs.ly[0]).abs())
        .fold(0.0, f64::max)
        / obs.ly[0].abs();
    (de, dl, report)
}

/// Heavy symmetric top on a SPHERICAL joint (m = 1 kg, L = 0.1 m, I_a = 0.01, I_t = 0.005
/// kg m², spin 50 rad/s, axis 30° from the vertical): precession period ≈ 3.2 s, nutation
/// ≈ 33 rad/s. Over 5 s (1.5 precession turns) at h = 1e-3 s (190 steps per nutation
/// period) the energy and the vertical angular momentum about the pivot drift by less than
/// 1e-4 relative, and the drifts fall about fourfold (≥ 3) at h = 5e-4 s: the error is the
/// O(h²) of the scheme. HHT α = −0.05 (the deck's): with α = 0 this constrained top blows
/// up near t = 0.5 s at any step (see docs/stability.md).
///
/// Measured: energy 1.25e-6 → 2.89e-7 (ratio 4.3); L_y 2.04e-6 → 2.55e-7 (ratio 8.0).
#[test]
fn heavy_top_conserves_energy_and_vertical_momentum() {
    let (e1, l1, r1) = heavy_top_drifts(1e-3);
    let (e2, l2, _) = heavy_top_drifts(5e-4);
    println!(
        "heavy top, 5 s: h = 1e-3: energy drift {e1:.3e}, L_y drift {l1:.3e} ({:.2} it/step); \
         h = 5e-4: {e2:.3e}, {l2:.3e}; ratios {:.2}, {:.2}",
        r1.stats.newton_iterations as f64 / r1.stats.steps as f64,
        e1 / e2,
        l1 / l2
    );
    assert!(e1 < 1e-4 && l1 < 1e-4, "drifts {e1:e}, {l1:e}");
    assert!(e1 / e2 > 3.0, "energy drift ratio {}", e1 / e2);
    assert!(l1 / l2 > 3.0 || l1 < 1e-9, "L_y drift ratio {}", l1 / l2);
}

// ---------------------------------------------------------------- universal joint at 90°

/// `decks/ujoint_singular.dat`: a body hanging on a Cardan joint swings through a bend of
/// 90°. What is correct: the four equations of the joint keep a Jacobian of full rank
/// there (the configuration space is a torus), so the run goes on — the singularity is
/// one of transmission (no torque about the shafts), not of the equations. The test
/// asserts that (1) the run completes with constraints met, (2) the passage is recorded
/// (`summary`: `singular_passages` ≥ 1, `min_abs_cos_bend` < 1e-2), (3) the element's
/// diagnosis at that state names the joint and the singular configuration, and (4) a step
/// that fails there (Newton limited to one iteration with a 10× step) carries that
/// diagnosis in its `Failure` message.
#[test]
fn universal_joint_at_ninety_degrees_is_diagnosed() {
    let model = deck("ujoint_singular.dat");
    let mut integ = solver::prepare(&model).expect("builds");
    integ.initialize().expect("initial state");
    let mut diag = None;
    let mut max_viol: f64 = 0.0;
    while integ.t < 1.0 - 1e-9 {
        integ
            .try_step(1e-3)
            .expect("the run goes through the singular configuration");
        max_viol = max_viol.max(integ.constraint_violation());
        if diag.is_none()
            && let Some(d) = integ.sys.elements[0].diagnose(&integ.nodes)
        {
            diag = Some((integ.t, d));
            // (4) a failed step here carries the diagnosis.
            let saved = integ.newton.max_iterations;
            integ.newton.max_iterations = 1;
            let f = integ
                .try_step(1e-2)
                .expect_err("one iteration cannot converge");
            integ.newton.max_iterations = saved;
            let text = f.to_string();
            println!("failure near the singularity: {text}");
            assert!(
                f.diagnoses.iter().any(|d| d.contains("element 1 (UJOINT)")),
                "{text}"
            );
            assert!(
                text.contains("diagnosis: element 1 (UJOINT) is at its singular"),
                "{text}"
            );
        }
    }
    let (t, d) = diag.expect("the bend reaches 90°");
    println!("t = {t:.3} s: {d}; max violation {max_viol:.1e}");
    assert!(d.contains("singular configuration") && d.contains("cannot transmit a torque"));
    assert!(max_viol < 1e-10, "violation {max_viol:e}");
    let s = integ.sys.elements[0].summary().expect("UJOINT summary");
    println!("summary: {s}");
    assert!(s["singular_passages"].as_u64().unwrap() >= 1, "{s}");
    assert!(s["min_abs_cos_bend"].as_f64().unwrap() < 1e-2, "{s}");
}

/// Consistent initial multipliers with initial velocities: a pendulum launched at 2 m/s
/// from the bottom starts with the link tension m(g + v²/L) = 13.81 N. The acceleration-
/// level constraint includes the velocity term Ḃv, taken by a second difference along the
/// motion (truncation O(ε²) with ε|v| = 1e-3 L: ~1e-6 relative): 1e-5 m g.
#[test]
fn launched_pendulum_starts_with_the_centripetal_tension() {
    let model = deck("pendulum_launched.dat");
    let mut integ = mecano::solver::prepare(&model).expect("builds");
    integ.initialize().expect("initial accelerations");
    let e = model
        .elements
        .get_index_of(&mecano::model::ElementId(1))
        .unwrap();
    let ctx = integ.current_context();
    let lam = integ.sys.element_lambda(e, &integ.lambda).to_vec();
    let row = integ.sys.elements[e].output_row(&ctx, &integ.nodes, &lam);
    let header = integ.sys.elements[e].output_header();
    let fy = row[header.iter().position(|h| h == "fy").expect("fy column")];
    let exact = 9.81 + 2.0 * 2.0 / 1.0;
    assert!(
        (fy - exact).abs() < 1e-5 * 9.81,
        "tension {fy} N, exact {exact} N"
    );
    // And the mass starts with the centripetal acceleration v²/L upward.
    let i = model.nodes.get_index_of(&mecano::model::NodeId(2)).unwrap();
    assert!(
        (integ.nodes[i].a.y - 4.0).abs() < 1e-4,
        "{}",
        integ.nodes[i].a
    );
}

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

/// The rigid double pendulum with ESDIRK5 (ESDIRK5(4)7L[2]SA2), the twin of the ESDIRK3
/// test at the same steps: third order too (the index-3 constraints and stage order 2 cap
/// the positions at min(p, q + 1) = 3, tests/esdirk.rs), with a 3.7–4.2 times smaller
/// error. Measured (2026-11-27): largest angle errors (bar 1, bar 2) 3.78e-5, 3.95e-5 rad
/// at 8e-3; 4.52e-6, 4.71e-6 at 4e-3; 5.59e-7, 5.80e-7 at 2e-3 (violation ≤ 3e-13):
/// observed orders 3.07 and 3.02 (3.19 and 3.18 at 3.2e-2 → 1.6e-2 → 8e-3, coming down to 3).
///
/// Tolerances: the same 2.7–3.3 band as ESDIRK3's (the same reasons), and the finest error
/// below ESDIRK3's measured 2.34e-6 rad at the same step (a factor 4 above ESDIRK5's own,
/// 5.8e-7): a tableau that lost its fifth-order coefficients would still be third order
/// here, but with ESDIRK3's constant or worse.
#[test]
fn double_pendulum_of_rigid_bodies_with_esdirk5_is_third_order() {
    let errs = double_pendulum_third_order(mecano::model::Scheme::Esdirk5);
    assert!(errs[2] < 2.34e-6, "error at h = 2e-3: {:e} rad", errs[2]);
}
