//! The stability suite (issue 8): hard cases users of MECANO-style codes hit, each on a deck
//! from `decks/`. The tests print what they measure (`-- --nocapture`); the figures are
//! recorded in one place, docs/stability.md (with the suite's cost), not repeated here, so
//! that the two cannot disagree (issue 27 §1d).

mod common;

use mecano::model::{ElementId, ElementKind, Model, NodeId, Scheme};
use mecano::solver::{self, Observer, RunReport, Snapshot};
use nalgebra::{Complex, Matrix3, Vector3};
use std::f64::consts::PI;

/// The integrator the suite runs its cases with instead of the decks' (issue 26):
/// `MECANO_STABILITY_SCHEME=genalpha:0.8 cargo test --test stability` (names as
/// `study --integrator`). Unset: the decks' own, and the α each case sets. The HHT-only
/// closed form is then skipped (generalized-α's is `tests/genalpha.rs`), and the cases
/// that run a deck through the binary (clean failure) keep their decks'.
fn scheme_override() -> Option<Scheme> {
    let s = std::env::var("MECANO_STABILITY_SCHEME").ok()?;
    Some(Scheme::parse(&s).unwrap_or_else(|e| panic!("MECANO_STABILITY_SCHEME: {e}")))
}

/// `common::deck`, with the scheme of [`scheme_override`] if set.
fn deck(name: &str) -> Model {
    let mut m = common::deck(name);
    if let (Some(s), mecano::model::Analysis::Dynamic { scheme, .. }) =
        (scheme_override(), &mut m.analysis)
    {
        *scheme = s;
    }
    m
}

/// Fixed steps `h` to `t_end`, with HHT `alpha` if given — unless the suite runs with
/// another scheme ([`scheme_override`]), which the model then keeps.
fn set_steps(model: &mut Model, h: f64, t_end: f64, alpha: Option<f64>) {
    let alpha = alpha.filter(|_| scheme_override().is_none());
    assert!(
        model.set_fixed_step(h, t_end, alpha.map(|alpha| Scheme::Hht { alpha })),
        "dynamic deck expected"
    );
}

fn set_contact_stiffness(model: &mut Model, k: f64) {
    for el in model.elements.values_mut() {
        if let ElementKind::Came(d) = &mut el.kind {
            d.stiffness = k;
        }
    }
}

fn node(model: &Model, id: u32) -> usize {
    model.nodes.get_index_of(&NodeId(id)).expect("node exists")
}

/// Per accepted state: t, `E − W_ext` (kinetic + strain + gravity − work of the loads),
/// kinetic energy, node states, constraint violation, and the rows of chosen elements.
#[derive(Default)]
struct Rec {
    t: Vec<f64>,
    e: Vec<f64>,
    kin: Vec<f64>,
    nodes: Vec<Vec<mecano::elements::NodeState>>,
    viol: Vec<f64>,
    rows: Vec<Vec<f64>>,
    elem: Option<usize>,
    keep_nodes: bool,
}

impl Observer for Rec {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let i = snap.integ;
        let en = i.energies();
        self.t.push(i.t);
        self.e
            .push(en.kinetic + en.strain + en.gravity - i.external_work);
        self.kin.push(en.kinetic);
        self.viol.push(i.constraint_violation());
        if self.keep_nodes {
            self.nodes.push(i.nodes.clone());
        }
        if let Some(e) = self.elem {
            self.rows.push(i.sys.elements[e].output_row(
                &i.current_context(),
                &i.nodes,
                i.sys.element_lambda(e, &i.lambda),
            ));
        }
        Ok(())
    }
}

fn run(model: &Model, mut rec: Rec) -> (RunReport, Rec) {
    let report = solver::run(model, &mut rec).expect("run starts");
    (report, rec)
}

fn it_per_step(r: &RunReport) -> f64 {
    r.stats.newton_iterations as f64 / r.stats.steps.max(1) as f64
}

/// Largest rise of `E − W_ext` above its initial value.
fn rise(rec: &Rec) -> f64 {
    rec.e.iter().map(|e| e - rec.e[0]).fold(f64::MIN, f64::max)
}

