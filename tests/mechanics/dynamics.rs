//! The dynamics core against closed forms and published benchmarks (issue: finite
//! rotations, the geometrically exact BEAM, HHT and Newton). Every case runs a deck from
//! `decks/`; tolerances are derived in the comments next to them.

use crate::common;

use common::deck;
use mecano::elements::NodeState;
use mecano::model::{Function, Model, NodeId, Scheme};
use mecano::output::History;
use mecano::rotation;
use mecano::solver;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

fn run(model: &Model, every: u64) -> History {
    let mut h = History::new(every);
    let report = solver::run(model, &mut h).expect("run starts");
    assert!(
        report.failure.is_none(),
        "run failed: {}",
        report.failure.unwrap()
    );
    h
}

fn idx(model: &Model, node: u32) -> usize {
    model
        .nodes
        .get_index_of(&NodeId(node))
        .expect("node exists")
}

fn set_dynamic(model: &mut Model, h: f64, t_end: f64, alpha: Option<f64>) {
    assert!(
        model.set_fixed_step(h, t_end, alpha.map(|alpha| Scheme::Hht { alpha })),
        "dynamic deck expected"
    );
}

/// Cantilever roll-up (static): `M₀ = 2πEI/L` bends the beam into a full circle; at
/// `M₀/2` it is a half circle of radius `R = EI/M = L/π`.
///
/// With one-point integration and an interpolation of the relative rotation, each element
/// carries the exact constant curvature `M/EI` and an inextensible *chord* of length `Lₑ`
/// (zero axial force). The discrete solution is therefore the regular polygon inscribed in
/// a circle of radius `R' = Lₑ / (2 sin(θₑ/2))`, `θₑ = M Lₑ / EI`: at `M₀` it closes
/// exactly (tip at the clamp, rotation 2π); at `M₀/2` its tip is at height `2R'`, which
/// tends to the closed form `2R` as `(θₑ/2)²/6` relative.
#[test]
fn cantilever_rolls_up_into_a_full_circle() {
    let mut half_errors = Vec::new();
    for n in [10usize, 20] {
        let model = deck(&format!("cantilever_rollup_{n}.dat"));
        let tip = idx(&model, n as u32 + 1);
        let h = run(&model, 1);
        let last = h.nodes.last().unwrap()[tip];
        // Full circle: the tip is back at the clamp, turned by 2π (R = I), to 1e-3 L.
        assert!(last.x.norm() < 1e-3, "{n} elements: tip at {}", last.x);
        assert!((last.r - Matrix3::identity()).norm() < 1e-9);
        // Half circle at the load factor 0.5 (load step 10 of 20).
        let k =
            h.t.iter()
                .position(|t| (t - 0.5).abs() < 1e-9)
                .expect("t = 0.5 recorded");
        let tip_half = h.nodes[k][tip].x;
        let le = 1.0 / n as f64;
        let theta_e = PI * le; // M Lₑ/EI with M = M₀/2 = π EI / L, L = 1
        let polygon = le / (theta_e / 2.0).sin(); // 2R'
        let exact = 2.0 / PI; // 2R
        assert!(
            (tip_half.y - polygon).abs() < 1e-9,
            "{n}: {} vs polygon {polygon}",
            tip_half.y
        );
        assert!(
            tip_half.x.abs() < 1e-9,
            "{n}: the half circle tip is above the clamp"
        );
        let err = (tip_half.y - exact).abs();
        let bound = exact * ((theta_e / 2.0) / (theta_e / 2.0).sin() - 1.0) * 1.0001;
        assert!(
            err <= bound,
            "{n}: half-circle error {err} above the polygon bound {bound}"
        );
        half_errors.push(err);
    }
    // Second-order convergence: halving the element size divides the error by ~4.
    let ratio = half_errors[0] / half_errors[1];
    assert!((3.8..4.2).contains(&ratio), "refinement ratio {ratio}");
}

