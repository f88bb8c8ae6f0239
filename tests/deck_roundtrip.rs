//! Every deck in `decks/` reads, prints back (canonical writer) and reads again to the
//! same model (spans aside).

use mecano::deck::{load_deck, parse_deck, strip_spans, write_deck};
use mecano::model::{ElementKind, Model};
use std::path::PathBuf;

fn decks() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("decks");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("decks/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "dat"))
        .collect();
    v.sort();
    v
}

fn load(path: &std::path::Path) -> Model {
    match load_deck(path) {
        Ok(m) => m,
        Err(e) => panic!("{}: {:?}", path.display(), miette::Report::new(e)),
    }
}

#[test]
fn every_deck_round_trips() {
    let paths = decks();
    assert!(
        paths.len() >= 5,
        "expected the pendulum decks, found {paths:?}"
    );
    for path in paths {
        let mut first = load(&path);
        let text = write_deck(&first);
        let mut second = match parse_deck(&text, "written") {
            Ok(m) => m,
            Err(e) => panic!(
                "{}: written deck does not parse: {:?}\n{text}",
                path.display(),
                miette::Report::new(e)
            ),
        };
        strip_spans(&mut first);
        strip_spans(&mut second);
        assert_eq!(
            first,
            second,
            "{}: round trip differs\n{text}",
            path.display()
        );
        // The canonical text is a fixed point.
        assert_eq!(write_deck(&second), text, "{}", path.display());
    }
}

#[test]
fn pendulum_has_the_scene_of_the_paper() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("decks");
    for name in [
        "pendulum.dat",
        "pendulum_flexible1.dat",
        "pendulum_flexible2.dat",
        "pendulum_rigid.dat",
    ] {
        let m = load(&dir.join(name));
        let s = m.summary();
        assert_eq!(s.nodes, 24, "{name}");
        assert_eq!(m.elements.len(), 25, "{name}");
        assert_eq!(s.elements.get("HINGE"), Some(&1));
        assert_eq!(s.elements.get("BEAM"), Some(&20));
        assert_eq!(s.elements.get("UJOINT"), Some(&1));
        assert_eq!(s.elements.get("CAME"), Some(&1));
        assert_eq!(s.elements.get("MASS"), Some(&2));
        let e = s.effects;
        assert!(e.gravity && e.applied_loads && e.contact && e.point_masses && e.joints);
        let n23 = &m.nodes[&mecano::model::NodeId(23)];
        assert!(
            (n23.position - nalgebra::Vector3::new(1.8660254037844386, 0.0, 0.5)).norm() < 1e-15
        );
        let n7 = &m.nodes[&mecano::model::NodeId(7)];
        assert!((n7.position.x - 0.5).abs() < 1e-15);
        assert!(m.nodes[&mecano::model::NodeId(1)].fixed.iter().all(|f| *f));
        assert!(m.nodes[&mecano::model::NodeId(24)].fixed.iter().all(|f| *f));
        assert!(matches!(
            m.elements[&mecano::model::ElementId(23)].kind,
            ElementKind::Came(_)
        ));
        assert_eq!(
            m.elements[&mecano::model::ElementId(23)].nodes,
            vec![mecano::model::NodeId(24), mecano::model::NodeId(23)]
        );
    }
    let young: Vec<f64> = [
        "pendulum_rigid.dat",
        "pendulum_flexible1.dat",
        "pendulum_flexible2.dat",
    ]
    .iter()
    .map(|n| load(&dir.join(n)).materials[0].young)
    .collect();
    assert_eq!(young, vec![2.1e15, 2.1e11, 2.1e10]);
    // flexible1 is the default deck with another title.
    let mut a = load(&dir.join("pendulum.dat"));
    let mut b = load(&dir.join("pendulum_flexible1.dat"));
    strip_spans(&mut a);
    strip_spans(&mut b);
    b.title = a.title.clone();
    assert_eq!(a, b);
    let nc = load(&dir.join("pendulum_nocontact.dat"));
    assert_eq!(nc.elements.len(), 24);
    assert!(!nc.effects().contact);
}
