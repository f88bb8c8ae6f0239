//! Controlled inputs written in the deck (issue 36 §6): a `CONTROL` card's law of sensors
//! against the `PID` card of the same controller, and against solutions computed here —
//! the PD-controlled rigid arm's ODE by a fine RK4, and a node force law of the node's
//! coordinate and velocity, a spring–damper in closed form.
//!
//! Tolerances. The law is evaluated at every Newton iterate with its exact derivatives, so
//! the schemes keep their order: the trapezoidal rule (HHT α = 0) is second order, checked
//! as the ratio of the errors at h and h/2 (order 2 ± 0.2, the asymptotic range: the next
//! term is O(h²) relative); ESDIRK5's error at h = 1e-3 s is O(h⁵) ≈ 1e-12 on this arm,
//! far below the 1e-8 rad the issue asks. The RK4 reference at h = 2e-5 s has an error
//! ~h⁴ = 1.6e-19 rad times the ODE's constant: negligible against both.

use crate::common;

use mecano::deck::parse_deck_with;
use mecano::model::Model;
use mecano::solver::{self, Observer, Snapshot};

/// Element `element` (dense index)'s output rows and node `node`'s x at every step.
#[derive(Default)]
struct Rec {
    element: usize,
    node: usize,
    t: Vec<f64>,
    rows: Vec<Vec<f64>>,
    x: Vec<f64>,
}

impl Observer for Rec {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let i = snap.integ;
        let e = self.element;
        let el = &i.sys.elements[e];
        let o = i.sys.mult_offset[e];
        let lam = &i.lambda[o..o + el.multipliers()];
        self.t.push(i.t);
        self.rows
            .push(el.output_row(&i.current_context(), &i.nodes, lam));
        self.x.push(i.nodes[self.node].x.x);
        Ok(())
    }
}

fn run(model: &Model, element: usize, node: usize) -> Rec {
    let mut rec = Rec {
        element,
        node,
        ..Rec::default()
    };
    let rep = solver::run(model, &mut rec).expect("runs");
    assert!(rep.failure.is_none(), "{:?}", rep.failure);
    rec
}

fn deck(name: &str, scheme: &str, h: f64) -> Model {
    let text = std::fs::read_to_string(common::deck_path(name))
        .expect("deck")
        .replace("ALPHA 0", scheme);
    parse_deck_with(&text, name, &[("H".into(), h)]).expect("parses")
}

/// decks/pd_arm.dat's parameters: θ̈ = −g cos θ + kp(θr − θ) + kd(θ̇r − θ̇), θr = A sin Wt.
const KP: f64 = 50.0;
const KD: f64 = 10.0;
const A: f64 = 0.5;
const W: f64 = 2.0;
const G: f64 = 9.81;