/// First bending frequency of the seed's steel cantilever (20 elements) against the
/// Euler–Bernoulli closed form `f₁ = (1.8751²/2πL²)√(EI/ρA)` = 27.88 Hz. Shear and rotary
/// inertia lower it by ~(r/L)² ≈ 1e-4 for this slender bar, the trapezoidal rule lengthens
/// the period by (ωh)²/12 = 1e-4, and 20 linear elements stiffen it by ~0.1%: all well
/// inside the 1%.
#[test]
fn cantilever_first_bending_frequency() {
    let model = deck("cantilever_frequency.dat");
    let tip = idx(&model, 21);
    let h = run(&model, 1);
    let y: Vec<f64> = h.nodes.iter().map(|n| n[tip].x.y).collect();
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    // Up-crossings of the mean, linearly interpolated.
    let mut crossings = Vec::new();
    for k in 1..y.len() {
        let (a, b) = (y[k - 1] - mean, y[k] - mean);
        if a < 0.0 && b >= 0.0 {
            crossings.push(h.t[k - 1] + (h.t[k] - h.t[k - 1]) * (-a) / (b - a));
        }
    }
    assert!(crossings.len() >= 6, "only {} periods", crossings.len());
    let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let (e, i, rho, a): (f64, f64, f64, f64) = (2.1e11, 8.3e-8, 7800.0, 9e-4);
    let f1 = 1.875104068711961f64.powi(2) / (2.0 * PI) * (e * i / (rho * a)).sqrt();
    let rel = (1.0 / period - f1) / f1;
    assert!(
        rel.abs() < 0.01,
        "f = {} Hz vs {f1} Hz ({rel:+.2e})",
        1.0 / period
    );
}

fn energy_drift_after(h: &History, t0: f64) -> f64 {
    let e: Vec<f64> =
        h.t.iter()
            .zip(&h.energy)
            .filter(|(t, _)| **t >= t0)
            .map(|(_, e)| *e)
            .collect();
    let (lo, hi) = e
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
    (hi - lo) / e[0]
}

/// The free-flying beam (a 3-D variant of Simo & Vu-Quoc's flying spaghetti, see the
/// deck): after the pulse (t > 5 s) nothing acts on it, so its energy must stay constant.
/// With α = 0 the Lie-group trapezoidal rule does not conserve it exactly, but keeps it
/// bounded, with an error of second order in h; with α = −0.1 it only dissipates.
#[test]
fn flying_beam_energy_is_bounded_and_converges() {
    let base = deck("flying_beam.dat");
    // 10⁴ steps at h = 0.01 (the deck): bounded to well below the 1e-3 a resolved run
    // should reach (measured 5e-5).
    let h1 = run(&base, 10);
    let drift1 = energy_drift_after(&h1, 5.0);
    assert!(drift1 < 1e-3, "drift {drift1:e} over 10⁴ steps");
    // Halving the step over the same 25 s of free flight: second order means a drift
    // divided by about 4; we ask for at least 2.5.
    let mut m = base.clone();
    set_dynamic(&mut m, 0.01, 30.0, None);
    let d_h = energy_drift_after(&run(&m, 1), 5.0);
    set_dynamic(&mut m, 0.005, 30.0, None);
    let d_h2 = energy_drift_after(&run(&m, 2), 5.0);
    assert!(d_h2 < d_h / 2.5, "drift {d_h:e} at h, {d_h2:e} at h/2");
}

#[test]
fn flying_beam_energy_never_rises_with_numerical_damping() {
    let mut m = deck("flying_beam.dat");
    set_dynamic(&mut m, 0.01, 30.0, Some(-0.1));
    let h = run(&m, 1);
    let e0 = h.energy[h.t.iter().position(|t| *t >= 5.0).unwrap()];
    for w in h
        .energy
        .windows(2)
        .zip(&h.t[1..])
        .filter(|(_, t)| **t > 5.0)
    {
        let (e, _) = w;
        // Round-off of the energy sum of 11 nodes: far below 1e-6 relative.
        assert!(
            e[1] <= e[0] + 1e-6 * e0,
            "energy rose from {} to {}",
            e[0],
            e[1]
        );
    }
}

/// Order of accuracy on a smooth case: the torque-free rigid body of `free_body.dat`
/// (Euler's equations: nonlinear, rotation-dominated, no unresolved modes). The ratio of
/// the differences of successive runs, |x_h − x_{h/2}| / |x_{h/2} − x_{h/4}|, is 2^p for a
/// method of order p, with no reference solution needed; measured: 2.0000 for α = 0,
/// −0.1 and −1/3. (Flexible cases hit by a sudden load excite modes with ωh ≳ 1 whose phase
/// errors only converge once ωh√(ωt) ≪ 1; there the ratio approaches 4 only at small h.)
#[test]
fn hht_is_second_order_accurate() {
    let mut m = deck("free_body.dat");
    for alpha in [0.0, -0.1, -1.0 / 3.0] {
        let mut finals = Vec::new();
        for h in [0.02, 0.01, 0.005, 0.0025] {
            set_dynamic(&mut m, h, 4.0, Some(alpha));
            let hist = run(&m, 1);
            finals.push(hist.nodes.last().unwrap()[0].r);
        }
        for k in 0..2 {
            let p = ((finals[k] - finals[k + 1]).norm() / (finals[k + 1] - finals[k + 2]).norm())
                .log2();
            assert!(
                (1.8..=2.2).contains(&p),
                "alpha {alpha}: observed order {p}"
            );
        }
    }
}

