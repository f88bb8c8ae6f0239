//! Superelements in motion (issue 38): the project's own bar exported, reduced and run as a
//! `SUPERELEMENT` against the beam decks it came from — the flexible pendulum per mode
//! count, free flight, the spin-up beam, a rotated FE model, every integrator, the spin
//! warning and the deformed FE mesh (docs/superelements.md gives the figures these tests
//! print). The reduction itself, export and bad input: tests/superelement.rs.

mod common;

use mecano::deck::load_deck_with;
use mecano::elements::superelement::{fe, invariants::Body, reduce, spin};
use mecano::model::NodeId;
use mecano::output::History;
use std::path::Path;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
}

/// The exported bar (decks/superelement/beam/).
fn beam() -> fe::FeModel {
    fe::read(&common::root().join("decks/superelement/beam")).expect("the exported bar reads")
}

/// Runs `deck` with the overrides into memory; node `node`'s positions.
fn positions(deck: &str, set: &[(String, f64)], node: u32) -> (Vec<f64>, Vec<[f64; 3]>) {
    let model = load_deck_with(&common::deck_path(deck), set).expect("deck");
    let i = model.nodes.get_index_of(&NodeId(node)).expect("node");
    let mut h = History::new(1);
    let report = mecano::solver::run(&model, &mut h).expect("starts");
    assert!(report.failure.is_none(), "{deck}: {:?}", report.failure);
    let x = h
        .nodes
        .iter()
        .map(|s| [s[i].x.x, s[i].x.y, s[i].x.z])
        .collect();
    (h.t, x)
}