/// θ(1 s) of the PD arm by RK4 at h = 2e-5 s.
fn rk4_arm() -> f64 {
    let f = |t: f64, y: [f64; 2]| {
        let (r, rd) = (A * (W * t).sin(), A * W * (W * t).cos());
        [y[1], -G * y[0].cos() + KP * (r - y[0]) + KD * (rd - y[1])]
    };
    let (h, n) = (2e-5, 50_000);
    let mut y = [0.0, 0.0];
    for k in 0..n {
        let t = k as f64 * h;
        let add = |y: [f64; 2], k: [f64; 2], s: f64| [y[0] + s * k[0], y[1] + s * k[1]];
        let k1 = f(t, y);
        let k2 = f(t + h / 2.0, add(y, k1, h / 2.0));
        let k3 = f(t + h / 2.0, add(y, k2, h / 2.0));
        let k4 = f(t + h, add(y, k3, h));
        for i in 0..2 {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    y[0]
}

/// The PID card and the same law written as a CONTROL law of sensors give the same
/// history (the same function of the same numbers: to round-off; measured identical).
#[test]
fn law_of_sensors_is_the_pid_card() {
    let pid = run(&deck("pd_arm.dat", "ALPHA 0", 1e-3), 0, 1);
    let law = run(&deck("pd_arm_law.dat", "ALPHA 0", 1e-3), 0, 1);
    assert_eq!(pid.t.len(), law.t.len());
    let worst = pid
        .rows
        .iter()
        .zip(&law.rows)
        .map(|(a, b)| (a[0] - b[0]).abs())
        .fold(0.0, f64::max);
    eprintln!("PID card vs CONTROL law: angles differ by at most {worst:e} rad");
    assert!(worst <= 1e-12, "angle histories differ by {worst:e} rad");
    // The torques too (element 3, dense 2): the law's value is the PID's.
    let tp = run(&deck("pd_arm.dat", "ALPHA 0", 1e-3), 2, 1);
    let tl = run(&deck("pd_arm_law.dat", "ALPHA 0", 1e-3), 2, 1);
    // PID columns: target, error, torque, s1, s2; CONTROL: torque, s1, s2.
    let worst = tp
        .rows
        .iter()
        .zip(&tl.rows)
        .map(|(a, b)| (a[2] - b[0]).abs())
        .fold(0.0, f64::max);
    eprintln!("PID card vs CONTROL law: torques differ by at most {worst:e} N m");
    assert!(worst <= 1e-10, "torques differ by {worst:e} N m");
}

/// The deck's law against the ODE: ESDIRK5 to 1e-8 rad, HHT α = 0 of order 2.
#[test]
fn law_of_sensors_against_the_arm_ode() {
    let theta = rk4_arm();
    let end = |r: &Rec| r.rows.last().expect("rows")[0];
    let e5 = (end(&run(&deck("pd_arm_law.dat", "ESDIRK5", 1e-3), 0, 1)) - theta).abs();
    assert!(e5 < 1e-8, "ESDIRK5: {e5:e} rad");
    let e1 = (end(&run(&deck("pd_arm_law.dat", "ALPHA 0", 2e-3), 0, 1)) - theta).abs();
    let e2 = (end(&run(&deck("pd_arm_law.dat", "ALPHA 0", 1e-3), 0, 1)) - theta).abs();
    let order = (e1 / e2).log2();
    eprintln!("PD arm law: ESDIRK5 {e5:e} rad; HHT {e1:e} -> {e2:e} rad, order {order:.3}");
    assert!((1.8..2.2).contains(&order), "{e1:e} {e2:e}: order {order}");
}

/// A force on a node whose law reads the node's coordinate and velocity: a spring–damper
/// `m ẍ = −k (x − 1) − c ẋ` from x = 1 at v0, in closed form
/// `x − 1 = v0/ω_d e^{−ζω t} sin ω_d t`. Order 2 of the trapezoidal rule: the exact
/// velocity derivative (`∂u/∂vx = −c`) is in the iteration matrix.
#[test]
fn node_force_law_of_coordinate_and_velocity_is_a_spring_damper() {
    let (m, k, c, v0) = (2.0_f64, 200.0_f64, 4.0_f64, 0.3_f64);
    let text = |h: f64| {
        format!(
            "NODES\n 2 1 0 0 FIX Y Z ROT\nELEMENTS\n 1 MASS 2 M {m}\n \
             2 CONTROL FORCE 2 X LAW (-{k}*(x(2)-1)-{c}*vx(2))\n\
             INITIAL\n 2 V {v0} 0 0\nANALYSIS DYNAMIC ALPHA 0 STEP {h} END 1\n"
        )
    };
    let w = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let exact = |t: f64| 1.0 + v0 / wd * (-zeta * w * t).exp() * (wd * t).sin();
    let mut errors = Vec::new();
    for h in [2e-3, 1e-3] {
        let model = mecano::deck::parse_deck(&text(h), "damper.dat").expect("parses");
        let r = run(&model, 1, 0);
        let err =
            r.t.iter()
                .zip(&r.x)
                .map(|(t, x)| (x - exact(*t)).abs())
                .fold(0.0, f64::max);
        // The trapezoidal rule's phase error ω³h²t/12 times the amplitude v0/ω_d.
        let bound = v0 / wd * w.powi(3) * h * h / 12.0;
        assert!(err <= bound, "h = {h}: {err:e} > {bound:e}");
        errors.push(err);
    }
    let order = (errors[0] / errors[1]).log2();
    eprintln!("spring-damper law: {errors:?} m, order {order:.3}");
    assert!((1.8..2.2).contains(&order), "{errors:?}: order {order}");
}