fn rotate_model(model: &Model, q: &Matrix3<f64>) -> Model {
    let mut m = model.clone();
    for n in m.nodes.values_mut() {
        n.position = q * n.position;
    }
    for l in &mut m.loads {
        l.value = q * l.value;
    }
    if let Some(g) = &mut m.gravity {
        *g = q * *g;
    }
    for iv in &mut m.initial {
        iv.velocity = q * iv.velocity;
        iv.angular = q * iv.angular;
    }
    for e in m.elements.values_mut() {
        if let mecano::model::ElementKind::Beam { axis2, .. } = &mut e.kind {
            *axis2 = axis2.map(|a| q * a);
        }
    }
    m
}

/// Objectivity: the flying beam with every coordinate, load and axis turned by a rigid
/// rotation Q (|Φ| ≈ 2.5 rad) gives positions Q x(t) and nodal rotations Q R(t) Qᵀ (the
/// nodal frames start as the global axes in both runs): the strain
/// measures are invariant (Crisfield & Jelenić 1999), so the two runs differ by round-off
/// amplified by the Newton tolerance (1e-10 relative increments), far below 1e-8.
#[test]
fn rigidly_rotated_deck_gives_rotated_histories() {
    let mut m = deck("flying_beam.dat");
    set_dynamic(&mut m, 0.01, 3.0, None);
    let q = rotation::exp(&Vector3::new(1.2, -1.9, 0.9));
    let a = run(&m, 1);
    let b = run(&rotate_model(&m, &q), 1);
    assert_eq!(a.t.len(), b.t.len());
    let scale = 10.0; // the beam's length
    let mut worst: f64 = 0.0;
    for (sa, sb) in a.nodes.iter().zip(&b.nodes) {
        for (na, nb) in sa.iter().zip(sb) {
            worst = worst.max((q * na.x - nb.x).norm() / scale);
            worst = worst.max((q * na.r * q.transpose() - nb.r).norm());
        }
    }
    assert!(worst < 1e-8, "relative difference {worst:e}");
}

/// Many turns: steady spin about the axis of an axisymmetric bar is an exact solution;
/// the integrator reproduces `R(t) = exp(ω t ẽₓ)` through 20 turns (orientations are
/// matrices updated by exp of the increment: no 2π singularity), and the kinetic energy
/// exactly.
#[test]
fn spinning_beam_turns_twenty_times_without_singularity() {
    let model = deck("spinning_beam.dat");
    let h = run(&model, 1);
    let w = 10.0;
    for (t, nodes) in h.t.iter().zip(&h.nodes) {
        let exact = rotation::exp(&Vector3::new(w * t, 0.0, 0.0));
        for s in nodes {
            // 1257 steps of round-off (1e-16 each) on an orthonormalised matrix.
            assert!(
                (s.r - exact).norm() < 1e-10,
                "t = {t}: {}",
                (s.r - exact).norm()
            );
        }
    }
    let e0 = h.energy[0];
    assert!(h.energy.iter().all(|e| (e - e0).abs() < 1e-10 * e0));
    assert!((h.t.last().unwrap() - 4.0 * PI).abs() < 1e-9);
}

