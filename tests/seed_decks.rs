//! Every deck derived from a seed case is that case's model but for the differences it names
//! (issue 27 §1): `decks/pendulum_converged.dat` ran the clipped contact law for months while
//! its header said "only the mesh and the step differ" from `pendulum_flexible1.dat`.
//!
//! The decks are compared as parsed models, not as text: each model is brought to a canonical
//! form that does not depend on the numbering or on how the bars are meshed, and the forms are
//! compared with `==` (all of `Model`'s fields but the title, the source spans and the
//! `PARAMETERS` table, whose values are already in the fields that use them). A named
//! difference ([`Diff`]) blanks the corresponding part of both forms before the comparison;
//! everything else must be equal, bit for bit.
//!
//! Canonical form: the *key nodes* are those a bar of beams does not own — nodes of a
//! non-beam element, loaded, fixed, given an initial velocity, or the ends of a bar; they
//! are labelled by their rank in deck order. A *bar* is a maximal chain of beams between two
//! key nodes: its end labels, its material and section (by value), axis 2 and arc, and (unless
//! the mesh is a named difference) its number of elements and their orders. Every node of a
//! straight bar, generated or not, must lie on the segment between its ends (to 1e-12 of the
//! bar's length: the generators place nodes by linear interpolation of the ends, so the
//! rounding is a few ulps of 1 m), whatever the mesh: a mesh that bends a bar is caught.

mod common;

use common::{deck, deck_path};
use mecano::deck::{load_deck, parse_deck, strip_spans};
use mecano::model::{
    Analysis, Element, ElementId, ElementKind, Fixity, Function, Material, MaterialId, Model,
    NodeId, Scheme, Section, SectionId, Selection,
};
use mecano::scenes::{PendulumSettings, pendulum_deck, pendulum_order_deck};
use nalgebra::Vector3;
use std::collections::HashMap;

/// A difference a derived deck names in its header.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Diff {
    /// The bars' meshes (number of beams, their orders, generated nodes, `DIVIDE`).
    Mesh,
    /// The time step (and the smallest and largest steps derived from it).
    Step,
    /// Adaptive steps (their tolerances and their measure).
    Adaptive,
    /// The end time.
    End,
    /// The time integrator (HHT, generalized-α, ESDIRK3) and its parameter.
    Integrator,
    /// The output request.
    Output,
    /// The time function of the `k`-th load (deck order).
    LoadFunction(usize),
}

/// A bar: a chain of beams between two key nodes.
#[derive(Debug, Clone, PartialEq)]
struct Bar {
    ends: [usize; 2],
    material: Material,
    section: Section,
    axis2: Option<Vector3<f64>>,
    arc: Option<Vector3<f64>>,
    /// `(elements, order of each)`; blanked when the mesh is a named difference.
    mesh: Option<(usize, Vec<u32>)>,
}

/// A node or element of an output request: a key node's label, a non-beam element's rank, a
/// bar's rank, or (not canonical) a generated number.
#[derive(Debug, Clone, PartialEq)]
enum Ref {
    Key(usize),
    Other(usize),
    Bar(usize),
    Raw(u64),
}

/// The OUTPUT card: nodes, elements, every, directory, VTK.
type OutputCanon = (Selection<Ref>, Selection<Ref>, u32, Option<String>, bool);

#[derive(Debug, Clone, PartialEq)]
struct Canon {
    key_nodes: Vec<(Vector3<f64>, Fixity)>,
    bars: Vec<Bar>,
    others: Vec<(ElementKind, Vec<usize>)>,
    loads: Vec<(usize, bool, Vector3<f64>, Option<Function>)>,
    gravity: Option<Vector3<f64>>,
    initial: Vec<(usize, Vector3<f64>, Vector3<f64>)>,
    analysis: Analysis,
    output: Option<OutputCanon>,
}

fn is_beam(e: &Element) -> bool {
    matches!(e.kind, ElementKind::Beam { .. })
}