/// The energy rise a case is judged on. The α schemes: [`rise`]. The stage schemes
/// (ESDIRK3, ESDIRK5) keep the resolved motion's energy to O((ωh)⁴) or better, so the
/// balance's trapezoidal work of a torque pulse errs visibly while it acts (up to
/// 1e-2 of the kinetic energy: the bound `quadrature_bound` of tests/esdirk.rs, which judges
/// that part): for them the rise is measured from the end of the decks' pulse (0.02 s), after
/// which only gravity acts, whose work is in `E`.
fn judged_rise(rec: &Rec) -> f64 {
    if !scheme_override().is_some_and(|s| s.is_esdirk()) {
        return rise(rec);
    }
    let Some(k) = rec.t.iter().position(|t| *t >= 0.02) else {
        return rise(rec);
    };
    rec.e[k..]
        .iter()
        .map(|e| e - rec.e[k])
        .fold(f64::MIN, f64::max)
}

/// Newton solves per step: one for the α schemes, the implicit stages for ESDIRK3 (3) and
/// ESDIRK5 (6), so that the per-solve bounds of the suite hold for every scheme.
fn solves_per_step() -> f64 {
    match scheme_override() {
        Some(Scheme::Esdirk3) => 3.0,
        Some(Scheme::Esdirk5) => 6.0,
        _ => 1.0,
    }
}

fn max_of(v: &[f64]) -> f64 {
    v.iter().copied().fold(0.0, f64::max)
}

// ---------------------------------------------------------------- stiff bars

/// The rigid case (10 beams per bar, E = 2.1e15) converges at the same step as steel
/// (h = 1e-4 s, through the torque pulse and the first impact, 0.6 s), with no cut step
/// and a bounded Newton effort: ≤ 4 matrix factorisations per step on average and ≤ 14
/// (modified) Newton iterations (a contraction of at least 4 per iteration from a residual
/// ≤ 1 to the 1e-8 tolerance; figures printed), and its tip follows the RIGID-body variant
/// (`decks/pendulum_rigid_body.dat`; a missing deck fails the test) to
/// within 1e-3 m.
#[test]
fn stiff_bars_converge_at_the_steel_step_and_agree_with_rigid_bodies() {
    let mut out = Vec::new();
    for d in [
        "pendulum.dat",
        "pendulum_rigid.dat",
        "pendulum_rigid_body.dat",
    ] {
        let mut model = deck(d);
        set_steps(&mut model, 1e-4, 0.6, None);
        let tip = node(&model, 23);
        let (r, rec) = run(
            &model,
            Rec {
                keep_nodes: true,
                ..Default::default()
            },
        );
        assert!(r.failure.is_none(), "{d}: {}", r.failure.unwrap());
        let it = it_per_step(&r) / solves_per_step();
        let fact = r.stats.factorizations as f64 / r.stats.steps.max(1) as f64;
        println!(
            "{d}: {} steps, {} cut, {it:.2} it/solve, {fact:.2} factorisations/step, max violation {:.1e}, {:.1} s",
            r.stats.steps,
            r.stats.rejected_steps,
            max_of(&rec.viol),
            r.stats.cpu_seconds
        );
        assert!(it <= 14.0, "{d}: {it} iterations per step");
        assert!(fact <= 4.0, "{d}: {fact} factorisations per step");
        let traj: Vec<(f64, Vector3<f64>)> = rec
            .t
            .iter()
            .zip(&rec.nodes)
            .map(|(t, n)| (*t, n[tip].x))
            .collect();
        out.push((d, traj));
    }
    // Compare at common times (both runs step at 1e-4 apart from impact refinement).
    let (a, b) = (&out[1].1, &out[2].1);
    let mut err: f64 = 0.0;
    let (mut j, mut shared) = (0, 0);
    for (t, x) in a {
        while j + 1 < b.len() && b[j].0 < *t - 1e-9 {
            j += 1;
        }
        if (b[j].0 - t).abs() < 1e-9 {
            err = err.max((b[j].1 - x).norm());
            shared += 1;
        }
    }
    println!(
        "rigid beams vs RIGID bodies: max tip distance {err:.2e} m over 0.6 s, {shared} of {} instants shared",
        a.len()
    );
    // The 6000 steps of 1e-4 s are on both runs' grids; only the impact's refined steps
    // (a few tens) may differ: at least 90 % shared, or the distance means nothing.
    assert!(
        shared * 10 >= a.len() * 9 && shared * 10 >= b.len() * 9,
        "{shared} instants shared of {} and {}",
        a.len(),
        b.len()
    );
    assert!(err < 1e-3, "{err:e} m");
}

