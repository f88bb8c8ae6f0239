//! Mesh refinement without rewriting a deck: `DIVIDE n` on a BEAM card and `--refine k`
//! on the command line (issue 17). The user's nodes keep their numbers (and so their output
//! files), generated nodes and elements are numbered beyond the user's, loads, masses,
//! joints and contacts stay where the user put them, and a refined deck is the same model
//! — and gives the same motion — as the hand-written finer deck.

use crate::common;

use mecano::deck::{load_deck, parse_deck, strip_spans, write_deck};
use mecano::model::{ElementId, ElementKind, Model, NodeId};
use mecano::output::History;
use mecano::scenes::{PendulumSettings, pendulum_deck};
use mecano::solver;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn deck_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("decks")
        .join(name)
}

fn pendulum() -> Model {
    load_deck(&deck_path("pendulum.dat")).expect("seed deck parses")
}

/// `--refine 2` on the seed deck (24 nodes, elements 1–25, 20 beams): 20 midpoint nodes
/// numbered 25…44, 20 elements numbered 26…45; every user node unchanged; beam 2 now
/// joins node 2 to its midpoint 25; loads, masses, joints, contact and outputs unchanged.
#[test]
fn refine_keeps_user_numbers_and_numbers_generated_entities_beyond_them() {
    let user = pendulum();
    let mut m = user.clone();
    m.refine(2).expect("refines");
    assert_eq!(m.nodes.len(), 44);
    assert_eq!(m.elements.len(), 45);
    assert_eq!(m.generated_counts(), (20, 20));
    for (id, n) in &user.nodes {
        assert_eq!(m.nodes[id].position, n.position, "{id} moved");
        assert_eq!(m.nodes[id].fixed, n.fixed);
    }
    let generated: Vec<u32> = m
        .nodes
        .keys()
        .filter(|id| !user.nodes.contains_key(*id))
        .map(|id| id.0)
        .collect();
    assert_eq!(generated, (25..=44).collect::<Vec<_>>());
    let generated_el: Vec<u32> = m
        .elements
        .keys()
        .filter(|id| !user.elements.contains_key(*id))
        .map(|id| id.0)
        .collect();
    assert_eq!(generated_el, (26..=45).collect::<Vec<_>>());
    // Each generated node is its beam's midpoint: x_a + (x_b − x_a)/2, exact here to one
    // rounding of the coordinates (≤ 1 ulp of 2 m).
    for (beam, d) in &m.divisions {
        let [a, b] = d.ends;
        let mid = (user.nodes[&a].position + user.nodes[&b].position) / 2.0;
        let x = m.nodes[&d.interior[0]].position;
        assert!(
            (x - mid).norm() <= 4.0 * f64::EPSILON,
            "{beam}: {x} vs {mid}"
        );
        assert_eq!(m.elements[beam].nodes, vec![a, d.interior[0]]);
        assert_eq!(m.elements[&d.elements[1]].nodes, vec![d.interior[0], b]);
    }
    assert_eq!(m.elements[&ElementId(2)].nodes, vec![NodeId(2), NodeId(25)]);
    // Everything but the beams is where the user put it.
    for (id, e) in &user.elements {
        if !matches!(e.kind, ElementKind::Beam { .. }) {
            assert_eq!(m.elements[id].nodes, e.nodes, "{id}");
            assert_eq!(m.elements[id].kind, e.kind, "{id}");
        }
    }
    assert_eq!(m.loads, user.loads);
    assert_eq!(m.output, user.output);
    assert_eq!(m.initial, user.initial);
}

