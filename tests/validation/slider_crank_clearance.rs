//! Benchmark: the slider-crank with a revolute clearance joint between the connecting rod and
//! the slider (Flores & Ambrósio 2004), `decks/benchmarks/slider_crank_clearance.dat`, and
//! its ideal-joint twin `slider_crank_ideal.dat` (docs/benchmarks.md). The paper's numbers
//! are plots only, and no public digitisation was found: the references are the closed form
//! of the rigid mechanism (ideal twin) and bounds derived from it and from the contact law
//! (clearance deck).

use crate::common;

use common::deck;
use mecano::model::{Adaptive, Analysis, ElementKind, Model, NodeId};
use mecano::solver::{self, Observer, Snapshot};
use std::f64::consts::PI;

const R: f64 = 0.05;
const L: f64 = 0.12;
const C: f64 = 5e-4;
const M_SLIDER: f64 = 0.14;

fn omega() -> f64 {
    5000.0 * 2.0 * PI / 60.0
}

/// Per accepted state: t, crank angle (from the crank pin, node 4), slider x and ẍ (node 8),
/// and the clearance element's row when there is one.
#[derive(Default)]
struct Rec {
    idx: [usize; 2],
    elem: Option<usize>,
    t: Vec<f64>,
    theta: Vec<f64>,
    x: Vec<f64>,
    a: Vec<f64>,
    rows: Vec<Vec<f64>>,
}