/// Largest distance between node `node`'s paths in the pendulum as beams and as a
/// superelement of `modes` modes, at step `h`.
fn pendulum_difference(modes: u32, h: f64) -> f64 {
    let hs = ("h".to_string(), h);
    let (t, full) = positions(
        "superelement/pendulum_beams.dat",
        std::slice::from_ref(&hs),
        2,
    );
    let (ts, se) = positions(
        "superelement/pendulum_se.dat",
        &[("modes".to_string(), f64::from(modes)), hs],
        2,
    );
    assert_eq!(ts.len(), t.len());
    full.iter().zip(&se).fold(0.0f64, |m, (a, b)| {
        m.max(((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt())
    })
}

/// The flexible pendulum (the bar hinged at one end, 1 kg at the tip, released horizontal
/// under gravity, 0.4 s): the tip's path as a superelement against the beams', per number
/// of fixed-interface modes. The difference falls with the modes (0 modes: the Guyan
/// reduction, the tip's constraint modes alone), then with the step: what remains with
/// every mode is the two discretisations' time error (the beams' own time error at
/// h = 1e-3 is 2.2e-5 m against h = 2.5e-4), not the reduction.
#[test]
fn flexible_pendulum_converges_with_modes() {
    let mut last = f64::INFINITY;
    let mut errs = Vec::new();
    for modes in [0, 2, 4, 8, 42] {
        let e = pendulum_difference(modes, 1e-3);
        eprintln!(
            "flexible pendulum, h = 1e-3, {modes:2} modes: largest tip distance to the beams over 0.4 s: {e:.3e} m"
        );
        errs.push(e);
        assert!(e <= last * 1.05, "{modes} modes: {e} above {last}");
        last = last.min(e);
    }
    assert!(errs[4] < errs[0] / 5.0 && errs[4] < 1e-5, "{errs:?}");
    let half = pendulum_difference(42, 5e-4);
    eprintln!("flexible pendulum, h = 5e-4, 42 modes: {half:.3e} m");
    assert!(half < errs[4] / 2.0, "{half} against {}", errs[4]);
}

/// Free flight without gravity or damping: kinetic + strain energy is constant; its drift
/// is the integrator's, falling with the step as h² (the α = 0 scheme is second order).
#[test]
fn free_flight_conserves_energy() {
    let drift = |h: f64| {
        let model = load_deck_with(
            &common::deck_path("superelement/free_flying_se.dat"),
            &[("h".to_string(), h)],
        )
        .expect("deck");
        let mut hist = History::new(1);
        let r = mecano::solver::run(&model, &mut hist).expect("starts");
        assert!(r.failure.is_none());
        let e0 = hist.energy[0];
        let d = hist
            .energy
            .iter()
            .fold(0.0f64, |m, e| m.max((e - e0).abs()))
            / e0;
        eprintln!("free flight, h = {h:e}: largest relative energy change {d:.3e}");
        d
    };
    let (d1, d2) = (drift(2e-3), drift(1e-3));
    assert!(d1 < 1e-4 && d2 < d1 / 3.0, "{d1} {d2}");
}

/// Kane's spin-up beam's tip deflection in the rotating frame (node 2's rotation), at
/// every recorded time.
fn spinup_deflection(deck: &str, set: &[(String, f64)]) -> Vec<f64> {
    let model = load_deck_with(&common::deck_path(deck), set).expect("deck");
    let (i2, i3) = (
        model.nodes.get_index_of(&NodeId(2)).expect("hub"),
        model.nodes.get_index_of(&NodeId(3)).expect("tip"),
    );
    let mut h = History::new(1);
    let report = mecano::solver::run(&model, &mut h).expect("starts");
    assert!(report.failure.is_none(), "{deck}: {:?}", report.failure);
    h.nodes
        .iter()
        .map(|s| (s[i2].r.transpose() * (s[i3].x - s[i2].x)).y)
        .collect()
}

/// Kane's spin-up beam (decks/benchmarks/spinup.dat) at low hub rates, as beams and as a
/// superelement of its exported matrices (8 modes): the floating frame keeps every
/// inertia coupling but, its body being linear, not the centrifugal stiffening of the
/// beams, whose share of the tip's deflection is `(ω_s/ω₁)²` (ω₁ = 3.80 rad/s, the first
/// bending frequency): the difference stays below it and grows as `ω_s²`.
#[test]
fn spin_up_at_low_rates_within_the_missing_stiffening() {
    let w1: f64 = 3.7977;
    let mut rel = Vec::new();
    for ws in [0.5, 1.0] {
        let set = [("ws".to_string(), ws), ("tend".to_string(), 16.0)];
        let beams = spinup_deflection("benchmarks/spinup.dat", &set);
        let se = spinup_deflection("superelement/spinup_se.dat", &set);
        assert_eq!(beams.len(), se.len());
        let peak = beams.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = beams
            .iter()
            .zip(&se)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        let r = diff / peak;
        eprintln!(
            "spin-up, ws = {ws}: tip deflection peak {peak:.4e} m, largest difference {diff:.3e} m ({r:.2e} of the peak; (ws/w1)^2 = {:.2e})",
            (ws / w1).powi(2)
        );
        assert!(r < (ws / w1).powi(2), "ws {ws}: {r}");
        rel.push(r);
    }
    let growth = rel[1] / rel[0];
    assert!(
        (2.5..6.0).contains(&growth),
        "growth {growth} for twice the rate"
    );
}

/// Objectivity of the whole chain: the free-flying bar's FE model and initial velocities
/// rotated by `Q` (nodes, `K` and `M` transformed dof block by dof block) give the
/// rotated trajectory of the frame node and the same energies, to round-off amplified by
/// the run (the step and Newton's tolerance are the same in both).
#[test]
fn a_rotated_fe_model_gives_the_rotated_motion() {
    use nalgebra::{DMatrix, Vector3};
    let q = mecano::rotation::exp(&Vector3::new(0.3, -0.8, 1.1));
    let fe0 = beam();
    let n = fe0.dofs.len();
    let mut t = DMatrix::zeros(n, n);
    for (r, &(p, c)) in fe0.dofs.iter().enumerate() {
        let base = 3 * (c as usize / 3);
        for k in 0..3 {
            let col = fe0.dof_of(p, (base + k) as u8).expect("six dofs");
            t[(r, col)] = q[(c as usize % 3, k)];
        }
    }
    let dir = common::TempDir::new("se_rotated");
    let fe_dir = dir.join("beam");
    std::fs::create_dir_all(&fe_dir).expect("dir");
    let k = &t * fe0.k.to_dense() * t.transpose();
    let m = &t * fe0.m.to_dense() * t.transpose();
    let sym = mecano::elements::superelement::mtx::SymMatrix::from_dense;
    std::fs::write(fe_dir.join("K.mtx"), sym(&k, 1e-15).to_text("rotated")).expect("K");
    std::fs::write(fe_dir.join("M.mtx"), sym(&m, 1e-15).to_text("rotated")).expect("M");
    let nodes: Vec<(u32, Vector3<f64>)> = fe0.nodes.iter().map(|(p, x)| (*p, q * x)).collect();
    std::fs::write(fe_dir.join("nodes.csv"), fe::nodes_text(&nodes)).expect("nodes");
    std::fs::write(fe_dir.join("dofs.csv"), fe::dofs_text(&fe0.dofs)).expect("dofs");
    let text = std::fs::read_to_string(common::deck_path("superelement/free_flying_se.dat"))
        .expect("deck");
    let (v, w) = (
        q * Vector3::new(0.5, 0.0, 0.0),
        q * Vector3::new(3.0, 0.0, 6.0),
    );
    let rotated = text.replace(
        "  1 V 0.5 0 0 W 3 0 6",
        &format!(
            "  1 V {:?} {:?} {:?} W {:?} {:?} {:?}",
            v.x, v.y, v.z, w.x, w.y, w.z
        ),
    );
    assert_ne!(rotated, text);
    std::fs::write(dir.join("rotated.dat"), rotated).expect("deck");
    let run = |path: &Path| {
        let model = mecano::deck::load_deck(path).expect("deck");
        let i = model.nodes.get_index_of(&NodeId(1)).expect("node 1");
        let mut h = History::new(1);
        let r = mecano::solver::run(&model, &mut h).expect("starts");
        assert!(r.failure.is_none());
        let x: Vec<Vector3<f64>> = h.nodes.iter().map(|s| s[i].x).collect();
        (x, h.energy)
    };
    let (x0, e0) = run(&common::deck_path("superelement/free_flying_se.dat"));
    let (x1, e1) = run(&dir.join("rotated.dat"));
    let dx = x0
        .iter()
        .zip(&x1)
        .fold(0.0f64, |m, (a, b)| m.max((q * a - b).norm()));
    let de = e0
        .iter()
        .zip(&e1)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs() / a.abs()));
    eprintln!(
        "rotated FE model: frame node off the rotated path by {dx:.2e} m, energies by {de:.2e}"
    );
    assert!(dx < 1e-8 && de < 1e-10, "{dx} {de}");
}