/// The seed deck refined by 2 is the deck generated with 20 elements per bar
/// (`scenes::pendulum_deck(20, ..)`), up to the numbering: every node has a node at the same
/// position (to 4 ulp: the two decks compute the same points by different roundings), and
/// the elements, loads and analysis map onto each other through that correspondence.
/// Integrated to 0.03 s (through the torque pulse, 300 steps) the tips of the two models
/// agree to round-off. The bound: the models differ only in the order of their unknowns,
/// so the histories differ by the round-off of the solves, amplified by Newton's stopping
/// (increment tolerance 1e-10 × the reference length, ~2e-10 m per step, the polished
/// iterate far below it): 300 steps × 2e-10 m = 6e-8 m is an upper bound; a real mismatch
/// (a misplaced node, a load on the wrong node) moves the tips by millimetres in 0.03 s.
#[test]
fn refine_2_is_the_hand_written_20_element_deck() {
    let mut refined = pendulum();
    refined.refine(2).expect("refines");
    let settings = PendulumSettings::default();
    let fine = parse_deck(&pendulum_deck(20, &settings), "generated").expect("parses");
    assert_eq!(refined.nodes.len(), fine.nodes.len());
    assert_eq!(refined.elements.len(), fine.elements.len());
    // Nodes 1 (ground, fixed) and 2 (bar 1) coincide, and so do 12 and 13 (the joint):
    // position and fixity, then the first twin not yet taken, in deck order; the element
    // check below verifies that choice.
    let mut map: HashMap<NodeId, NodeId> = HashMap::new();
    for n in refined.nodes.values() {
        let twin = fine
            .nodes
            .values()
            .find(|f| {
                (f.position - n.position).norm() <= 4.0 * 2.0 * f64::EPSILON
                    && f.fixed == n.fixed
                    && !map.values().any(|v| *v == f.id)
            })
            .unwrap_or_else(|| panic!("no node of the 20-element deck at {}", n.position));
        map.insert(n.id, twin.id);
    }
    let mut images: Vec<NodeId> = map.values().copied().collect();
    images.sort();
    images.dedup();
    assert_eq!(
        images.len(),
        fine.nodes.len(),
        "the correspondence is one to one"
    );
    for e in refined.elements.values() {
        let nodes: Vec<NodeId> = e.nodes.iter().map(|n| map[n]).collect();
        assert!(
            fine.elements
                .values()
                .any(|f| f.nodes == nodes && f.kind == e.kind),
            "{} ({:?}) has no twin",
            e.id,
            e.kind.keyword()
        );
    }
    for (l, f) in refined.loads.iter().zip(&fine.loads) {
        assert_eq!(map[&l.node], f.node);
        assert_eq!(
            (l.moment, l.value, l.function),
            (f.moment, f.value, f.function)
        );
    }
    assert_eq!(refined.gravity, fine.gravity);
    assert_eq!(refined.analysis, fine.analysis);

    // The same motion: tips 12 and 23 of the refined deck, 22 and 43 of the 20-element one.
    let run = |m: &Model| {
        let mut m = m.clone();
        m.set_fixed_step(1e-4, 0.03, None);
        let mut h = History::new(100);
        let r = solver::run(&m, &mut h).expect("runs");
        assert!(r.failure.is_none());
        h
    };
    let (a, b) = (run(&refined), run(&fine));
    assert_eq!(a.t, b.t);
    let idx = |m: &Model, n: u32| m.nodes.get_index_of(&NodeId(n)).expect("node");
    let mut worst: f64 = 0.0;
    let mut moved: f64 = 0.0;
    for (na, nb) in [(12, 22), (23, 43)] {
        let (pa, pb) = (a.positions(idx(&refined, na)), b.positions(idx(&fine, nb)));
        for (x, y) in pa.iter().zip(&pb) {
            worst = worst.max((x - y).norm());
        }
        moved = moved.max((pa[pa.len() - 1] - pa[0]).norm());
    }
    println!("tips of --refine 2 vs 20 elements per bar: {worst:e} m (tips moved {moved:e} m)");
    assert!(moved > 1e-3, "the test must see motion: {moved}");
    assert!(worst <= 6e-8, "{worst:e} m");
}

/// DIVIDE on the cards and `--refine` compose: DIVIDE 2 on bar 1 with refine 2 is DIVIDE 4
/// on bar 1 and 2 on bar 2; the canonical writer writes DIVIDE (not the generated entities)
/// and reads back to the same model; every deck of `decks/` refined by 2 round-trips.
#[test]
fn divide_and_refine_compose_and_round_trip() {
    let text = std::fs::read_to_string(deck_path("pendulum.dat")).expect("reads");
    let divided = text.replace("BEAM 2 3  MAT 1 SEC 1", "BEAM 2 3  MAT 1 SEC 1 DIVIDE 2");
    assert_ne!(divided, text);
    let mut a = parse_deck(&divided, "divided").expect("parses");
    a.refine(2).expect("refines");
    let both = text
        .replace("BEAM 2 3  MAT 1 SEC 1", "BEAM 2 3  MAT 1 SEC 1 DIVIDE 4")
        .replace(
            "BEAM 13 14  MAT 1 SEC 1",
            "BEAM 13 14  MAT 1 SEC 1 DIVIDE 2",
        );
    let mut b = parse_deck(&both, "both").expect("parses");
    strip_spans(&mut a);
    strip_spans(&mut b);
    assert_eq!(a, b);
    assert_eq!(a.generated_counts(), (10 * 3 + 10, 10 * 3 + 10));
    let written = write_deck(&a);
    assert!(written.contains("DIVIDE 4") && !written.contains("\n  30 "));
    let mut c = parse_deck(&written, "written").expect("written deck parses");
    strip_spans(&mut c);
    assert_eq!(a, c);

    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("decks");
    for entry in std::fs::read_dir(dir).expect("decks/") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|x| x != "dat") {
            continue;
        }
        let mut m = load_deck(&path).expect("parses");
        m.refine(2).expect("refines");
        let mut back = parse_deck(&write_deck(&m), "written")
            .unwrap_or_else(|e| panic!("{}: {:?}", path.display(), miette::Report::new(e)));
        strip_spans(&mut m);
        strip_spans(&mut back);
        assert_eq!(m, back, "{}", path.display());
    }
}