impl Observer for Rec {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let i = snap.integ;
        let (pin, slider) = (&i.nodes[self.idx[0]], &i.nodes[self.idx[1]]);
        self.t.push(i.t);
        self.theta.push(pin.x.y.atan2(pin.x.x));
        self.x.push(slider.x.x);
        self.a.push(slider.a.x);
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

fn run(model: &Model) -> (Rec, solver::RunReport, Option<serde_json::Value>) {
    let node = |n| model.nodes.get_index_of(&NodeId(n)).expect("node");
    let elem = model
        .elements
        .values()
        .position(|e| matches!(e.kind, ElementKind::Clearance(_)));
    let mut rec = Rec {
        idx: [node(4), node(8)],
        elem,
        ..Rec::default()
    };
    let mut integ = solver::prepare(model).expect("prepare");
    let rep = solver::run_prepared(model, &mut integ, &mut rec).expect("run starts");
    assert!(rep.failure.is_none(), "{:?}", rep.failure);
    let summary = elem.and_then(|e| integ.sys.elements[e].summary());
    (rec, rep, summary)
}

/// The value of `y` where the crank angle crosses `target` (linear interpolation in the
/// angle between the two states around each crossing; the angle is unwrapped).
fn at_angle(rec: &Rec, y: &[f64], target: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut unwrapped = Vec::with_capacity(rec.theta.len());
    let mut turns = 0.0;
    for (k, th) in rec.theta.iter().enumerate() {
        if k > 0 && th - rec.theta[k - 1] < -PI {
            turns += 2.0 * PI;
        }
        unwrapped.push(th + turns);
    }
    for k in 1..unwrapped.len() {
        let (a0, a1) = (unwrapped[k - 1], unwrapped[k]);
        let mut goal = target;
        while goal < a0 {
            goal += 2.0 * PI;
        }
        if goal <= a1 && a1 > a0 && (k > 1 || goal > a0 || a0 == target) {
            let s = (goal - a0) / (a1 - a0);
            out.push(y[k - 1] + s * (y[k] - y[k - 1]));
        }
    }
    out
}

/// The ideal twin: the slider's acceleration at θ = 0 and π against the closed form of the
/// rigid mechanism at constant ω, `−rω²(1 + r/l)` and `+rω²(1 − r/l)` (the crank's hinge is
/// driven by θ = ωt: ω is exact). Tolerance: HHT is second-order, its error on a harmonic kω of the
/// motion is of order (kωh)² of that harmonic's amplitude; the slider's motion is the
/// harmonic ω (amplitude rω²) and, to within (r/l)³, 2ω (amplitude rω² r/l): relative
/// error ≤ (ωh)² (1 + 4 r/l)/(1 ∓ r/l).
#[test]
fn ideal_slider_acceleration_matches_the_closed_form() {
    let model = deck("benchmarks/slider_crank_ideal.dat");
    let (rec, rep, _) = run(&model);
    let w = omega();
    let h = 1e-5;
    let lam = R / L;
    let wh2 = (w * h).powi(2);
    for (theta, exact, tol) in [
        (
            0.0,
            -R * w * w * (1.0 + lam),
            wh2 * (1.0 + 4.0 * lam) / (1.0 + lam),
        ),
        (
            PI,
            R * w * w * (1.0 - lam),
            wh2 * (1.0 + 4.0 * lam) / (1.0 - lam),
        ),
    ] {
        let got = at_angle(&rec, &rec.a, theta);
        assert!(got.len() >= 2, "the crank turns twice: {got:?}");
        for a in &got {
            let err = (a - exact).abs() / exact.abs();
            println!(
                "ideal: theta {theta:.4}: slider acceleration {a:.3} m/s^2, closed form {exact:.3}, relative error {err:.2e} (tol {tol:.2e})"
            );
            assert!(err <= tol, "{a} vs {exact}");
        }
    }
    println!(
        "ideal: {} steps, {:.2} it/step, {:.3} s CPU",
        rep.stats.steps,
        rep.stats.newton_iterations as f64 / rep.stats.steps as f64,
        rep.stats.cpu_seconds
    );
}

/// The clearance deck, at its fixed base step with the impacts cut by the joint's events,
/// and with the adaptive step (ADAPTIVE TOLPOS 1e-8): in each run
/// - the journal's orbit stays within the clearance circle plus the largest penetration,
///   and that penetration is the one the largest contact force implies by the law:
///   between `(F_max/(K(1 + D)))^(1/n)` and `(F_max/K)^(1/n)`, D = 3(1 − e²)/4;
/// - the slider's acceleration never exceeds the largest contact force over the slider's
///   mass (the joint is the only force along the slide: `m_s ẍ = F n_x`, HHT's weighted
///   mean of such forces), and its peaks far exceed the ideal ones (the impacts: Flores &
///   Ambrósio's finding);
/// - the slider's position stays within `1.1 (c + δ_max)` of the ideal mechanism's: with the
///   crank's angle the same, the slider is the journal's point less the eccentricity e, and
///   the journal moves the rod's end by at most `|e_y| r/√(l² − r²)` along the slide, so
///   `|Δx| ≤ |e_x| + 0.46 |e_y| ≤ √(1 + 0.46²)|e|`.
///
/// The two runs differ in their impact sequence (an impacting mechanism is sensitive to
/// the step), not in these bounds; their peak forces agree to a few per cent (printed).
#[test]
fn clearance_orbit_and_slider_stay_within_the_derived_bounds() {
    let ideal = run(&deck("benchmarks/slider_crank_ideal.dat")).0;
    let fixed = deck("benchmarks/slider_crank_clearance.dat");
    let mut adaptive = fixed.clone();
    if let Analysis::Dynamic {
        adaptive: a,
        max_step,
        ..
    } = &mut adaptive.analysis
    {
        *a = Some(Adaptive {
            tol_position: 1e-8,
            tol_rotation: 1e-6,
            max_growth: 2.0,
            carry: Default::default(),
        });
        *max_step = 4e-5;
    }
    let k = 4.0 / (3.0 * 2.0 * (1.0 - 0.09) / 207e9) * (0.01f64 * 0.0095 / C).sqrt();
    let peak_ideal = ideal.a.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    for (name, model) in [("fixed", &fixed), ("adaptive", &adaptive)] {
        let (rec, rep, summary) = run(model);
        let summary = summary.expect("clearance summary");
        let f_max = summary["max_normal_force"].as_f64().unwrap();
        let pen_max = summary["max_penetration"].as_f64().unwrap();
        let ecc_max = rec.rows.iter().map(|r| r[1]).fold(0.0, f64::max);
        let a_max = rec.a.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        let dx_max = rec
            .t
            .iter()
            .zip(&rec.x)
            .filter_map(|(t, x)| {
                // The ideal slider interpolated linearly between its states (error
                // rω²h²/8 ≈ 2e-7 m at h = 1e-5 s).
                let k = ideal.t.partition_point(|s| s <= t);
                let (k0, k1) = (k.checked_sub(1)?, k.min(ideal.t.len() - 1));
                let s = if k1 > k0 {
                    (t - ideal.t[k0]) / (ideal.t[k1] - ideal.t[k0])
                } else {
                    0.0
                };
                Some((x - (ideal.x[k0] + s * (ideal.x[k1] - ideal.x[k0]))).abs())
            })
            .fold(0.0, f64::max);
        println!(
            "{name}: {} steps ({} refused, smallest {:.2e} s), {:.3} s CPU; {} impacts, F_max {f_max:.0} N, penetration {pen_max:.3e} m ((F/K)^(2/3) = {:.3e}), |e| max {ecc_max:.4e} m, slider |a| max {a_max:.0} m/s^2 (F/m {:.0}, ideal peak {peak_ideal:.0}), |x - x_ideal| max {dx_max:.3e} m (bound {:.3e})",
            rep.stats.steps,
            rep.stats.rejected_steps,
            rep.stats.min_step,
            rep.stats.cpu_seconds,
            summary["impacts"],
            (f_max / k).powf(1.0 / 1.5),
            f_max / M_SLIDER,
            1.1 * (C + pen_max)
        );
        assert!(ecc_max <= C + pen_max + 1e-12);
        // At the deepest point δ̇ = 0 and F = K δⁿ ≤ F_max; the hysteresis term raises a
        // force by at most the factor 1 + D (δ̇ ≤ δ̇⁻ while the journal goes in).
        let d = 0.75 * (1.0 - 0.9f64 * 0.9);
        assert!(pen_max <= (f_max / k).powf(1.0 / 1.5) * (1.0 + 1e-9));
        assert!(pen_max >= (f_max / (k * (1.0 + d))).powf(1.0 / 1.5));
        assert!(a_max <= f_max / M_SLIDER * (1.0 + 1e-6));
        assert!(a_max > 2.0 * peak_ideal, "impacts should raise the peaks");
        assert!(dx_max <= 1.1 * (C + pen_max) + 1e-6, "{dx_max}");
    }
}
