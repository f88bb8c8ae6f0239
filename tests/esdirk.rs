//! The third-order ESDIRK integrator (`ANALYSIS ... ESDIRK3`, `solver::integrator::esdirk`,
//! issue 26 §2): its coefficients, its observed order on closed-form cases, and the
//! stability suite's cases (tests/stability/) run with it. The tests print what they
//! measure (`-- --nocapture`); docs/accuracy.md ("A third-order integrator") records it.

mod common;

use common::deck;
use mecano::model::{Analysis, ElementKind, Model, NodeId, Scheme};
use mecano::solver::{self, Observer, RunReport, Snapshot};
use nalgebra::Vector3;

/// The stage schemes every stability case runs with.
const SCHEMES: [Scheme; 2] = [Scheme::Esdirk3, Scheme::Esdirk5];

fn esdirk(model: &mut Model, h: f64, end: f64) {
    with_scheme(model, Scheme::Esdirk3, h, end);
}

/// Fixed steps `h` to `end` with `scheme` on the model's ANALYSIS card.
fn with_scheme(model: &mut Model, scheme: Scheme, h: f64, end: f64) {
    assert!(
        model.set_fixed_step(h, end, Some(scheme)),
        "dynamic deck expected"
    );
    assert!(matches!(
        model.analysis,
        Analysis::Dynamic { scheme: s, .. } if s == scheme
    ));
}

fn node(model: &Model, id: u32) -> usize {
    model.nodes.get_index_of(&NodeId(id)).expect("node exists")
}

/// Per accepted state: t, `E − W_ext + W_damping` (what the run's energy balance keeps
/// constant up to the integrator's own dissipation), kinetic energy, node states,
/// constraint violation.
#[derive(Default)]
struct Rec {
    t: Vec<f64>,
    e: Vec<f64>,
    kin: Vec<f64>,
    last: Vec<mecano::elements::NodeState>,
    viol: f64,
    /// The powers the balance integrates by the trapezoidal rule: loads' and dampers'.
    power: Vec<f64>,
}

impl Observer for Rec {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let i = snap.integ;
        assert!(i.is_esdirk(), "the run must use an ESDIRK scheme");
        let en = i.energies();
        self.t.push(i.t);
        self.e
            .push(en.kinetic + en.strain + en.gravity - i.external_work + i.damping_work);
        self.kin.push(en.kinetic);
        let damp: f64 = i
            .sys
            .elements
            .iter()
            .map(|e| e.dissipated_power(&i.nodes))
            .sum();
        self.power.push(i.sys.external_power(i.t, &i.nodes) + damp);
        self.viol = self.viol.max(i.constraint_violation());
        self.last.clone_from(&i.nodes);
        Ok(())
    }
}

fn run(model: &Model) -> (RunReport, Rec) {
    let mut rec = Rec::default();
    let r = solver::run(model, &mut rec).expect("run starts");
    (r, rec)
}

fn max_of(v: &[f64]) -> f64 {
    v.iter().copied().fold(0.0, f64::max)
}

/// Largest rise of the energy balance above its initial value.
fn rise(rec: &Rec) -> f64 {
    rec.e.iter().map(|e| e - rec.e[0]).fold(f64::MIN, f64::max)
}

/// What the balance's own quadrature may err by: the works of the loads and dampers are
/// trapezoidal sums of their powers, each step erring by `h³|P̈|/12`; with `h²P̈` estimated
/// by the second difference of the recorded powers, `Σ h |ΔΔP| / 12`, doubled for the
/// estimate's own error (uneven steps at events). HHT's numerical damping hides this
/// error in its losses; ESDIRK3 damps the resolved motion by only O((ωh)⁴) per step, so a
/// rise of this size is the measure's, not energy created.
fn quadrature_bound(rec: &Rec) -> f64 {
    let (t, p) = (&rec.t, &rec.power);
    let mut b = 0.0;
    for k in 1..t.len().saturating_sub(1) {
        let h = 0.5 * (t[k + 1] - t[k - 1]);
        b += h * (p[k + 1] - 2.0 * p[k] + p[k - 1]).abs() / 12.0;
    }
    2.0 * b
}