/// The command line: `--check --refine 2` says what was generated; a run with `--refine 2`
/// writes the user's nodes under their own numbers (node_12.csv, node_23.csv: the same
/// points as the unrefined run at t = 0) and records the factor in summary.json; a
/// generated number cannot be referenced by the deck (loads stay on user nodes).
#[test]
fn command_line_refine_check_run_and_outputs() {
    let bin = env!("CARGO_BIN_EXE_mecano-rs");
    let out = Command::new(bin)
        .args(["--check", "--refine", "2"])
        .arg(deck_path("pendulum.dat"))
        .output()
        .expect("runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("nodes:       44"), "{text}");
    assert!(
        text.contains("generated:   20 nodes and 20 elements, dividing 20 beams"),
        "{text}"
    );

    let tmp = common::TempDir::new("refine");
    std::fs::create_dir_all(&tmp).expect("tmp");
    let src = std::fs::read_to_string(deck_path("pendulum.dat")).expect("reads");
    let short = src.replace("END 2.0", "END 0.002");
    assert_ne!(short, src);
    let deck = tmp.join("short.dat");
    std::fs::write(&deck, &short).expect("writes");
    let out_dir = tmp.join("out");
    let out = Command::new(bin)
        .args(["--quiet", "--refine", "2", "-o"])
        .arg(&out_dir)
        .arg(&deck)
        .output()
        .expect("runs");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let first_row = |f: &str| -> Vector3<f64> {
        let t = std::fs::read_to_string(out_dir.join(f)).expect(f);
        let row: Vec<f64> = t
            .lines()
            .nth(1)
            .expect("row")
            .split(',')
            .map(|x| x.parse().expect("num"))
            .collect();
        Vector3::new(row[1], row[2], row[3])
    };
    assert_eq!(first_row("node_12.csv"), Vector3::new(1.0, 0.0, 0.0));
    assert_eq!(
        first_row("node_23.csv"),
        Vector3::new(1.8660254037844386, 0.0, 0.5)
    );
    assert!(
        !out_dir.join("node_25.csv").exists(),
        "OUTPUT NODES lists user nodes only"
    );
    let summary = std::fs::read_to_string(out_dir.join("summary.json")).expect("summary");
    let v: serde_json::Value = serde_json::from_str(&summary).expect("json");
    assert_eq!(v["refine"], 2);
    assert_eq!(v["generated"]["nodes"], 20);
    assert_eq!(v["complete"], true);

    // A load on a number that only generation would create is an undefined node.
    let bad = src.replace("MOMENT 2  0 0 -1000", "MOMENT 25  0 0 -1000");
    assert_ne!(bad, src);
    std::fs::write(
        &deck,
        bad.replace("BEAM 2 3  MAT 1 SEC 1", "BEAM 2 3  MAT 1 SEC 1 DIVIDE 2"),
    )
    .expect("writes");
    let out = Command::new(bin)
        .arg("--check")
        .arg(&deck)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("undefined node 25"), "{err}");
    let _ = std::fs::remove_dir_all(&tmp);
}

/// `decks/pendulum_converged_beams.dat` is the seed deck with every beam divided into 8 (DIVIDE 8
/// on both bars' cards): the same model as `--refine 8` of `decks/pendulum.dat`, up to the
/// title, the step, the end time and the output sampling.
#[test]
fn the_converged_deck_is_the_seed_deck_refined_by_8() {
    let mut seed = pendulum();
    seed.refine(8).expect("refines");
    let mut conv = load_deck(&deck_path("pendulum_converged_beams.dat")).expect("parses");
    assert_eq!(conv.generated_counts(), (140, 140));
    assert!(seed.set_fixed_step(2e-5, 1.5, None));
    seed.title = conv.title.clone();
    seed.output.every = conv.output.every;
    strip_spans(&mut seed);
    strip_spans(&mut conv);
    assert_eq!(seed, conv);
}