/// The canonical form of `m` with the differences `diffs` blanked.
fn canon(m: &Model, diffs: &[Diff]) -> Canon {
    let mut m = m.clone();
    strip_spans(&mut m);
    let m = &m;
    let has = |d: Diff| diffs.contains(&d);
    // Beam ends and how many beams meet at each node.
    // (The interior nodes of beams of order > 1 are in no beam's ends.)
    let mut degree: HashMap<NodeId, usize> = HashMap::new();
    let mut interior: Vec<NodeId> = Vec::new();
    for e in m.elements.values().filter(|e| is_beam(e)) {
        for n in [e.nodes[0], e.nodes[e.nodes.len() - 1]] {
            *degree.entry(n).or_default() += 1;
        }
        interior.extend(&e.nodes[1..e.nodes.len() - 1]);
    }
    let key = |n: &NodeId| -> bool {
        let node = &m.nodes[n];
        (degree.get(n).is_none_or(|&d| d != 2) && !interior.contains(n))
            || node.fixed.iter().any(|&f| f)
            || m.elements
                .values()
                .any(|e| !is_beam(e) && e.nodes.contains(n))
            || m.loads.iter().any(|l| l.node == *n)
            || m.initial.iter().any(|v| v.node == *n)
    };
    let keys: Vec<NodeId> = m.nodes.keys().filter(|n| key(n)).copied().collect();
    let label: HashMap<NodeId, usize> = keys.iter().enumerate().map(|(i, n)| (*n, i)).collect();

    // Bars: from each key node, follow the beams that leave it until the next key node.
    let mut used: Vec<ElementId> = Vec::new();
    let mut bar_of: HashMap<ElementId, usize> = HashMap::new();
    let mut bars = Vec::new();
    for first in m.elements.values().filter(|e| is_beam(e)) {
        if used.contains(&first.id) {
            continue;
        }
        let (a, b) = (first.nodes[0], first.nodes[first.nodes.len() - 1]);
        assert!(
            label.contains_key(&a),
            "{}: beam {} does not start a bar at a key node (beams of a bar must be written from one end to the other)",
            m.title,
            first.id
        );
        let mut chain = vec![first];
        let mut at = b;
        while !label.contains_key(&at) {
            let next = m
                .elements
                .values()
                .find(|e| is_beam(e) && e.nodes[0] == at && !used.contains(&e.id))
                .unwrap_or_else(|| panic!("{}: the bar stops at node {at}", m.title));
            chain.push(next);
            at = next.nodes[next.nodes.len() - 1];
        }
        let ElementKind::Beam {
            material,
            section,
            axis2,
            arc,
            ..
        } = &first.kind
        else {
            unreachable!()
        };
        let mut orders = Vec::new();
        for e in &chain {
            let ElementKind::Beam {
                material: mat,
                section: sec,
                axis2: ax,
                arc: ar,
                order,
            } = &e.kind
            else {
                unreachable!()
            };
            assert_eq!(
                (mat.map(|x| &m.materials[&x]), &m.sections[sec], ax, ar),
                (
                    material.map(|x| &m.materials[&x]),
                    &m.sections[section],
                    axis2,
                    arc
                ),
                "{}: beam {} differs from the rest of its bar",
                m.title,
                e.id
            );
            orders.push(*order);
            used.push(e.id);
            bar_of.insert(e.id, bars.len());
        }
        // Straight bars: every node on the segment between the ends.
        if arc.is_none() {
            let (pa, pb) = (m.nodes[&a].position, m.nodes[&at].position);
            let l = (pb - pa).norm();
            for e in &chain {
                for n in &e.nodes {
                    let p = m.nodes[n].position - pa;
                    let s = p.dot(&(pb - pa)) / (l * l);
                    let off = (p - (pb - pa) * s).norm();
                    assert!(
                        off <= 1e-12 * l && (-1e-12..=1.0 + 1e-12).contains(&s),
                        "{}: node {n} of the bar {a}-{at} is off its axis by {off:e} m (s = {s})",
                        m.title
                    );
                }
            }
        }
        let mut material = m.materials[&material.expect("the seed decks name materials")].clone();
        let mut section = m.sections[section].clone();
        (material.id, section.id) = (MaterialId(0), SectionId(0));
        bars.push(Bar {
            ends: [label[&a], label[&at]],
            material,
            section,
            axis2: *axis2,
            arc: *arc,
            mesh: (!has(Diff::Mesh)).then_some((chain.len(), orders)),
        });
    }

    let others: Vec<&Element> = m.elements.values().filter(|e| !is_beam(e)).collect();
    let node_ref = |n: &NodeId| {
        label
            .get(n)
            .map_or(Ref::Raw(u64::from(n.0)), |&k| Ref::Key(k))
    };
    let element_ref = |e: &ElementId| {
        if let Some(k) = others.iter().position(|o| o.id == *e) {
            Ref::Other(k)
        } else if let Some(&b) = bar_of.get(e) {
            Ref::Bar(b)
        } else {
            Ref::Raw(u64::from(e.0))
        }
    };
    fn map<T, U>(s: &Selection<T>, f: impl Fn(&T) -> U) -> Selection<U> {
        match s {
            Selection::All => Selection::All,
            Selection::None => Selection::None,
            Selection::Default => Selection::Default,
            Selection::List(v) => Selection::List(v.iter().map(f).collect()),
        }
    }

    let mut analysis = m.analysis.clone();
    if let Analysis::Dynamic {
        step,
        end,
        min_step,
        max_step,
        scheme,
        adaptive,
        ..
    } = &mut analysis
    {
        if has(Diff::Adaptive) {
            *adaptive = None;
        }
        if has(Diff::Step) {
            (*step, *min_step, *max_step) = (0.0, 0.0, 0.0);
        }
        if has(Diff::End) {
            *end = 0.0;
        }
        if has(Diff::Integrator) {
            *scheme = Scheme::Hht { alpha: 0.0 };
        }
    }
    let o = &m.output;
    Canon {
        key_nodes: keys
            .iter()
            .map(|n| (m.nodes[n].position, m.nodes[n].fixed))
            .collect(),
        bars,
        others: others
            .iter()
            .map(|e| (e.kind.clone(), e.nodes.iter().map(|n| label[n]).collect()))
            .collect(),
        loads: m
            .loads
            .iter()
            .enumerate()
            .map(|(k, l)| {
                let f = l.function.map(|f| m.functions[&f].function.clone());
                let f = if has(Diff::LoadFunction(k)) { None } else { f };
                (label[&l.node], l.moment, l.value, f)
            })
            .collect(),
        gravity: m.gravity,
        initial: m
            .initial
            .iter()
            .map(|v| (label[&v.node], v.velocity, v.angular))
            .collect(),
        analysis,
        output: (!has(Diff::Output)).then(|| {
            (
                map(&o.nodes, node_ref),
                map(&o.elements, element_ref),
                o.every,
                o.dir.clone(),
                o.vtk,
            )
        }),
    }
}