// ---------------------------------------------------------------- stiff contact

/// Contact stiffness 1e5 … 1e10 N/m: the bouncing mass (1 m drop, ζ = 0.1 at k = 1e6)
/// and the pendulum (RIGID-body variant for every k; the 10-beam steel deck at the two
/// extremes; to 0.6 s, through the first impact at 0.533 s) all run, and `E − W_ext` never
/// rises above its initial value by more than 1e-6 of the largest kinetic energy: the
/// spring–dashpot only dissipates, whatever the stiffness (the step limiter resolves each
/// impact whatever k).
#[test]
fn stiff_contact_runs_and_never_creates_energy() {
    for k in [1e5, 1e6, 1e7, 1e8, 1e9, 1e10] {
        let mut model = deck("contact_bounce.dat");
        set_contact_stiffness(&mut model, k);
        // Contact damping for ζ = 0.1 at this k, a drop from 1 m (INITIAL would do the same).
        for el in model.elements.values_mut() {
            if let ElementKind::Came(d) = &mut el.kind {
                d.damping = 0.2 * k.sqrt();
            }
        }
        set_steps(&mut model, 1e-4, 0.02, Some(0.0));
        let mut integ = solver::prepare(&model).expect("prepare");
        integ.set_velocity(
            node(&model, 2),
            Vector3::new(0.0, -(2.0 * 9.81f64).sqrt(), 0.0),
            Vector3::zeros(),
        );
        let mut rec = Rec::default();
        let r = solver::run_prepared(&model, &mut integ, &mut rec).expect("run");
        assert!(
            r.failure.is_none(),
            "bounce k = {k:e}: {}",
            r.failure.unwrap()
        );
        let (up, kmax) = (rise(&rec), max_of(&rec.kin));
        println!(
            "bounce k = {k:.0e}: {} steps ({} refused), rise {:.1e} of max kinetic {kmax:.2} J",
            r.stats.steps,
            r.stats.rejected_steps,
            up / kmax
        );
        assert!(
            up <= 1e-6 * kmax,
            "bounce k = {k:e}: energy rose by {up:e} J"
        );
    }
    for (d, ks) in [
        (
            "pendulum_rigid_body.dat",
            &[1e5, 1e6, 1e7, 1e8, 1e9, 1e10][..],
        ),
        ("pendulum.dat", &[1e5, 1e10][..]),
    ] {
        for &k in ks {
            let mut model = deck(d);
            set_contact_stiffness(&mut model, k);
            if d == "pendulum.dat" {
                // Since issue 17 the deck has the paper's unclipped law (CLIP OFF), whose
                // force jumps from −c·q̇ to 0 at the release; at k = 1e10 Newton then fails
                // at the release of the steel pendulum (t = 0.5415 s, h = 2e-7 s: the
                // residual jumps with the contact state between iterations). This test is
                // about the contact stiffness, so it keeps the clipped law (continuous at
                // the release) for this deck; the rigid-body deck runs unclipped at every k.
                for el in model.elements.values_mut() {
                    if let ElementKind::Came(c) = &mut el.kind {
                        c.clip_tension = true;
                    }
                }
            }
            set_steps(&mut model, 1e-4, 0.6, None);
            let (r, rec) = run(&model, Rec::default());
            assert!(r.failure.is_none(), "{d} k = {k:e}: {}", r.failure.unwrap());
            let (up, kmax) = (judged_rise(&rec), max_of(&rec.kin));
            println!(
                "{d} k = {k:.0e}: {} steps ({} refused), {:.2} it/step, rise {:.1e} of max kinetic {kmax:.1} J, {:.1} s",
                r.stats.steps,
                r.stats.rejected_steps,
                it_per_step(&r),
                up / kmax,
                r.stats.cpu_seconds
            );
            assert!(up <= 1e-6 * kmax, "{d} k = {k:e}: energy rose by {up:e} J");
        }
    }
}

