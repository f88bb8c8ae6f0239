//! The solid plate pendulum (issue 38, "The plate against Exudyn"):
//! decks/superelement/plate_solid_pendulum.dat, the plate of the shell deck meshed in bricks
//! of three translational dofs per node (decks/superelement/plate_solid/, written by
//! plate_solid_mesh.py), hinged along an edge through an RBE2 over 22 FE nodes, its far corner
//! a second RBE2, released horizontal under gravity. The side by side with Exudyn is a peer
//! bench (benches/peers/plate_side_by_side.py), out of CI; this test checks the deck itself.

mod common;

use mecano::deck::load_deck_with;
use mecano::model::NodeId;
use mecano::output::History;
use nalgebra::Vector3;

/// The plate (plate_solid_mesh.py): side along y, thickness, density, Young's modulus,
/// Poisson's ratio; mass ρ a b h.
const LY: f64 = 0.3;
const TH: f64 = 0.005;
const RHO: f64 = 2700.0;
const E: f64 = 70e9;
const NU: f64 = 0.33;
const MASS: f64 = RHO * 0.5 * LY * TH;
/// Gravity, m/s².
const G: f64 = 9.81;
/// The corner patch's centroid (deck node 2), relative to the hinge axis (x through node 1).
const SENSOR: [f64; 2] = [0.475, 0.275];

struct Run {
    t: Vec<f64>,
    energy: Vec<f64>,
    sensor: Vec<Vector3<f64>>,
}

fn run(h: f64) -> Run {
    let model = load_deck_with(
        &common::deck_path("superelement/plate_solid_pendulum.dat"),
        &[("h".to_string(), h)],
    )
    .expect("deck");
    let i = model.nodes.get_index_of(&NodeId(2)).expect("node 2");
    let mut hist = History::new(1);
    let r = mecano::solver::run(&model, &mut hist).expect("starts");
    assert!(r.failure.is_none(), "{:?}", r.failure);
    Run {
        sensor: hist.positions(i),
        t: hist.t,
        energy: hist.energy,
    }
}

/// The rigid plate's angle below the horizontal, `I φ̈ = m g (b/2) cos φ`, `I = m (b²/3 +
/// h²/12)` about the edge's mid-surface line, by RK4 at a step far below the runs'.
fn rigid_angle(t_end: f64) -> impl Fn(f64) -> f64 {
    let k = G * (LY / 2.0) / (LY * LY / 3.0 + TH * TH / 12.0);
    let n = 20_000;
    let dt = t_end / n as f64;
    let f = |y: [f64; 2]| [y[1], k * y[0].cos()];
    let mut ys = vec![[0.0, 0.0]];
    for _ in 0..n {
        let y = *ys.last().expect("state");
        let a = f(y);
        let b = f([y[0] + dt / 2.0 * a[0], y[1] + dt / 2.0 * a[1]]);
        let c = f([y[0] + dt / 2.0 * b[0], y[1] + dt / 2.0 * b[1]]);
        let d = f([y[0] + dt * c[0], y[1] + dt * c[1]]);
        ys.push([
            y[0] + dt / 6.0 * (a[0] + 2.0 * b[0] + 2.0 * c[0] + d[0]),
            y[1] + dt / 6.0 * (a[1] + 2.0 * b[1] + 2.0 * c[1] + d[1]),
        ]);
    }
    move |t: f64| {
        let s = (t / dt).clamp(0.0, n as f64 - 1.0);
        let j = s.floor() as usize;
        ys[j][0] + (s - j as f64) * (ys[j + 1][0] - ys[j][0])
    }
}

/// Undamped under HHT α = 0, the solid plate's energy (kinetic + strain + gravity, 0 at the
/// start) stays constant to the scheme's error, which falls as h²: the largest change,
/// relative to m g b/2 sin φ(end), at h and h/2 falls by 4 ± 1. The corner patch's centroid
/// follows the rigid plate (RK4, here) to within twice the Kirchhoff cantilever's static tip
/// deflection under the plate's weight, 2 ρhg b⁴/(8D) (a load applied at once; the coarse
/// brick mesh is stiffer than Kirchhoff's plate, so this bounds it), plus the run's time
/// error (h and h/2); and it bends: the distance is above that time error.
#[test]
fn solid_plate_pendulum_conserves_energy_and_follows_the_rigid_plate() {
    let (h1, h2) = (2e-3, 1e-3);
    let (a, b) = (run(h1), run(h2));
    let t_end = *b.t.last().expect("steps");
    let phi = rigid_angle(t_end);
    let e_scale = MASS * G * LY / 2.0 * phi(t_end).sin();
    let drift = |r: &Run| r.energy.iter().fold(0.0f64, |m, e| m.max(e.abs())) / e_scale;
    let (d1, d2) = (drift(&a), drift(&b));
    eprintln!(
        "solid plate: largest relative energy change {d1:.3e} at h = {h1:e}, {d2:.3e} at h = {h2:e} (ratio {:.2})",
        d1 / d2
    );
    assert!(d2 < 1e-4 && (3.0..=5.0).contains(&(d1 / d2)), "{d1} {d2}");
    let d = E * TH.powi(3) / (12.0 * (1.0 - NU * NU));
    let w_static = RHO * TH * G * LY.powi(4) / (8.0 * d);
    let mut time_err = 0.0f64;
    let mut dist = 0.0f64;
    for (k, t) in b.t.iter().enumerate() {
        let f = phi(*t);
        let rigid = Vector3::new(SENSOR[0], SENSOR[1] * f.cos(), -SENSOR[1] * f.sin());
        dist = dist.max((b.sensor[k] - rigid).norm());
        if k % 2 == 0 {
            time_err = time_err.max((b.sensor[k] - a.sensor[k / 2]).norm() / 3.0);
        }
    }
    let bound = 2.0 * w_static + time_err;
    eprintln!(
        "solid plate: corner patch to the rigid plate {dist:.3e} m; bound 2 w_static + time error = {:.3e} + {time_err:.3e} m",
        2.0 * w_static
    );
    assert!(dist <= bound && dist > time_err, "{dist} against {bound}");
}