/// Every integrator advances the superelement unchanged (its coordinates are nodes): the
/// flexible pendulum (8 modes) under generalized-α, ESDIRK3 and ESDIRK5 against the
/// beams under the same scheme, within the HHT figure of
/// `flexible_pendulum_converges_with_modes` (3.4e-6 m at h = 1e-3).
#[test]
fn every_integrator_runs_the_superelement() {
    let dir = common::TempDir::new("se_schemes");
    let src = common::root().join("decks/superelement");
    std::fs::create_dir_all(dir.join("beam")).expect("dir");
    for f in fe::FILES {
        std::fs::copy(src.join("beam").join(f), dir.join("beam").join(f)).expect("copy");
    }
    for scheme in ["GENALPHA RHOINF 0.8", "ESDIRK3", "ESDIRK5"] {
        let mut tips = Vec::new();
        for deck in ["pendulum_beams.dat", "pendulum_se.dat"] {
            let text = std::fs::read_to_string(src.join(deck)).expect("deck");
            let text = text
                .replace("ALPHA 0 STEP", &format!("{scheme} STEP"))
                .replace("  modes 4\n", "  modes 8\n");
            let path = dir.join(deck);
            std::fs::write(&path, text).expect("write");
            let model = mecano::deck::load_deck(&path).expect("deck");
            let i = model.nodes.get_index_of(&NodeId(2)).expect("tip");
            let mut h = History::new(1);
            let r = mecano::solver::run(&model, &mut h).expect("starts");
            assert!(r.failure.is_none(), "{scheme} {deck}: {:?}", r.failure);
            tips.push(h.nodes.iter().map(|s| s[i].x).collect::<Vec<_>>());
        }
        assert_eq!(tips[0].len(), tips[1].len());
        let d = tips[0]
            .iter()
            .zip(&tips[1])
            .fold(0.0f64, |m, (a, b)| m.max((a - b).norm()));
        eprintln!("{scheme}: largest tip distance, superelement (8 modes) to beams: {d:.2e} m");
        assert!(d < 4e-6, "{scheme}: {d}");
    }
}