// ---------------------------------------------------------------- step range

/// The simple pendulum (IFToMM A01, a HINGE with a 1 m offset, released from rest, α = −0.02)
/// run to t = 0.05 s with h = 1e-2 … 1e-6 s: the Newton iterations per step do not grow as h
/// shrinks, the constraint holds (≤ 1e-11), and the multiplier — the hinge reaction on the mass — agrees with the exact
/// `F = m(a − g)` of the RK4 solution of `θ'' = −(g/L) cos θ` within the truncation bound
/// plus the round-off bound derived below: at 1e-6 s the index-3 formulation's round-off
/// (ε L/(βh²) in the accelerations) is what is left, as derived. (Before the constraint rows got the
/// force tolerance, h = 1e-4 gave 6.6e-3: the absolute 1e-11 m tolerance on Φ, divided by
/// βh², rang in the multipliers.)
///
/// (Runs that start with velocities get the constraints' velocity term Ḃv in their
/// initial multipliers: see `launched_pendulum_starts_with_the_centripetal_tension` in
/// tests/joints.rs.)
#[test]
fn step_range_keeps_iterations_and_multipliers() {
    const T_END: f64 = 0.05;
    let (g, l, m) = (9.81, 1.0, 1.0);
    let mut its = Vec::new();
    for k in 2..=6 {
        let h = 10f64.powi(-k);
        let mut model = deck("simple_pendulum.dat");
        set_steps(&mut model, h, T_END, None);
        let hinge = model.elements.get_index_of(&ElementId(1)).unwrap();
        let (r, rec) = run(
            &model,
            Rec {
                elem: Some(hinge),
                ..Default::default()
            },
        );
        assert!(r.failure.is_none(), "h = {h:e}: {}", r.failure.unwrap());
        assert_eq!(r.stats.rejected_steps, 0);
        // Exact state at t = 50 h by RK4 (200 sub-steps).
        let t_end = *rec.t.last().unwrap();
        let (mut th, mut w) = (0.0f64, 0.0f64);
        let n = 2000;
        let dt = t_end / n as f64;
        let f = |th: f64| -g / l * th.cos();
        for _ in 0..n {
            let (k1t, k1w) = (w, f(th));
            let (k2t, k2w) = (w + 0.5 * dt * k1w, f(th + 0.5 * dt * k1t));
            let (k3t, k3w) = (w + 0.5 * dt * k2w, f(th + 0.5 * dt * k2t));
            let (k4t, k4w) = (w + dt * k3w, f(th + dt * k3t));
            th += dt / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t);
            w += dt / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
        }
        let acc = f(th);
        // a = L θ'' t̂ − L θ'² r̂, r̂ = (cos θ, sin θ), t̂ = (−sin θ, cos θ).
        let (s, c) = th.sin_cos();
        let a = Vector3::new(
            -l * acc * s - l * w * w * c,
            l * acc * c - l * w * w * s,
            0.0,
        );
        let exact = m * (a - Vector3::new(0.0, -g, 0.0));
        let row = rec.rows.last().unwrap();
        let got = Vector3::new(row[1], row[2], row[3]);
        let err = (got - exact).norm() / (m * g);
        let it = it_per_step(&r);
        // Truncation: the reaction m ẍ errs by O(h² m x⁗), x⁗ ~ g ω², ω² = g/L: h² ω² in units
        // of m g, allowed 10×. Round-off: positions are stored to ε L, which the constraint
        // turns into accelerations ε L/(β h²); Newton accepts a residual down to its floor
        // 10 ε c_a m L (integrator.rs), a reaction noise per step which the spurious root of
        // index-3 HHT (ρ∞ = (1+α)/(1−α)) accumulates by 1/(1 − ρ∞).
        let alpha = -0.02; // the deck's
        let (beta, af) = ((1.0 - alpha) * (1.0f64 - alpha) / 4.0, -alpha);
        let c_a = 1.0 / ((1.0 - af) * beta * h * h);
        let rho_inf = (1.0 + alpha) / (1.0 - alpha);
        let truncation = 10.0 * h * h * g / l;
        let roundoff = 10.0 * f64::EPSILON * c_a * m * l / (1.0 - rho_inf) / (m * g);
        println!(
            "h = {h:.0e}: {it:.2} it/step, hinge reaction {:.6} {:.6} N (exact {:.6} {:.6}), relative error {err:.1e}, max violation {:.1e}",
            got.x,
            got.y,
            exact.x,
            exact.y,
            max_of(&rec.viol)
        );
        println!("   bound: truncation {truncation:.1e} + round-off {roundoff:.1e}");
        assert!(err <= truncation + roundoff, "h = {h:e}: {err:e}");
        assert!(max_of(&rec.viol) <= 1e-11, "h = {h:e}");
        its.push(it);
    }
    for w in its.windows(2) {
        assert!(w[1] <= w[0] + 0.5, "iterations grow as h shrinks: {its:?}");
    }
}

