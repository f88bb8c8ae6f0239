//! The flexible plate pendulum (issue 38, "A plate"): decks/superelement/plate_pendulum.dat,
//! an aluminium plate of a flat-shell FE model (decks/superelement/plate/, written by
//! plate_mesh.py) hinged along an edge through an RBE2, its far corner read by an RBE3,
//! released horizontal under gravity, and the same plate as a solid mesh
//! (docs/superelements.md gives the figures printed here).

mod common;

use mecano::deck::load_deck_with;
use mecano::model::NodeId;
use mecano::output::History;
use nalgebra::Vector3;

/// The plate (plate_mesh.py): sides along x and y, thickness, density, Young's modulus,
/// Poisson's ratio.
const LX: f64 = 0.5;
const LY: f64 = 0.3;
const TH: f64 = 0.005;
const RHO: f64 = 2700.0;
const E: f64 = 70e9;
const NU: f64 = 0.33;
/// Gravity, m/s².
const G: f64 = 9.81;
/// The corner patch's centroid (deck node 2), relative to the hinge axis (x through node 1).
const SENSOR_Y: f64 = 0.275;

struct Run {
    t: Vec<f64>,
    energy: Vec<f64>,
    sensor: Vec<Vector3<f64>>,
}

fn run(h: f64) -> Run {
    run_with(h, 6)
}

fn run_with(h: f64, modes: u32) -> Run {
    run_deck(
        "superelement/plate_pendulum.dat",
        &[
            ("h".to_string(), h),
            ("modes".to_string(), f64::from(modes)),
        ],
    )
}

/// Runs `deck` with the overrides; deck node 2's path (the corner patch's).
fn run_deck(deck: &str, set: &[(String, f64)]) -> Run {
    let model = load_deck_with(&common::deck_path(deck), set).expect("deck");
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

/// Undamped under HHT α = 0, the plate's energy (kinetic + strain + gravity, 0 at the start)
/// stays constant to the scheme's error, which falls as h² (its order): the largest change,
/// relative to the largest kinetic energy reached (m g b/2 sin φ), at h and h/2, falls by
/// 4 ± 1. The corner patch's mean motion (the RBE3 node) follows the rigid plate (RK4 of its
/// pendulum equation, here) to within the plate's bending under its weight, dynamically
/// amplified at most twice (a load applied at once: 2 q b⁴/(8D), the cantilever's static
/// tip deflection), plus each run's time error (Richardson, from h and h/2); and it does
/// bend: the distance is above that time error (what is measured is not the scheme's).
#[test]
fn plate_pendulum_conserves_energy_and_follows_the_rigid_plate() {
    let (h1, h2) = (2e-3, 1e-3);
    let (a, b) = (run(h1), run(h2));
    conserves_energy_and_follows_the_rigid_plate("plate pendulum", (&a, h1), (&b, h2));
}

/// Bad interfaces over many FE nodes: located errors (the token for what the deck alone
/// shows wrong, the card for what needs the mesh), exit 2, nothing written.
#[test]
fn bad_interfaces_are_refused_located() {
    let dir = common::TempDir::new("se_bad_rbe");
    let src = common::root().join("decks/superelement");
    let card = "RBE2 1000 SET 1 TO 11 RBE3 2000 SET 65 66 76 77";
    let cases: [(&str, &str, &str); 9] = [
        (
            "missing",
            "RBE2 1000 SET 1 TO 11 999 RBE3 2000 SET 65 66 76 77",
            "line 18:3: element 2: SUPERELEMENT: RBE2 1000: FE node 999 is not in nodes.csv",
        ),
        (
            "empty",
            "RBE2 1000 SET 1 TO 11 RBE3 2000 WITHIN 0.01",
            "RBE3 2000: the set is empty",
        ),
        (
            "collinear",
            "RBE2 1000 SET 1 TO 11 RBE3 2000 SET 56 TO 66",
            "RBE3 2000: its 11 FE nodes are collinear",
        ),
        (
            "overlap",
            "RBE2 1000 SET 1 TO 11 RBE3 2000 SET 10 11 21 22",
            "RBE3 2000: FE node 10 is also in the set of interface node 1000",
        ),
        (
            "taken",
            "RBE2 1000 SET 1 TO 11 RBE3 2000 SET 65 66 76 77",
            "RBE2 12: FE node 12 is a node of the mesh",
        ),
        (
            "not_interface",
            "RBE2 1000 SET 1 TO 11 RBE3 3000 SET 65 66 76 77",
            "d.dat:18:94",
        ),
        (
            "empty_set",
            "RBE2 1000 SET RBE3 2000 SET 65 66 76 77",
            "at least one FE node",
        ),
        (
            "weights_count",
            "RBE2 1000 SET 1 TO 11 RBE3 2000 SET 65 66 76 77 WEIGHTS 1 2 3",
            "4 weights",
        ),
        (
            "weights_rigid",
            "RBE2 1000 SET 1 TO 11 WEIGHTS 1 RBE3 2000 SET 65 66 76 77",
            "WEIGHTS only after an RBE3",
        ),
    ];
    for (name, clause, expect) in cases {
        let case = dir.join(name);
        std::fs::create_dir_all(case.join("plate")).expect("dir");
        for f in ["K.mtx", "M.mtx", "nodes.csv", "dofs.csv"] {
            std::fs::copy(src.join("plate").join(f), case.join("plate").join(f)).expect("copy");
        }
        let mut deck = std::fs::read_to_string(src.join("plate_pendulum.dat")).expect("deck");
        assert!(deck.contains(card));
        deck = deck.replacen(card, clause, 1);
        if name == "taken" {
            deck = deck
                .replace("INTERFACE 1000 1", "INTERFACE 12 1")
                .replace("RBE2 1000", "RBE2 12");
        }
        std::fs::write(case.join("d.dat"), deck).expect("write");
        let err = common::refused(&case, name, expect);
        // Build errors at the card, parse errors at their token.
        let located = err.contains("d.dat: line 18:3") || err.contains("d.dat:18:");
        assert!(located, "{name}: {err}");
    }
}

/// `WITHIN` and `WEIGHTS` read, print back and read again to the same model (the deck of
/// `decks/` round-trips with `SET … TO …` in tests/deck/deck_roundtrip.rs).
#[test]
fn within_and_weights_round_trip() {
    let path = common::deck_path("superelement/plate_pendulum.dat");
    let text = std::fs::read_to_string(&path).expect("deck");
    // The four corner nodes are within 0.036 m of their centroid, the next ones 0.056 away.
    let within = text.replace("RBE3 2000 SET 65 66 76 77", "RBE3 2000 WITHIN 0.036");
    let weighted = text.replace(
        "RBE3 2000 SET 65 66 76 77",
        "RBE3 2000 SET 65 66 76 77 WEIGHTS 1 1 1 1",
    );
    for t in [&within, &weighted] {
        let mut m = mecano::deck::parse_deck(t, "d.dat").expect("parses");
        let back = mecano::deck::write_deck(&m);
        let mut again = mecano::deck::parse_deck(&back, "d.dat").expect("reads back");
        mecano::deck::strip_spans(&mut m);
        mecano::deck::strip_spans(&mut again);
        assert_eq!(m, again, "{back}");
    }
}

/// Convergence in the number of fixed-interface modes, at one step (h = 1e-3, so the time
/// discretisation is shared): the corner patch's largest distance to its path with 24 modes
/// falls as modes are added — 0 (Guyan: the RBE3's constraint modes alone), 2, 6, 12 — and
/// with 12 is below a tenth of Guyan's.
#[test]
fn plate_pendulum_converges_with_modes() {
    let reference = run_with(1e-3, 24);
    let mut errs = Vec::new();
    for modes in [0, 2, 6, 12] {
        let r = run_with(1e-3, modes);
        let d = r
            .sensor
            .iter()
            .zip(&reference.sensor)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).norm()));
        eprintln!("plate pendulum, {modes:2} modes: corner patch to 24 modes {d:.3e} m");
        if let Some(last) = errs.last() {
            assert!(d < *last, "{modes} modes: {d} not below {last}");
        }
        errs.push(d);
    }
    assert!(errs[3] < errs[0] / 10.0, "{errs:?}");
}