/// The observed order from errors `e` at steps halving: `log2(e_k / e_{k+1})`.
fn slopes(e: &[f64]) -> Vec<f64> {
    e.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

/// The order test of a ladder of halving steps. For a method of order 3 the error is
/// `C h³ (1 + D h + O(h²))`, so the slope between two levels is `3 + O(h)` and its
/// deviation from 3 halves with each halving: the last slope is within
/// `|s_last − s_prev|` of 3 (the rest of a geometric series of ratio ½), plus `O(h²)`.
/// The test asks for the last slope within twice that of 3 and the slopes' limit,
/// extrapolated as `2 s_last − s_prev`, within 0.2 of 3: a second-order method (limit 2)
/// cannot pass, nor a fourth-order one.
fn assert_third_order(what: &str, e: &[f64]) {
    assert_order(what, e, 3.0);
}

/// [`assert_third_order`] for order `p`.
fn assert_order(what: &str, e: &[f64], p: f64) {
    let s = slopes(e);
    let (last, prev) = (s[s.len() - 1], s[s.len() - 2]);
    let limit = 2.0 * last - prev;
    let es: Vec<String> = e.iter().map(|x| format!("{x:.3e}")).collect();
    let ss: Vec<String> = s.iter().map(|x| format!("{x:.3}")).collect();
    println!(
        "{what}: errors [{}], slopes [{}], extrapolated slope {limit:.3}",
        es.join(", "),
        ss.join(", ")
    );
    assert!(
        (last - p).abs() <= 2.0 * (last - prev).abs() + 0.05,
        "{what}: last slope {last}"
    );
    assert!((limit - p).abs() <= 0.2, "{what}: slope limit {limit}");
}

/// Runge–Kutta 4 on `θ'' = −(g/L) cos θ` (the simple pendulum, tests/joints/planar.rs): at
/// dt = 1e-4 s its error over 2 s is ~1e-13 rad (h⁴ scaling from the 1e-3 run), far below
/// the errors measured here (≥ 4e-8 m).
fn pendulum_angle(t_end: f64) -> f64 {
    let f = |y: [f64; 2]| [y[1], -9.81 * y[0].cos()];
    let dt = 1e-4;
    let mut y = [0.0, 0.0];
    for _ in 0..(t_end / dt).round() as usize {
        let k1 = f(y);
        let k2 = f([y[0] + dt / 2.0 * k1[0], y[1] + dt / 2.0 * k1[1]]);
        let k3 = f([y[0] + dt / 2.0 * k2[0], y[1] + dt / 2.0 * k2[1]]);
        let k4 = f([y[0] + dt * k3[0], y[1] + dt * k3[1]]);
        for i in 0..2 {
            y[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    y[0]
}

/// The rigid pendulum (IFToMM A01: a HINGE with a 1 m offset, an index-3 constraint that
/// couples the node's rotation and position) against its ODE reference, at h = 0.02 …
/// 0.0025 s over 2 s: third order (measured slopes 2.77, 2.90, 2.95; errors 1.6e-5 …
/// 4.0e-8 m, against 1.1e-2 … 1.7e-4 m for HHT α = −0.1 at the same steps). With the
/// constraints at the position level at every stage the order is 2 (the index-3 order
/// reduction of a stage-order-2 method), hence the inner stages' velocity constraints.
#[test]
fn third_order_on_the_rigid_pendulum_against_its_ode() {
    let mut m = deck("simple_pendulum.dat");
    let t_end = 2.0;
    let th = pendulum_angle(t_end);
    let exact = Vector3::new(th.cos(), th.sin(), 0.0);
    let n2 = node(&m, 2);
    let mut errs = Vec::new();
    for h in [0.02, 0.01, 0.005, 0.0025] {
        esdirk(&mut m, h, t_end);
        let (r, rec) = run(&m);
        assert!(r.failure.is_none(), "h = {h}: {}", r.failure.unwrap());
        // The hinge holds at every step (its Newton tolerance, 1e-11 m).
        assert!(rec.viol < 1e-11, "violation {:e}", rec.viol);
        errs.push((rec.last[n2].x - exact).norm());
    }
    assert_third_order("rigid pendulum", &errs);
}

/// The torque-free rigid body of `free_body.dat` (Euler's equations on SO(3), as
/// `hht_is_second_order_accurate` in tests/dynamics.rs): with no reference, the ratio of
/// successive differences of the final orientation, `|R_h − R_{h/2}|/|R_{h/2} − R_{h/4}|`,
/// is `2^p` (measured slopes 2.998, 2.999: the exact `dexp⁻¹` of the stages keeps the
/// Lie-group scheme third order).
#[test]
fn third_order_on_the_free_rigid_body() {
    let mut m = deck("free_body.dat");
    let mut finals = Vec::new();
    for h in [0.04, 0.02, 0.01, 0.005, 0.0025] {
        esdirk(&mut m, h, 4.0);
        let (r, rec) = run(&m);
        assert!(r.failure.is_none(), "h = {h}: {}", r.failure.unwrap());
        finals.push(rec.last[0].r);
    }
    let d: Vec<f64> = finals.windows(2).map(|w| (w[0] - w[1]).norm()).collect();
    assert_third_order("free rigid body (differences)", &d);
}

/// Stiff bars (E = 2.1e15, `pendulum_rigid.dat`) and steel (`pendulum.dat`) at h = 1e-4 s
/// through the torque pulse and the first impact (0.6 s): no failure, the constraints held,
/// and the energy balance never rises above its start by more than its own quadrature's
/// error ([`quadrature_bound`]) plus 1e-6 of the largest kinetic energy (the Newton
/// tolerance's work, as in tests/stability/stiff.rs).
#[test]
fn stiff_bars_and_the_impact_run_and_never_create_energy() {
    for (scheme, d) in SCHEMES
        .into_iter()
        .flat_map(|s| ["pendulum_rigid.dat", "pendulum.dat"].map(|d| (s, d)))
    {
        let mut m = deck(d);
        with_scheme(&mut m, scheme, 1e-4, 0.6);
        let (r, rec) = run(&m);
        assert!(r.failure.is_none(), "{scheme} {d}: {}", r.failure.unwrap());
        let kmax = max_of(&rec.kin);
        let loss = rec.e[0] - rec.e.last().unwrap();
        let bound = 1e-6 * kmax + quadrature_bound(&rec);
        println!(
            "{scheme} {d}: {} steps ({} refused), {:.2} it/step, {} factorisations, violation {:.1e}, \
             rise {:.1e} (bound {:.1e}) and loss {:.2e} of max kinetic {kmax:.1} J",
            r.stats.steps,
            r.stats.rejected_steps,
            r.stats.newton_iterations as f64 / r.stats.steps as f64,
            r.stats.factorizations,
            rec.viol,
            rise(&rec) / kmax,
            bound / kmax,
            loss / kmax
        );
        assert!(rec.viol < 1e-10, "{scheme} {d}: violation {:e}", rec.viol);
        assert!(rise(&rec) <= bound, "{scheme} {d}: energy rose");
    }
}

/// The bouncing mass (`contact_bounce.dat`) with contact stiffness 1e5 … 1e10 N/m and the
/// unclipped law (the force jumps by c·q̇ at the onset): the step lands on touch and
/// release (the CAME's limits), the run restarts there and completes; up to k = 1e8 no
/// energy is created beyond the balance's quadrature error ([`quadrature_bound`]).
#[test]
fn stiff_contact_runs_and_never_creates_energy() {
    for (scheme, k) in SCHEMES
        .into_iter()
        .flat_map(|s| [1e5, 1e6, 1e7, 1e8, 1e9, 1e10].map(|k| (s, k)))
    {
        let mut m = deck("contact_bounce.dat");
        for el in m.elements.values_mut() {
            if let ElementKind::Came(d) = &mut el.kind {
                d.stiffness = k;
                d.damping = 0.2 * k.sqrt();
            }
        }
        with_scheme(&mut m, scheme, 1e-4, 0.02);
        let mut integ = solver::prepare(&m).expect("prepare");
        integ.set_velocity(
            node(&m, 2),
            Vector3::new(0.0, -(2.0 * 9.81f64).sqrt(), 0.0),
            Vector3::zeros(),
        );
        let mut rec = Rec::default();
        let r = solver::run_prepared(&m, &mut integ, &mut rec).expect("run");
        assert!(
            r.failure.is_none(),
            "{scheme} k = {k:e}: {}",
            r.failure.unwrap()
        );
        let kmax = max_of(&rec.kin);
        let bound = 1e-6 * kmax + quadrature_bound(&rec);
        println!(
            "{scheme} bounce k = {k:.0e}: {} steps ({} refused), {} restarts, rise {:.1e} (bound {:.1e}) of max kinetic {kmax:.2} J",
            r.stats.steps,
            r.stats.rejected_steps,
            r.stats.restarts,
            rise(&rec) / kmax,
            bound / kmax
        );
        assert!(
            r.stats.restarts >= 2,
            "k = {k:e}: touch and release restart"
        );
        // Up to k = 1e8 the rise stays below 7e-5 of the kinetic energy (measured), far
        // inside the bound. At 1e9 and 1e10 it reaches 2.1e-4 and 0.40 (within the bound,
        // 0.16 and 0.99, which is then too loose to tell the measure's error from energy the
        // stages create across the stiff onset): recorded in docs/accuracy.md as open, only
        // the run's completion is asserted there.
        if k <= 1e8 {
            assert!(rise(&rec) <= bound, "k = {k:e}: energy rose");
        }
    }
}

/// The bouncing mass (`contact_bounce.dat`: k = 1e6 N/m, ζ = 0.1, the unclipped law, no
/// gravity) with the contact resolved by the step itself (`IMPACT_STEPS 1`: ωh = 0.2 …
/// 0.025, ω = 1000 rad/s): the rebound velocity against the Kelvin–Voigt closed form
/// `e = exp(−ζπ/√(1−ζ²))` (tests/contact.rs). The touch and the release are landed on and the
/// stages restart there, so the restitution converges at the scheme's order 3 (HHT α = 0 on
/// the same ladder: 2.03e-3, 5.06e-4, 1.25e-4, 3.1e-5, order 2.0). The slopes of single
/// halvings scatter (measured 2.88, 3.54, 2.83: the last step in contact is a partial one,
/// of a different length at each h), so the test takes the slope over the whole ladder (h
/// divided by 8): a disturbance of the error by a factor 2^(±0.27) (half the largest
/// measured deviation of a single slope, 0.54) at each end moves it by at most
/// ±0.54/3 = ±0.18; order 2 or 4 cannot pass `|s − 3| ≤ 0.25`. The landing tolerance
/// (1e-4 of a step in time) bounds the event timing's share of the error to ~1e-7 (the floor
/// measured at h ≤ 1.25e-5 s), below 1/9 of the smallest error here (9.4e-7).
#[test]
fn restitution_is_third_order_through_the_unclipped_contact() {
    let errs = restitution_errors(Scheme::Esdirk3);
    let s = (errs[0] / errs[3]).log2() / 3.0;
    let es: Vec<String> = errs.iter().map(|x| format!("{x:.3e}")).collect();
    println!(
        "ESDIRK3 restitution errors [{}] at h = 2e-4 … 2.5e-5 s, slope over the ladder {s:.3}, single slopes {:?}",
        es.join(", "),
        slopes(&errs)
    );
    assert!((s - 3.0).abs() <= 0.25, "restitution order {s}");
}

/// The relative error of the restitution coefficient of the bouncing mass at h = 2e-4,
/// 1e-4, 5e-5 and 2.5e-5 s (see [`restitution_is_third_order_through_the_unclipped_contact`]).
fn restitution_errors(scheme: Scheme) -> Vec<f64> {
    let (k, m, zeta, v0) = (1e6f64, 1.0f64, 0.1f64, (2.0 * 9.81f64).sqrt());
    let e_exact = (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
    let mut errs = Vec::new();
    for h in [2e-4, 1e-4, 5e-5, 2.5e-5] {
        let mut model = deck("contact_bounce.dat");
        for el in model.elements.values_mut() {
            if let ElementKind::Came(d) = &mut el.kind {
                assert_eq!(d.stiffness, k);
                assert!((d.damping - 2.0 * zeta * (k * m).sqrt()).abs() < 1e-9);
                d.impact_steps = 1;
            }
        }
        with_scheme(&mut model, scheme, h, 0.008);
        let mut integ = solver::prepare(&model).expect("prepare");
        let n = node(&model, 2);
        integ.set_velocity(n, Vector3::new(0.0, -v0, 0.0), Vector3::zeros());
        let mut rec = Rec::default();
        let r = solver::run_prepared(&model, &mut integ, &mut rec).expect("run");
        assert!(r.failure.is_none(), "h = {h}: {:?}", r.failure);
        assert!(r.stats.restarts >= 2, "h = {h}: touch and release restart");
        // After the release (at 3.4 ms) the mass flies free: its velocity is the rebound's.
        let e = rec.last[n].v.y / v0;
        errs.push((e - e_exact).abs() / e_exact);
    }
    errs
}

/// The simple pendulum at h = 1e-2 … 1e-6 s (to 0.05 s): converges at every step size
/// with the constraint held (≤ 1e-11 m) and bounded Newton effort per stage.
#[test]
fn step_range_keeps_the_constraint_and_iterations() {
    for (scheme, h) in SCHEMES
        .into_iter()
        .flat_map(|s| [1e-2, 1e-3, 1e-4, 1e-5, 1e-6].map(|h| (s, h)))
    {
        let mut m = deck("simple_pendulum.dat");
        with_scheme(&mut m, scheme, h, 0.05f64.max(50.0 * h));
        let (r, rec) = run(&m);
        assert!(
            r.failure.is_none(),
            "{scheme} h = {h:e}: {}",
            r.failure.unwrap()
        );
        let implicit = if scheme == Scheme::Esdirk3 { 3.0 } else { 6.0 };
        let per_stage = r.stats.newton_iterations as f64 / (implicit * r.stats.steps as f64);
        println!(
            "{scheme} pendulum h = {h:.0e}: {} steps, {per_stage:.2} it/stage, violation {:.1e}",
            r.stats.steps, rec.viol
        );
        assert!(
            rec.viol < 1e-11,
            "{scheme} h = {h:e}: violation {:e}",
            rec.viol
        );
        // A stage from a good predictor: one solve, a check and at most a few polishing
        // iterations; 10 per stage would mean the kept matrix no longer contracts.
        assert!(per_stage < 10.0, "{scheme} h = {h:e}: {per_stage} it/stage");
    }
}

/// The pendulum without floor (10 beams per bar, steel) at h = 1e-3 s, where the beams'
/// axial and shear modes have ωh up to ~1e3 (HHT α = 0 blows up on them near 2.3 s): 20 s
/// (2e4 steps) with the energy balance never above its start, its loss reported; the
/// tumbling bar of `tumbling_beam.dat` (rotation vectors through 2π, 4π, …) for 10 s.
#[test]
fn long_runs_stay_bounded() {
    for scheme in SCHEMES {
        long_runs_stay_bounded_with(scheme);
    }
}

fn long_runs_stay_bounded_with(scheme: Scheme) {
    let mut m = deck("pendulum_nocontact.dat");
    with_scheme(&mut m, scheme, 1e-3, 20.0);
    let (r, rec) = run(&m);
    assert!(r.failure.is_none(), "{}", r.failure.unwrap());
    let kmax = max_of(&rec.kin);
    let loss = rec.e[0] - rec.e.last().unwrap();
    // While the torque pulse acts (t ≤ 0.02 s) the balance's trapezoidal work of the pulse
    // errs by up to `quadrature_bound`; after it only gravity acts, which the balance holds
    // exactly (its potential is in E), so from there on no rise at all beyond Newton's
    // tolerance (1e-6 of the largest kinetic energy, as in tests/stability/stiff.rs).
    let after = rec
        .t
        .iter()
        .position(|t| *t >= 0.02)
        .expect("run past the pulse");
    let rise_after = rec.e[after..]
        .iter()
        .fold(f64::NEG_INFINITY, |m, e| m.max(e - rec.e[after]));
    let bound = 1e-6 * kmax + quadrature_bound(&rec);
    println!(
        "{scheme} long run: {} steps, {:.2} it/step, rise {:.1e} (bound {:.1e}), after the pulse {:.1e}, loss over 20 s {:.2e} of max kinetic {kmax:.1} J",
        r.stats.steps,
        r.stats.newton_iterations as f64 / r.stats.steps as f64,
        rise(&rec) / kmax,
        bound / kmax,
        rise_after / kmax,
        loss / kmax
    );
    assert!(rise(&rec) <= bound, "energy rose by {:e} J", rise(&rec));
    assert!(
        rise_after <= 1e-6 * kmax,
        "energy rose by {rise_after:e} J after the pulse"
    );
    let mut m = deck("tumbling_beam.dat");
    with_scheme(&mut m, scheme, 0.01, 10.0);
    let (r, rec) = run(&m);
    assert!(r.failure.is_none(), "tumbling: {}", r.failure.unwrap());
    let drift = (rec.e.last().unwrap() - rec.e[0]).abs() / rec.e[0].abs().max(1e-300);
    println!("{scheme} tumbling beam: 1000 steps, energy change {drift:.1e} relative");
    assert!(
        rise(&rec) <= 1e-6 * max_of(&rec.kin),
        "tumbling: energy rose"
    );
}

/// A run that cannot converge (`stab_diverge.dat`, with ESDIRK3 on its card) fails cleanly:
/// exit code 1, the diagnosis, `summary.json` incomplete, no NaN in any file.
#[test]
fn a_diverging_run_fails_cleanly() {
    for kw in ["ESDIRK3", "ESDIRK5"] {
        a_diverging_run_fails_cleanly_with(kw);
    }
}

fn a_diverging_run_fails_cleanly_with(kw: &str) {
    let scratch = common::TempDir::new(&format!("esdirk_diverge_{kw}"));
    let text = std::fs::read_to_string(common::deck_path("stab_diverge.dat")).unwrap();
    let text = text.replace(
        "ANALYSIS DYNAMIC ALPHA -0.1",
        &format!("ANALYSIS DYNAMIC {kw}"),
    );
    assert!(text.contains(kw));
    let deck = scratch.join("diverge.dat");
    std::fs::write(&deck, text).unwrap();
    let out_dir = scratch.join("out");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck)
        .arg("-o")
        .arg(&out_dir)
        .output()
        .expect("binary runs");
    let err = String::from_utf8_lossy(&out.stderr);
    println!("exit {:?}\n{err}", out.status.code());
    assert_eq!(out.status.code(), Some(1));
    for needle in [
        "at t = ",
        "with step h = ",
        "relative residual by iteration",
    ] {
        assert!(err.contains(needle), "diagnosis lacks {needle:?}: {err}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["complete"], serde_json::json!(false));
    // The CSVs hold no NaN or infinity; summary.json parsed above (JSON has neither, and its
    // keys may say "rho_inf").
    for f in std::fs::read_dir(&out_dir).unwrap() {
        let p = f.unwrap().path();
        if p.extension().is_some_and(|e| e == "csv") {
            let low = std::fs::read_to_string(&p).unwrap().to_ascii_lowercase();
            assert!(
                !low.contains("nan") && !low.contains("inf"),
                "{} has a non-finite value",
                p.display()
            );
        }
    }
}

/// ESDIRK5 (Kennedy & Carpenter's ESDIRK5(4)7L[2]SA2) on the torque-free rigid body of
/// `free_body.dat`: no constraint, so the scheme's classical order 5 shows (the RKMK stages
/// with the exact `dexp⁻¹`), measured slopes 4.88, 4.93, 4.96 of the differences of
/// successive runs at h = 0.16 … 0.01 s over 4 s. The Newton tolerances are tightened to
/// 1e-13 (residual) and 1e-15 (increment): with the defaults the differences stop falling
/// at ~2e-9 rad (the defaults' accuracy), below which the scheme's 5e-11 at h = 0.02 s
/// cannot show.
#[test]
fn fifth_order_on_the_free_rigid_body_with_esdirk5() {
    let mut m = deck("free_body.dat");
    let mut finals = Vec::new();
    for h in [0.16, 0.08, 0.04, 0.02, 0.01] {
        with_scheme(&mut m, Scheme::Esdirk5, h, 4.0);
        if let Analysis::Dynamic { newton, .. } = &mut m.analysis {
            newton.tol_residual = 1e-13;
            newton.tol_increment = 1e-15;
        }
        let (r, rec) = run(&m);
        assert!(r.failure.is_none(), "h = {h}: {}", r.failure.unwrap());
        finals.push(rec.last[0].r);
    }
    let d: Vec<f64> = finals.windows(2).map(|w| (w[0] - w[1]).norm()).collect();
    assert_order("ESDIRK5, free rigid body (differences)", &d, 5.0);
}

/// ESDIRK5 on the rigid pendulum (a HINGE: index 3) against its ODE, h = 0.04 … 0.0025 s
/// over 2 s: third order, not five. Its inner stages meet the constraints at the velocity
/// level, so with stage order 2 the positions converge at min(p, q + 1) = 3 (Hairer &
/// Wanner II, § VII.4), as ESDIRK3's do (measured slopes 4.25, 3.60, 3.33, 3.09, coming
/// down to 3 from above), with errors 2.1–5.4 times smaller than ESDIRK3's at the same step
/// from h = 0.02 s on.
#[test]
fn esdirk5_is_third_order_on_the_rigid_pendulum_against_its_ode() {
    let mut m = deck("simple_pendulum.dat");
    let t_end = 2.0;
    let th = pendulum_angle(t_end);
    let exact = Vector3::new(th.cos(), th.sin(), 0.0);
    let n2 = node(&m, 2);
    let mut errs = [Vec::new(), Vec::new()];
    for h in [0.04, 0.02, 0.01, 0.005, 0.0025] {
        for (k, scheme) in SCHEMES.into_iter().enumerate() {
            with_scheme(&mut m, scheme, h, t_end);
            let (r, rec) = run(&m);
            assert!(
                r.failure.is_none(),
                "{scheme} h = {h}: {}",
                r.failure.unwrap()
            );
            assert!(rec.viol < 1e-11, "{scheme}: violation {:e}", rec.viol);
            errs[k].push((rec.last[n2].x - exact).norm());
        }
    }
    assert_third_order("ESDIRK5, rigid pendulum", &errs[1]);
    // From h = 0.02 s on (ωh ≤ 0.06 for the pendulum's 0.5 Hz); at 0.04 s ESDIRK5's larger
    // error constant of the constrained stages still dominates (1.4e-4 against 7.9e-5 m).
    for (e3, e5) in errs[0].iter().zip(&errs[1]).skip(1) {
        assert!(e5 < e3, "ESDIRK5 {e5:e} against ESDIRK3 {e3:e}");
    }
}

/// ESDIRK5 through the unclipped contact of the bouncing mass (the ladder of
/// [`restitution_is_third_order_through_the_unclipped_contact`]): errors of the restitution
/// coefficient 2.8e-6, 2.4e-6, 1.9e-6, 2.7e-7 at h = 2e-4 … 2.5e-5 s (measured), against
/// ESDIRK3's 5.8e-4 … 9.4e-7. Not an order: below ~3e-6 the error is the contact's
/// landing and restart, not the stages' (it stops falling between 2e-4 and 5e-5 s). Asserted:
/// below ESDIRK3's at every step, and below 1e-5 — a tenth of ESDIRK3's error at 1e-4 s —
/// at steps up to 2e-4 s (ωh = 0.2).
#[test]
fn esdirk5_restitution_is_accurate_through_the_unclipped_contact() {
    let e3 = restitution_errors(Scheme::Esdirk3);
    let e5 = restitution_errors(Scheme::Esdirk5);
    println!("ESDIRK5 restitution errors {e5:?} (ESDIRK3 {e3:?})");
    for (a, b) in e3.iter().zip(&e5) {
        assert!(b < a && *b < 1e-5, "ESDIRK5 {b:e}, ESDIRK3 {a:e}");
    }
}

/// A stage scheme's steps are checked for events at every stage, not only at their ends
/// (`Integrator::event_control` at each inner stage, src/solver/integrator/esdirk.rs): the steel clearance impact of
/// `stab_clearance_impact.dat` (5 m/s into a 0.5 mm clearance, the Lankarani–Nikravesh law
/// with k = 6.61e10, e = 0.9: an impact 1e-5 s long at t = 1e-4 s) with base steps 1e-3,
/// 5e-4 and 1e-4 s. With the ends alone a 5e-4 s step's stages sat in the contact that both
/// ends were clear of: ESDIRK3 reached 6.9e-5 m of penetration instead of 1.8e-4 m and kept
/// 0.3 J of 5 J, and ESDIRK5 at 1e-3 s created 33 J. Asserted, as
/// `clearance_joint_hard_impact_over_the_step_range` in tests/stability/clearance.rs does for HHT: no
/// energy created (the balance `E − W_ext + W_damp` above its start by no more than 1e-6 of
/// the initial 12.5 J plus the trapezoidal error of the contact's dissipated work,
/// [`quadrature_bound`]: measured 3.1e-3 J for ESDIRK3 at 1e-3 s), and the deepest penetration within
/// (π/N)²/4 = 2.5 % (N = 10 steps per impact) of the impact ODE's (RK4, tests/common/impact.rs).
#[test]
fn stages_see_a_clearance_impact_inside_a_step() {
    let (m, v0, k) = (1.0, 5.0, 6.61e10f64);
    let hertz = (5.0 * m * v0 * v0 / (4.0 * k)).powf(0.4);
    let law = common::impact::lankarani_nikravesh(k, 1.5, 0.9, v0);
    let (_, deepest) = common::impact::impact_ode(m, v0, law, 3.0 * hertz / v0, 20_000);
    let tol = (std::f64::consts::PI / 10.0).powi(2) / 4.0;
    for (scheme, h) in SCHEMES
        .into_iter()
        .flat_map(|s| [1e-3, 5e-4, 1e-4].map(|h| (s, h)))
    {
        let mut model = deck("stab_clearance_impact.dat");
        with_scheme(&mut model, scheme, h, 2e-3);
        let mut integ = solver::prepare(&model).expect("prepare");
        let mut rec = Rec::default();
        let r = solver::run_prepared(&model, &mut integ, &mut rec).expect("run");
        assert!(r.failure.is_none(), "{scheme} h = {h:e}: {:?}", r.failure);
        let s = integ.sys.elements[0].summary().expect("summary");
        let pen = s["max_penetration"].as_f64().unwrap();
        let e0 = rec.e[0];
        let bound = 1e-6 * e0 + quadrature_bound(&rec);
        println!(
            "{scheme} clearance impact, h = {h:e}: {} steps ({} refused), penetration {pen:.5e} m \
             (ODE {deepest:.5e}), rise {:.1e} J (bound {bound:.1e}) of {e0} J",
            r.stats.steps,
            r.stats.rejected_steps,
            rise(&rec)
        );
        assert!(rise(&rec) <= bound, "{scheme} h = {h:e}: energy created");
        assert!(
            (pen - deepest).abs() <= tol * deepest,
            "{scheme} h = {h:e}: penetration {pen:e} against {deepest:e}"
        );
    }
}