// ---------------------------------------------------------------- long run

/// 100 s of the spatial pendulum without contact (`decks/pendulum_nocontact.dat`: the
/// paper's scene, 10 beams per bar, without the floor) at h = 1e-3 s (1e5 steps). With
/// α = −0.1 (the deck's) and α = −0.02, the smallest of {0, −0.01, −0.02} that runs the
/// 100 s (α = 0 and −0.01 blow up on the unresolved axial and shear modes — ωh up to ~1e3
/// at this step — and stop with a clean failure near t = 2.3 s: see
/// `decks/stab_pendulum_undamped.dat` and `a_diverging_run_fails_cleanly`), `E − W_ext`
/// never rises above E(0), and its drift is reported.
/// (The physical energy of HHT is not monotone, only bounded: the scheme dissipates a
/// modified energy, so local rises over the running minimum are printed, not judged.)
#[test]
fn long_run_energy_never_increases_with_damping_and_stays_bounded() {
    // With another scheme (scheme_override) the two runs would be the same one.
    let alphas: &[f64] = if scheme_override().is_some() {
        &[-0.1]
    } else {
        &[-0.1, -0.02]
    };
    for &alpha in alphas {
        let mut model = deck("pendulum_nocontact.dat");
        set_steps(&mut model, 1e-3, 100.0, Some(alpha));
        let (r, rec) = run(&model, Rec::default());
        assert!(r.failure.is_none(), "alpha {alpha}: {}", r.failure.unwrap());
        let kmax = max_of(&rec.kin);
        let (mut lowest, mut up) = (f64::INFINITY, 0.0f64);
        for e in &rec.e {
            lowest = lowest.min(*e);
            up = up.max(e - lowest);
        }
        let loss = rec.e[0] - rec.e.last().unwrap();
        let label = scheme_override().map_or(format!("alpha = {alpha}"), |s| s.label());
        println!(
            "long run {label}: {} steps, {:.2} it/step, {:.1} s CPU; largest rise over the running minimum {:.1e}, \
             above E(0) {:.1e} (of max kinetic {kmax:.1} J); loss over 100 s {loss:.2} J ({:.1e} relative)",
            r.stats.steps,
            it_per_step(&r),
            r.stats.cpu_seconds,
            up / kmax,
            rise(&rec) / kmax,
            loss / kmax
        );
        assert!(
            judged_rise(&rec) <= 1e-6 * kmax,
            "{label}: energy rose above its initial value by {:e} J",
            judged_rise(&rec)
        );
    }
}

// ---------------------------------------------------------------- many turns