/// Panics with the first field that differs.
fn assert_same_case(what: &str, derived: &Model, case: &str, diffs: &[Diff]) {
    let seed = canon(&deck(case), diffs);
    let ours = canon(derived, diffs);
    macro_rules! field {
        ($f:ident) => {
            assert_eq!(
                ours.$f,
                seed.$f,
                "{what} is not {case} but for {diffs:?}: `{}` differs",
                stringify!($f)
            );
        };
    }
    field!(key_nodes);
    field!(bars);
    field!(others);
    field!(loads);
    field!(gravity);
    field!(initial);
    field!(analysis);
    field!(output);
}

use Diff::*;

/// The decks of `decks/` derived from a seed case, the case, and the differences their
/// headers name.
const DERIVED: &[(&str, &str, &[Diff])] = &[
    ("pendulum.dat", "pendulum_flexible1.dat", &[]),
    (
        "pendulum_converged.dat",
        "pendulum_flexible1.dat",
        &[Mesh, Step, End, Output, Integrator],
    ),
    (
        "pendulum_adaptive.dat",
        "pendulum_flexible1.dat",
        &[Mesh, Step, Adaptive, End, Output, Integrator],
    ),
    (
        "pendulum_converged_beams.dat",
        "pendulum_flexible1.dat",
        &[Mesh, Step, End, Output],
    ),
    // The triangle of Fig. 2 replaced by a haversine pulse (the torque, the only nodal load: load 0).
    ("pendulum_haversine.dat", "pendulum.dat", &[LoadFunction(0)]),
    ("pendulum_short.dat", "pendulum.dat", &[End]),
    // To 20.8 s, node 23 only (tests/energy_guard_run.rs).
    ("pendulum_grazing.dat", "pendulum.dat", &[End, Output]),
    // At its PARAMETERS' values.
    ("pendulum_sweep.dat", "pendulum.dat", &[Output]),
];

