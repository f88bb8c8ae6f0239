//! The CAME contact element on its verification decks (decks/contact_*.dat): bouncing mass
//! (restitution and contact duration against the Kelvin–Voigt closed form), oblique bounce,
//! sliding with friction, and the pendulum's floor.
//!
//! Initial velocities are set with `Integrator::set_velocity` between `solver::prepare` and
//! `solver::run_prepared` (the decks have no INITIAL section yet).

use mecano::model::{ElementKind, Model, NodeId};
use mecano::solver::{self, Observer, Snapshot};
use nalgebra::Vector3;
use std::path::Path;

fn load(name: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("decks")
        .join(name);
    mecano::deck::load_deck(&path).unwrap_or_else(|e| panic!("{name}: {e:?}"))
}

/// (t, position, velocity) of one node at every accepted state.
struct Track {
    node: usize,
    hist: Vec<(f64, Vector3<f64>, Vector3<f64>)>,
}

impl Observer for Track {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let s = &snap.integ.nodes[self.node];
        self.hist.push((snap.integ.t, s.x, s.v));
        Ok(())
    }
}

/// Runs `model` with node `node` (user number) launched at `v0`; returns its history and
/// the run's statistics.
fn run(model: &Model, node: u32, v0: Vector3<f64>) -> (Track, solver::Stats) {
    let idx = model.nodes.get_index_of(&NodeId(node)).expect("node");
    let mut integ = solver::prepare(model).expect("prepare");
    integ.set_velocity(idx, v0, Vector3::zeros());
    let mut tr = Track {
        node: idx,
        hist: Vec::new(),
    };
    let rep = solver::run_prepared(model, &mut integ, &mut tr).expect("run");
    assert!(rep.failure.is_none(), "{:?}", rep.failure);
    (tr, rep.stats)
}

fn set_came(model: &mut Model, f: impl Fn(&mut mecano::model::CameData)) {
    for el in model.elements.values_mut() {
        if let ElementKind::Came(d) = &mut el.kind {
            f(d);
        }
    }
}

/// The first contact in the history: (t_in, impact velocity, t_out, rebound velocity). The
/// contact instants interpolate the gap linearly between the states around them; the
/// velocities are those of the free flights just before and just after (constant without
/// gravity).
fn crossings(
    hist: &[(f64, Vector3<f64>, Vector3<f64>)],
    gap: impl Fn(&Vector3<f64>) -> f64,
) -> (f64, Vector3<f64>, f64, Vector3<f64>) {
    let mut t_in = None;
    for w in hist.windows(2) {
        let (g0, g1) = (gap(&w[0].1), gap(&w[1].1));
        let at = |s: f64| w[0].0 + s * (w[1].0 - w[0].0);
        if t_in.is_none() && g0 >= 0.0 && g1 < 0.0 {
            t_in = Some((at(g0 / (g0 - g1)), w[0].2));
        } else if let Some((ti, vi)) = t_in.filter(|_| g0 < 0.0 && g1 >= 0.0) {
            return (ti, vi, at(g0 / (g0 - g1)), w[1].2);
        }
    }
    panic!("no complete contact in the history");
}

#[test]
fn bouncing_mass_restitution_and_duration() {
    let (k, m, g): (f64, f64, f64) = (1e6, 1.0, 9.81);
    let wn = f64::sqrt(k / m);
    let mut worst = (0.0f64, 0.0f64);
    for zeta in [0.0, 0.1, 0.3] {
        for height in [0.01, 1.0] {
            let mut model = load("contact_bounce.dat");
            set_came(&mut model, |d| d.damping = 2.0 * zeta * (k * m).sqrt());
            let v0 = (2.0 * g * height).sqrt();
            let (tr, stats) = run(&model, 2, Vector3::new(0.0, -v0, 0.0));
            let (ti, vi, to, vo) = crossings(&tr.hist, |x| x.y);
            let e = -vo.y / vi.y;
            let e_exact = (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
            let dur = to - ti;
            let dur_exact = std::f64::consts::PI / (wn * (1.0 - zeta * zeta).sqrt());
            let (ee, ed) = (
                (e - e_exact).abs() / e_exact,
                (dur - dur_exact).abs() / dur_exact,
            );
            println!(
                "zeta {zeta}, H {height} m: v_in {:.5} e {e:.6} (exact {e_exact:.6}, err {:.2e}), duration {:.5} ms (exact {:.5}, err {:.2e}), {} steps, {} refused",
                -vi.y,
                ee,
                dur * 1e3,
                dur_exact * 1e3,
                ed,
                stats.steps,
                stats.rejected_steps
            );
            assert!(
                (-vi.y - v0).abs() < 2e-2 * v0,
                "free flight changed the speed"
            );
            assert!(ee < 0.01, "restitution error {ee}");
            assert!(ed < 0.02, "duration error {ed}");
            worst = (worst.0.max(ee), worst.1.max(ed));
        }
    }
    println!(
        "worst errors: restitution {:.2e}, duration {:.2e}",
        worst.0, worst.1
    );
}

#[test]
fn oblique_bounce_reflects_with_restitution_in_the_normal_direction() {
    let model = load("contact_oblique.dat");
    let th = 20f64.to_radians();
    let n = Vector3::new(-th.sin(), th.cos(), 0.0);
    let zeta: f64 = 0.1;
    let e_exact = (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
    let v0 = Vector3::new(0.0, -2.0, 0.0);
    let (tr, _) = run(&model, 2, v0);
    let (_, vi, _, vo) = crossings(&tr.hist, |x| n.dot(x));
    let (vin, vit) = (n.dot(&vi), vi - n * n.dot(&vi));
    let (von, vot) = (n.dot(&vo), vo - n * n.dot(&vo));
    println!(
        "normal: in {vin:.6} out {von:.6} (ratio {:.6}, exact {e_exact:.6}); tangential in {vit:?} out {vot:?}",
        -von / vin
    );
    assert!((-von / vin - e_exact).abs() < 0.01 * e_exact);
    assert!(
        (vot - vit).norm() < 1e-6 * vit.norm(),
        "frictionless: the tangential velocity is kept"
    );
    // The final velocity (free flight after the bounce) is the reflected one.
    let vf = tr.hist.last().unwrap().2;
    let expected = vit - n * (e_exact * vin);
    assert!(
        (vf - expected).norm() < 0.01 * v0.norm(),
        "{vf:?} vs {expected:?}"
    );
}

#[test]
fn sliding_with_friction_stops_at_v0_squared_over_2_mu_g() {
    let model = load("contact_sliding.dat");
    let (mu, g, v0): (f64, f64, f64) = (0.3, 9.81, 1.0);
    let (tr, stats) = run(&model, 2, Vector3::new(v0, 0.0, 0.0));
    let last = tr.hist.last().unwrap();
    let dist = last.1.x;
    let exact = v0 * v0 / (2.0 * mu * g);
    println!(
        "stopping distance {dist:.6} m (exact {exact:.6}, err {:.2e}); final speed {:.2e}; {} steps",
        (dist - exact).abs() / exact,
        last.2.norm(),
        stats.steps
    );
    assert!(last.2.norm() < 1e-3, "stopped");
    assert!((dist - exact).abs() < 0.01 * exact);
}
