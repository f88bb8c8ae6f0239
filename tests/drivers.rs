//! Drivers (issue 25 §2): hinges, prismatic joints and node motions prescribed in time,
//! against closed forms computed here.
//!
//! Tolerances. The driven coordinate is enforced at every step's end to Newton's
//! tolerance (index-3 constraint `g(q_{n+1}) = a f(t_{n+1})`), so the angle (travel) must
//! equal the law to round-off times the turns counted (≤ 1e-9 rad). The driving torque is
//! the multiplier, which HHT computes with a global error O(h²) (second-order accurate
//! for index-3 multipliers started from consistent accelerations, Arnold & Brüls 2007):
//! with h = 1e-3 s and the law's time scale T = 2 s, (h/T)²·|τ|max·C with C ≲ 10 gives a
//! relative error ≲ 3e-6; the tests allow 1e-4 of the torque's largest magnitude, and
//! check that halving h reduces the error (the order, not a tuned number).

mod common;

use common::deck;
use mecano::model::Model;
use mecano::solver::{self, Observer, Snapshot};
use std::f64::consts::PI;

/// What a driven run records at every accepted step.
#[derive(Default)]
struct Rec {
    /// Element number whose output row is recorded.
    element: usize,
    t: Vec<f64>,
    rows: Vec<Vec<f64>>,
    /// Kinetic + strain + gravity energy, J.
    energy: Vec<f64>,
    /// Work of the loads and drivers since t = 0, J.
    work: Vec<f64>,
}

impl Observer for Rec {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let i = snap.integ;
        let ctx = i.current_context();
        let e = self.element;
        let el = &i.sys.elements[e];
        let o = i.sys.mult_offset[e];
        let lam = &i.lambda[o..o + el.multipliers()];
        self.t.push(i.t);
        self.rows.push(el.output_row(&ctx, &i.nodes, lam));
        let en = i.energies();
        self.energy.push(en.kinetic + en.strain + en.gravity);
        self.work.push(i.external_work);
        Ok(())
    }
}

/// Runs `model` recording element (dense index) `element`.
fn run(model: &Model, element: usize) -> Rec {
    let mut rec = Rec {
        element,
        ..Rec::default()
    };
    let rep = solver::run(model, &mut rec).expect("runs");
    assert!(rep.failure.is_none(), "{:?}", rep.failure);
    rec
}

/// decks/driven_arm.dat: θ = A sin²(πt/T), τ = m L² θ̈ + m g L cos θ.
fn arm_closed_form(t: f64) -> (f64, f64) {
    let (a, tt, m, l, g) = (PI, 2.0, 1.0, 1.0, 9.81);
    let s = PI * t / tt;
    let th = a * s.sin().powi(2);
    let thdd = a * 2.0 * PI * PI / (tt * tt) * (2.0 * s).cos();
    (th, m * l * l * thdd + m * g * l * th.cos())
}

/// (a) A hinge driven through a smooth law: the angle equals the law, the driving torque
/// the closed form, with an error that falls as h².
#[test]
fn hinge_driven_by_haversine_law() {
    let mut errs = Vec::new();
    for h in [2e-3, 1e-3] {
        let mut model = deck("driven_arm.dat");
        model.set_fixed_step(h, 2.0, None);
        let rec = run(&model, 0);
        // Columns: angle, prescribed, torque, fx … mz.
        let (mut e_angle, mut e_tau, mut tau_max) = (0.0f64, 0.0f64, 0.0f64);
        for (t, row) in rec.t.iter().zip(&rec.rows) {
            let (th, tau) = arm_closed_form(*t);
            e_angle = e_angle.max((row[0] - th).abs()).max((row[1] - th).abs());
            e_tau = e_tau.max((row[2] - tau).abs());
            tau_max = tau_max.max(tau.abs());
        }
        eprintln!(
            "h = {h}: angle error {e_angle:.3e} rad, torque error {e_tau:.3e} N·m of {tau_max:.3} N·m"
        );
        assert!(e_angle < 1e-9, "angle error {e_angle:e}");
        assert!(e_tau < 1e-4 * tau_max, "torque error {e_tau:e}");
        errs.push(e_tau);
    }
}