/// The solid plate pendulum (decks/superelement/plate_solid_pendulum.dat, "The plate
/// against Exudyn"): the same plate meshed in bricks of three translational dofs per node
/// (decks/superelement/plate_solid/, written by plate_solid_mesh.py), hinged along an edge
/// through an RBE2 over 22 FE nodes, its far corner a second RBE2. The side by side with
/// Exudyn is a peer bench (benches/peers/plate_side_by_side.py), out of CI; this checks the
/// deck itself.
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
    let solid = |h: f64| {
        run_deck(
            "superelement/plate_solid_pendulum.dat",
            &[("h".to_string(), h)],
        )
    };
    let (a, b) = (solid(h1), solid(h2));
    conserves_energy_and_follows_the_rigid_plate("solid plate", (&a, h1), (&b, h2));
}

/// The checks both plate decks pass (their tests say why): runs at `h1` (`a`) and `h1/2`
/// (`b`); the energy's largest change falls by 4 ± 1, and the corner patch follows the
/// rigid plate within twice the static bending plus the time error, and bends.
fn conserves_energy_and_follows_the_rigid_plate(
    label: &str,
    (a, h1): (&Run, f64),
    (b, h2): (&Run, f64),
) {
    let mass = RHO * LX * LY * TH;
    let t_end = *b.t.last().expect("steps");
    let phi = rigid_angle(t_end);
    let e_scale = mass * G * LY / 2.0 * phi(t_end).sin();
    let drift = |r: &Run| r.energy.iter().fold(0.0f64, |m, e| m.max(e.abs())) / e_scale;
    let (d1, d2) = (drift(a), drift(b));
    eprintln!(
        "{label}: largest relative energy change {d1:.3e} at h = {h1:e}, {d2:.3e} at h = {h2:e} (ratio {:.2})",
        d1 / d2
    );
    assert!(d2 < 1e-4 && (3.0..=5.0).contains(&(d1 / d2)), "{d1} {d2}");
    // The sensor against the rigid plate.
    let d = E * TH.powi(3) / (12.0 * (1.0 - NU * NU));
    let w_static = RHO * TH * G * LY.powi(4) / (8.0 * d);
    let mut time_err = 0.0f64;
    let mut dist = 0.0f64;
    for (k, t) in b.t.iter().enumerate() {
        let f = phi(*t);
        let rigid = Vector3::new(0.475, SENSOR_Y * f.cos(), -SENSOR_Y * f.sin());
        dist = dist.max((b.sensor[k] - rigid).norm());
        if k % 2 == 0 {
            time_err = time_err.max((b.sensor[k] - a.sensor[k / 2]).norm() / 3.0);
        }
    }
    let bound = 2.0 * w_static + time_err;
    eprintln!(
        "{label}: corner patch to the rigid plate {dist:.3e} m; bound 2 w_static + time error = {:.3e} + {time_err:.3e} m",
        2.0 * w_static
    );
    assert!(dist <= bound && dist > time_err, "{dist} against {bound}");
}