/// A free flexible bar tumbling end over end through 20 turns: its nodes' rotation
/// vectors pass through 2π, 4π, …; energy (α = 0) stays bounded and the angular momentum
/// about Z is conserved (no external moment).
#[test]
fn tumbling_beam_turns_twenty_times() {
    let model = deck("tumbling_beam.dat");
    let h = run(&model, 10);
    // Bounded energy (α = 0, h = 0.01, 6283 steps): measured 3.9e-4, from the unresolved
    // axial modes the sudden centrifugal load excites (ωh ≈ 2–3.5 for the highest).
    let drift = energy_drift_after(&h, 0.0);
    assert!(drift < 1e-3, "energy drift {drift:e}");
    // Angular momentum about Z of the discrete system: Σ xᵢ × (M v)ᵢ with the consistent
    // element mass ρA Lₑ/6 [2 1; 1 2] (ρA Lₑ = 1 here), plus the lumped rotary part
    // J_z Ω_z with J_z = (Lₑ/2) ρ I₃ per element end. The semi-discrete equations conserve
    // it exactly; the Lie-group trapezoidal rule, like Newmark, only to O(h²) (it conserves
    // quadratic invariants of linear systems, and x × v is not one): measured 1.9e-4 at
    // h = 0.01.
    let lz = |nodes: &[NodeState]| -> f64 {
        let mut l = 0.0;
        for e in 0..nodes.len() - 1 {
            let (a, b) = (&nodes[e], &nodes[e + 1]);
            let pa = (a.v * 2.0 + b.v) / 6.0;
            let pb = (a.v + b.v * 2.0) / 6.0;
            l += a.x.cross(&pa).z + b.x.cross(&pb).z;
            l += 0.5 * 0.05 * ((a.r * a.w).z + (b.r * b.w).z);
        }
        l
    };
    let l0 = lz(&h.nodes[0]);
    let worst = h
        .nodes
        .iter()
        .map(|n| ((lz(n) - l0) / l0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-3, "angular momentum drift {worst:e}");
    // The bar's chord really turned 20 times (unwrapped angle of node 11 − node 1).
    let mut angle = 0.0;
    for w in h.nodes.windows(2) {
        let (d0, d1) = (w[0][10].x - w[0][0].x, w[1][10].x - w[1][0].x);
        let mut da = d1.y.atan2(d1.x) - d0.y.atan2(d0.x);
        da -= (da / (2.0 * PI)).round() * 2.0 * PI;
        angle += da;
    }
    assert!(angle > 2.0 * PI * 20.0, "turned {} rad", angle);
    for nodes in &h.nodes {
        assert!(nodes.iter().all(|s| s.x.iter().all(|v| v.is_finite())));
    }
}

/// Fixed steps land on the load function's kinks without slivers: the seed's torque
/// (triangle with kinks at 0.01 and 0.02 s, both on the grid of h = 2⁻⁹ ms) at
/// h = 1.953125e-6 s. The time is a sum of steps, 2.4e-15 s short of 0.02 s after
/// 10,240 of them; that gap once counted as a step of its own (a duplicate sample, and a
/// 1/(βh²) of 1e29 in the iteration matrix that moved the accelerations by 1e-2 m/s²).
/// Every step must be h up to round-off (1e-6 relative).
#[test]
fn fixed_steps_land_on_load_kinks_without_slivers() {
    let mut model = deck("pendulum.dat");
    let h0 = 1.953125e-6;
    set_dynamic(&mut model, h0, 0.0205, None);
    let mut hist = History::new(1);
    let report = solver::run(&model, &mut hist).expect("run starts");
    assert!(report.failure.is_none());
    assert!(
        (report.stats.min_step / h0 - 1.0).abs() < 1e-6,
        "shortest step {:e} of h = {h0:e}",
        report.stats.min_step
    );
    assert_eq!(report.stats.steps, (0.0205 / h0).round() as u64);
    for w in hist.t.windows(2) {
        assert!((w[1] - w[0] - h0).abs() < 1e-6 * h0, "{} -> {}", w[0], w[1]);
    }
    // A kink just off the grid (1e-5 h after 0.01 s, at h = 1e-4 s) is not a step of
    // its own either (it is taken as reached); the shortest step is the one that lands
    // on the other kink, 1e-5 h before 0.02 s, and the next one comes back to the grid.
    let mut model = deck("pendulum.dat");
    let h0 = 1e-4;
    set_dynamic(&mut model, h0, 0.03, None);
    let f = model
        .functions
        .values_mut()
        .next()
        .expect("the torque's table");
    f.function = Function::Table(vec![
        (0.0, 0.0),
        (0.01 + 1e-5 * h0, 1.0),
        (0.02 - 1e-5 * h0, 0.0),
    ]);
    let report = solver::run(&model, &mut History::new(1)).expect("run starts");
    assert!(report.failure.is_none());
    assert!(
        report.stats.min_step > 0.99 * h0,
        "shortest step {:e} of h = {h0:e}",
        report.stats.min_step
    );
}