/// A free rigid body spinning about its intermediate principal axis (inertias 1, 2, 3;
/// `decks/stab_racket_body.dat`): 50 turns (50 s) with α = 0 at h = 2e-3 s (500 steps per
/// turn): energy and the angular momentum vector (global, `R J Ω`) are conserved within
/// 1e-4 relative, and the body does flip (the tennis-racket instability: the spin about Y
/// reverses), with no singularity of the rotation update.
#[test]
fn free_body_about_the_intermediate_axis_conserves_energy_and_momentum() {
    let model = deck("stab_racket_body.dat");
    let (r, rec) = run(
        &model,
        Rec {
            keep_nodes: true,
            ..Default::default()
        },
    );
    assert!(r.failure.is_none(), "{}", r.failure.unwrap());
    let j = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0));
    let l: Vec<Vector3<f64>> = rec.nodes.iter().map(|n| n[0].r * (j * n[0].w)).collect();
    let e0 = rec.e[0];
    let de = rec.e.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max) / e0;
    let dl = l.iter().map(|x| (x - l[0]).norm()).fold(0.0, f64::max) / l[0].norm();
    // Flips: sign changes of the body-frame spin about Y.
    let flips = rec
        .nodes
        .windows(2)
        .filter(|w| w[0][0].w.y * w[1][0].w.y < 0.0)
        .count();
    println!(
        "racket body: {} steps, {:.2} it/step; energy drift {de:.2e}, angular momentum drift {dl:.2e}, {flips} flips",
        r.stats.steps,
        it_per_step(&r)
    );
    assert!(de < 1e-4 && dl < 1e-4, "drifts {de:e}, {dl:e}");
    assert!(flips >= 2, "the body should flip");
}

/// Energy, angular momentum about the origin and body-frame spin flips of the flexible
/// racket (`decks/stab_racket_beam.dat`), accumulated step by step (250,000 states).
struct RacketBeam {
    /// Per BEAM: node indices, translational mass ρ A L_e, nodal rotary inertia (material).
    beams: Vec<([usize; 2], f64, Vector3<f64>)>,
    /// Per MASS: node, rotary inertia (material frame = global at t = 0).
    masses: Vec<(usize, Matrix3<f64>)>,
    centre: usize,
    e0: f64,
    l0: Vector3<f64>,
    de: f64,
    dl: f64,
    flips: usize,
    last_spin: f64,
}

impl RacketBeam {
    fn new(model: &Model) -> Self {
        let mut beams = Vec::new();
        let mut masses = Vec::new();
        for el in model.elements.values() {
            match &el.kind {
                ElementKind::Beam {
                    material, section, ..
                } => {
                    let (p, _) = model.beam_properties(*material, *section);
                    let n = [node(model, el.nodes[0].0), node(model, el.nodes[1].0)];
                    let le = (model.nodes[n[1]].position - model.nodes[n[0]].position).norm();
                    beams.push((n, p.mass * le, p.inertia * (0.5 * le)));
                }
                ElementKind::Mass { inertia, .. } => {
                    masses.push((node(model, el.nodes[0].0), *inertia));
                }
                _ => {}
            }
        }
        RacketBeam {
            beams,
            masses,
            centre: node(model, 3),
            e0: f64::NAN,
            l0: Vector3::zeros(),
            de: 0.0,
            dl: 0.0,
            flips: 0,
            last_spin: 0.0,
        }
    }

    /// `L = Σ_beams m/6 (2 x₁×v₁ + x₁×v₂ + x₂×v₁ + 2 x₂×v₂)` (the consistent linear mass)
    /// `+ Σ R J Ω` (the lumped rotary inertias and the MASS).
    fn momentum(&self, nodes: &[mecano::elements::NodeState]) -> Vector3<f64> {
        let mut l = Vector3::zeros();
        for (n, m, j) in &self.beams {
            let (a, b) = (&nodes[n[0]], &nodes[n[1]]);
            l +=
                (a.x.cross(&a.v) * 2.0 + a.x.cross(&b.v) + b.x.cross(&a.v) + b.x.cross(&b.v) * 2.0)
                    * (m / 6.0);
            for s in [a, b] {
                l += s.r * j.component_mul(&s.w);
            }
        }
        for (n, j) in &self.masses {
            let s = &nodes[*n];
            l += s.r * (j * s.w);
        }
        l
    }
}