/// A turning superelement is watched against its lowest elastic frequency with its frame
/// held (`superelement::spin`): for the bar with its tip on the interface and every mode
/// kept, that is the clamped bar's first ω² (the FE model's own, to the reduction's 1e-8);
/// spun in its plane about its middle at (Ω/ω₁)² = 2.9 the run warns once and its strain
/// grows without bound (the missing centrifugal stiffening), at 0.029 it neither warns nor
/// deforms (a spin about the middle loads the bar axially only, and no axial mode is kept).
#[test]
fn a_superelement_spun_past_its_first_frequency_is_said() {
    let fe = beam();
    let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
    let n = fe.dofs.len();
    let node1: Vec<usize> = (0..6).map(|c| fe.dof_of(1, c).expect("node 1")).collect();
    let clamped: Vec<usize> = (0..n).filter(|r| !node1.contains(r)).collect();
    let w1_2 = reduce::lowest_eigenvalues(&k, &m, &clamped, 1).expect("clamped")[0];
    let red = reduce::reduce(&fe, &k, &m, &[1, 2], 42).expect("reduces");
    let body = Body::new(&fe, &m, &red, 1, &[2]).expect("mass");
    let got = spin::lowest_omega2(&body);
    assert!((got - w1_2).abs() < 1e-8 * w1_2, "{got} against {w1_2}");
    let w1 = w1_2.sqrt();
    eprintln!("exported bar: ω₁ = {w1:.4} rad/s with its frame held");
    let dir = common::TempDir::new("se_spin");
    let files = common::root().join("decks/superelement/beam");
    for (omega, warned) in [(0.17 * w1, false), (1.7 * w1, true)] {
        let deck = dir.join(format!("spin_{omega:.0}.dat"));
        std::fs::write(
            &deck,
            format!(
                "TITLE spin\nNODES\n  1 0 0 0\nELEMENTS\n  1 SUPERELEMENT FILES {} MODES 9 INTERFACE 1 1\n\
                 INITIAL\n  1 W 0 0 {omega} ABOUT 0.5 0 0\nANALYSIS DYNAMIC ALPHA 0 STEP 1e-5 END 0.05\nOUTPUT NODES 1\nEND\n",
                files.display()
            ),
        )
        .unwrap();
        let out = dir.join(format!("out_{omega:.0}"));
        let o = bin()
            .arg(&deck)
            .args(["-q", "--checkpoint", "0", "-o"])
            .arg(&out)
            .output()
            .expect("runs");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(
            stderr.matches("no centrifugal stiffening").count(),
            usize::from(warned),
            "Ω = {omega}: {stderr}"
        );
        let text = std::fs::read_to_string(out.join("energy.csv")).expect("energy.csv");
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = head.iter().position(|c| *c == "strain").expect("strain");
        let total = head.iter().position(|c| *c == "total").expect("total");
        let (mut strain, mut energy) = (0.0f64, 0.0f64);
        for l in lines {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            strain = strain.max(v[col].abs());
            energy = energy.max(v[total].abs());
        }
        eprintln!(
            "spun at {omega:.1} rad/s: largest strain energy {strain:.3e} J of {energy:.3e} J"
        );
        // Unstable: the strain takes a visible share of the energy; stable: round-off.
        assert_eq!(strain > 1e-6 * energy, warned, "Ω = {omega}: {strain} J");
    }
}

/// The deformed FE mesh for ParaView (`OUTPUT … VTK`): the pendulum as a superelement of
/// all 42 modes, its FE nodes recovered from the frame and the elastic coordinates at the
/// end (0.4 s). The interface tip's recovered place is the model's node 2 (the interface
/// constraint, solved to Newton's tolerance), and the bar's interior FE nodes 3–9 lie on
/// the beams deck's nodes 3–9 within the largest distance of the two decks' tip paths (the
/// same two discretisations; the tip, farthest from the hinge, moves most).
#[test]
fn the_deformed_fe_mesh_is_the_beams() {
    let set = [("modes".to_string(), 42.0), ("h".to_string(), 1e-3)];
    let mut model =
        load_deck_with(&common::deck_path("superelement/pendulum_se.dat"), &set).expect("deck");
    model.output.vtk = true;
    let mut h = History::new(1);
    let report = mecano::solver::run(&model, &mut h).expect("starts");
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let integ = mecano::solver::prepare(&model).expect("prepares");
    let last = h.nodes.last().expect("a state");
    let mesh = integ
        .sys
        .elements
        .iter()
        .find_map(|e| e.mesh(last))
        .expect("the superelement draws its mesh");
    // Points in the order of the FE nodes' first dofs.
    let fe = beam();
    let mut order: Vec<u32> = Vec::new();
    for &(p, _) in &fe.dofs {
        if !order.contains(&p) {
            order.push(p);
        }
    }
    assert_eq!(mesh.points.len(), order.len());
    assert!(
        mesh.lines.len() >= order.len() - 1,
        "{} lines",
        mesh.lines.len()
    );
    let point = |p: u32| mesh.points[order.iter().position(|&q| q == p).expect("FE node")];
    let node = |id: u32| last[model.nodes.get_index_of(&NodeId(id)).expect("node")].x;
    let tip = (point(2) - node(2)).norm();
    eprintln!("recovered interface tip to the model's node 2: {tip:.3e} m");
    assert!(tip < 1e-9, "{tip}");
    // The beams deck's generated nodes at the FE nodes' places (the export's mesh).
    let beams = load_deck_with(
        &common::deck_path("superelement/pendulum_beams.dat"),
        &set[1..],
    )
    .expect("deck");
    let mut hb = History::new(1);
    let rb = mecano::solver::run(&beams, &mut hb).expect("starts");
    assert!(rb.failure.is_none());
    let lb = hb.nodes.last().expect("a state");
    let bound = pendulum_difference(42, 1e-3);
    for p in 3..=9u32 {
        let at = beams
            .nodes
            .values()
            .position(|n| (n.position - fe.nodes[&p]).norm() < 1e-12)
            .expect("a beams node at the FE node's place");
        let b = lb[at].x;
        let d = (point(p) - b).norm();
        eprintln!("FE node {p}: {d:.3e} m from the beams' node (tip bound {bound:.3e})");
        assert!(d <= bound, "FE node {p}: {d} > {bound}");
    }
}
