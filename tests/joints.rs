//! Joint verification (issue 4): pendulums against independent Runge–Kutta solutions of
//! their Lagrange equations, constraint satisfaction, conditioning of the iteration
//! matrix as the step shrinks, energy of the spatial pendulum, redundant constraints.
//!
//! (The tangent checks of every joint type are unit tests in `src/elements/joints.rs`:
//! the finite-difference harness is crate-private.)

use mecano::deck::load_deck;
use mecano::model::{Analysis, Model, NodeId};
use mecano::solver::{self, Observer, RunReport, Snapshot};
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::path::Path;

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

fn deck(name: &str) -> Model {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("decks").join(name);
    load_deck(&p).unwrap_or_else(|e| panic!("{name}: {e:?}"))
}

fn set_steps(model: &mut Model, h: f64, end: f64) {
    if let Analysis::Dynamic { step, end: e, min_step, max_step, .. } = &mut model.analysis {
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
fn rk4_at<const N: usize>(f: impl Fn(&[f64; N]) -> [f64; N], y0: [f64; N], ts: &[f64], dt: f64) -> Vec<[f64; N]> {
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
    let sol = rk4_at(|y: &[f64; 2]| [y[1], -G / l * y[0].cos()], [0.0, 0.0], &ts, 1e-4);
    let mut err: f64 = 0.0;
    for (r, y) in recs.iter().zip(&sol) {
        let exact = Vector3::new(l * y[0].cos(), l * y[0].sin(), 0.0);
        err = err.max((r.x[n2] - exact).norm());
        assert!(r.violation < 1e-10, "violation {:e} at t = {}", r.violation, r.t);
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
        [w1, w2, (m22 * r1 - a * c * r2) / det, (m11 * r2 - a * c * r1) / det]
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
/// Tolerance: the measured error at h = 1e-3 s is reported below (and in the final
/// report); it is dominated by the time discretisation (O(h²): halving h divides it by
/// about 4), so 1e-3 rad sits well above it while any modelling error (a wrong mass,
/// inertia or constraint) would show as an error of order 1e-2 rad and more.
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
    println!("double pendulum (rigid, h = 1e-3): max angle errors {e1:.3e}, {e2:.3e} rad; max violation {viol:.2e}");
    assert!(viol < 1e-10, "violation {viol:e}");
    assert!(e1 < 1e-4 && e2 < 1e-4, "angle errors {e1:e}, {e2:e} rad");
}