impl Observer for RacketBeam {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let i = snap.integ;
        let en = i.energies();
        let e = en.kinetic + en.strain;
        let l = self.momentum(&i.nodes);
        if self.e0.is_nan() {
            (self.e0, self.l0) = (e, l);
        }
        self.de = self.de.max((e - self.e0).abs() / self.e0);
        self.dl = self.dl.max((l - self.l0).norm() / self.l0.norm());
        let spin = i.nodes[self.centre].w.y;
        if spin * self.last_spin < 0.0 {
            self.flips += 1;
        }
        self.last_spin = spin;
        Ok(())
    }
}

/// A free *flexible* beam spinning about its intermediate principal axis
/// (`decks/stab_racket_beam.dat`: 4 BEAMs and a MASS, principal inertias 0.15, 2.58, 3.58
/// kg m²; spin 2π rad/s, perturbed by 0.01 rad/s): 50 turns with α = 0 at h = 2e-4 s, the
/// step that resolves every mode of the mesh (ωh < 0.3, see the deck): energy (kinetic +
/// strain) and the angular momentum vector are conserved within 1e-4 relative, and the bar
/// does flip (the body-frame spin of its centre node about Y reverses), with no singularity.
#[test]
fn flexible_beam_about_the_intermediate_axis_conserves_energy_and_momentum() {
    let model = deck("stab_racket_beam.dat");
    let mut obs = RacketBeam::new(&model);
    let r = solver::run(&model, &mut obs).expect("run starts");
    assert!(r.failure.is_none(), "{}", r.failure.unwrap());
    println!(
        "racket beam: {} steps, {:.2} it/step, {:.1} s CPU; energy drift {:.2e}, angular momentum drift {:.2e}, {} flips",
        r.stats.steps,
        it_per_step(&r),
        r.stats.cpu_seconds,
        obs.de,
        obs.dl,
        obs.flips
    );
    assert!(
        obs.de < 1e-4 && obs.dl < 1e-4,
        "drifts {:e}, {:e}",
        obs.de,
        obs.dl
    );
    assert!(obs.flips >= 2, "the bar should flip");
}

// ---------------------------------------------------------------- numerical damping

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

// ---------------------------------------------------------------- failure is clean

/// Two decks built to diverge, through the binary: `decks/stab_diverge.dat` (a steel
/// cantilever hit by 1e12 N at once, steps not allowed to be cut) and
/// `decks/stab_pendulum_undamped.dat` (α = 0 on unresolved beam modes: the energy grows
/// until Newton fails near t = 2.26 s). Each: exit code 1; the diagnosis on standard error
/// names the time, the step, the residual history and the worst node or element (its equation); `summary.json` says
/// `"complete": false` with the failure; no NaN or infinity in any output file.
#[test]
fn a_diverging_run_fails_cleanly() {
    for name in ["stab_diverge", "stab_pendulum_undamped"] {
        fails_cleanly(name);
    }
}

