//! Joint verification (issue 4): pendulums against independent Runge–Kutta solutions of
//! their Lagrange equations, constraint satisfaction, conditioning of the iteration
//! matrix as the step shrinks, energy of the spatial pendulum, redundant constraints.
//!
//! (The tangent checks of every joint type are unit tests in `src/elements/joints.rs`:
//! the finite-difference harness is crate-private.) One module a group of cases, one test
//! binary: `cargo test --test joints planar::` runs one of them.

#[path = "../common/mod.rs"]
mod common;

mod conditioning;
mod planar;
mod rigid_sections;
mod spatial;

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