#[test]
fn every_derived_deck_is_its_seed_case_but_for_what_it_names() {
    for (derived, case, diffs) in DERIVED {
        assert_same_case(derived, &deck(derived), case, diffs);
    }
}

/// The old `pendulum_converged.dat` (no `CLIP OFF` on its CAME card) is caught: the test
/// above is not one that cannot fail.
#[test]
fn the_clipped_converged_deck_is_caught() {
    let text = std::fs::read_to_string(deck_path("pendulum_converged.dat")).expect("read");
    assert!(text.contains("CLIP OFF"));
    let old = parse_deck(&text.replace("  CLIP OFF", ""), "old converged").expect("parses");
    // (A model may hold controllers' laws, not unwind-safe in general; this one holds none
    // and the closure only reads it.)
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        assert_same_case(
            "the old converged deck",
            &old,
            "pendulum_flexible1.dat",
            &[Mesh, Step, End, Output, Integrator],
        )
    }));
    assert!(r.is_err(), "the clipped contact law went unnoticed");
}

/// The generators of `benches/` and of the tests (`mecano::scenes`) build the seed cases at
/// any mesh: flexible1 (and `decks/pendulum.dat`), flexible2 and rigid by Young's modulus.
#[test]
fn the_generated_decks_are_the_seed_cases() {
    let cases = [
        (2.1e11, "pendulum_flexible1.dat"),
        (2.1e10, "pendulum_flexible2.dat"),
        (2.1e15, "pendulum_rigid.dat"),
    ];
    for (young, case) in cases {
        for output in [true, false] {
            let s = PendulumSettings {
                young,
                output,
                ..Default::default()
            };
            // The seed's own settings: with the output, the paper's mesh is not a difference.
            let diffs: &[Diff] = if output { &[Mesh] } else { &[Mesh, Output] };
            for n in [1, 2, 10, 20, 80] {
                let m = parse_deck(&pendulum_deck(n, &s), "generated").expect("parses");
                assert_same_case(
                    &format!("pendulum_deck({n}), E = {young:e}"),
                    &m,
                    case,
                    diffs,
                );
            }
            if output {
                let m = parse_deck(&pendulum_deck(10, &s), "generated").expect("parses");
                assert_same_case("pendulum_deck(10)", &m, case, &[]);
            }
            for (d, p) in [(1, 1), (10, 1), (1, 8), (2, 6), (4, 4)] {
                let m = parse_deck(&pendulum_order_deck(d, p, &s), "generated").expect("parses");
                let what = format!("pendulum_order_deck({d}, {p}), E = {young:e}");
                assert_same_case(&what, &m, case, diffs);
            }
        }
    }
    // Step and end time are settings of their own.
    let s = PendulumSettings {
        step: 2.5e-5,
        end: 0.3,
        ..Default::default()
    };
    let m = parse_deck(&pendulum_order_deck(1, 8, &s), "generated").expect("parses");
    assert_same_case(
        "pendulum_order_deck at other steps",
        &m,
        "pendulum.dat",
        &[Mesh, Step, End],
    );
}

/// The three seed cases differ from each other only by Young's modulus (scenario.md).
#[test]
fn the_seed_cases_differ_only_by_young_s_modulus() {
    for case in ["pendulum_flexible2.dat", "pendulum_rigid.dat"] {
        let mut m = deck(case);
        let f1 = load_deck(&deck_path("pendulum_flexible1.dat")).expect("parses");
        let (ours, theirs) = (&mut m.materials[0], &f1.materials[0]);
        // Same Poisson's ratio: G/E the same to rounding.
        assert!((ours.shear / ours.young - theirs.shear / theirs.young).abs() < 1e-15);
        (ours.young, ours.shear) = (theirs.young, theirs.shear);
        assert_same_case(case, &m, "pendulum_flexible1.dat", &[]);
    }
}