fn fails_cleanly(name: &str) {
    let scratch = common::TempDir::new(name);
    let dir = scratch.path();
    let deck = common::deck_path(&format!("{name}.dat"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck)
        .arg("-o")
        .arg(dir)
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
    assert!(
        err.contains("largest residual: node ") || err.contains("largest residual: element "),
        "diagnosis names no worst node or element: {err}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["complete"], serde_json::json!(false));
    assert!(
        summary["failure"]["worst"]
            .as_str()
            .unwrap()
            .starts_with("node ")
            || summary["failure"]["worst"]
                .as_str()
                .unwrap()
                .starts_with("element ")
    );
    assert!(summary["failure"]["time"].as_f64().is_some());
    let mut files = 0;
    for f in std::fs::read_dir(dir).unwrap() {
        let p = f.unwrap().path();
        let text = std::fs::read_to_string(&p).unwrap();
        // A non-finite value is a whole field `nan`, `inf`, `-inf` or `infinity` (not a
        // key such as summary.json's `rho_inf`).
        let low = text.to_ascii_lowercase();
        let non_finite = low
            .split(|c: char| c == ',' || c == ':' || c == '"' || c.is_whitespace())
            .any(|w| matches!(w.trim_start_matches(['-', '+']), "nan" | "inf" | "infinity"));
        assert!(!non_finite, "{} has a non-finite value", p.display());
        files += 1;
    }
    assert!(files >= 3);
}

// ---------------------------------------------------------------- clearance joint

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

// ---------------------------------------------------------------- energy bursts (issue 35)

/// Step sizes and the balance along a run: every step, the largest growth of the step
/// from one accepted step to the next, and the guard's record at the end.
#[derive(Default)]
struct Steps {
    h: Vec<f64>,
}

impl Observer for Steps {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        if snap.h > 0.0 {
            self.h.push(snap.h);
        }
        Ok(())
    }
}

/// The seed's scene through its torque pulse, the swing and the first impacts (0.6 s, the
/// contact's events landing steps at 2e-7 s and less): no step is more than twice the
/// one before it (the grid's return splits into equal steps, the steps after a landing
/// double back: `solver::grid_step`, `solver::regrowth`), and the guard's largest
/// accepted rise of the balance residual is within its bound and tiny against the energy
/// in play (measured 0.048 J at the first impact, 0.535 s, of ~170 J).
#[test]
fn steps_never_grow_by_more_than_two_and_the_balance_stays_within_its_bound() {
    let mut m = deck("pendulum.dat");
    set_steps(&mut m, 1e-4, 0.6, Some(-0.1));
    let mut steps = Steps::default();
    let mut integ = solver::prepare(&m).unwrap();
    let report = solver::run_prepared(&m, &mut integ, &mut steps).unwrap();
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let growth = steps.h.windows(2).map(|w| w[1] / w[0]).fold(0.0, f64::max);
    let shortest = steps.h.iter().copied().fold(f64::INFINITY, f64::min);
    let b = integ.balance;
    println!(
        "pendulum 0.6 s: {} steps, shortest {shortest:.3e} s, largest growth {growth:.4}, largest rise {:.3e} J (bound {:.3e} J)",
        steps.h.len(),
        b.largest_rise,
        b.its_bound
    );
    assert!(
        shortest < 1e-6,
        "the run should land contact events: {shortest:e}"
    );
    if scheme_override().is_none() {
        assert!(growth <= 2.0 * (1.0 + 1e-9), "a step grew by {growth}");
    }
    assert!(b.largest_rise <= b.its_bound, "{b:?}");
    assert!(b.largest_rise < 1.0, "{b:?}");
}

/// The seed's scene run long (`decks/pendulum.dat`, to 30 s and 100 s; issue 35): it runs
/// clean, the balance residual never rises by more than 1 J above its running minimum
/// (measured 0.048 J; before issue 35 the 30 s run completed with a burst of 66 J at
/// 23.18 s, 270 J per step-by-step accounting) and the guard's record stays within its
/// bound. Expensive (1.7 and 1.5 min of CPU in release): run on demand,
/// `cargo test --release --features failpoints --test stability -- --ignored seed_scene`.
#[test]
#[ignore]
fn seed_scene_runs_clean_to_30_and_100_s() {
    for end in [30.0, 100.0] {
        let mut m = deck("pendulum.dat");
        set_steps(&mut m, 1e-4, end, Some(-0.1));
        let mut rec = Rec::default();
        let mut integ = solver::prepare(&m).unwrap();
        let report = solver::run_prepared(&m, &mut integ, &mut rec).unwrap();
        assert!(report.failure.is_none(), "{end} s: {:?}", report.failure);
        // E − W_ext: its rise above its running minimum (the dampers only lower it).
        let (mut low, mut worst) = (f64::INFINITY, 0.0f64);
        for e in &rec.e {
            low = low.min(*e);
            worst = worst.max(e - low);
        }
        let b = integ.balance;
        println!(
            "pendulum to {end} s: {} steps ({} refused), rise of E − W above its running minimum {worst:.3e} J, guard's largest {:.3e} J (bound {:.3e} J)",
            report.stats.steps, report.stats.rejected_steps, b.largest_rise, b.its_bound
        );
        assert!(b.largest_rise <= b.its_bound, "{b:?}");
        assert!(b.largest_rise < 1.0, "{end} s: {b:?}");
    }
}
