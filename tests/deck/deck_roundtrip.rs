//! Every deck in `decks/` reads, prints back (canonical writer) and reads again to the
//! same model (spans aside).

use mecano::deck::{load_deck, parse_deck, strip_spans, write_deck};
use mecano::model::{ElementKind, Model};
use std::path::PathBuf;

/// The decks of `decks/`, `decks/benchmarks/` and `decks/superelement/`.
fn decks() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("decks");
    let mut v: Vec<PathBuf> = [
        dir.clone(),
        dir.join("benchmarks"),
        dir.join("superelement"),
    ]
    .iter()
    .filter_map(|d| std::fs::read_dir(d).ok())
    .flatten()
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

/// Every feature of the language survives a round trip, including frames built from PLANE
/// and ANGLE, generated nodes with awkward spacing and adaptive stepping.
#[test]
fn feature_rich_decks_round_trip() {
    let decks = [
        "TITLE  every   feature, with commas
MATERIALS
  1 E 7e10 NU 0.33 RHO 2700 DAMPING 1e-4
  5 E 2.1e11 G 8.1e10 RHO 0
SECTIONS
  1 A 1e-4 I2 1e-9 I3 2e-9 J 3e-9 K 0.9
  2 RIGID A 1e-4 J 1e-9
NODES
  1 0 0 0 FIX ALL
  10 TO 17 LINE 0.1 0.2 0.3 1.7 -0.3 2.9 FIX RX RY
  20 -.5 +3 5. FIX TRANS
  21 1 1 1
  FIX 21 Z RZ
FUNCTIONS
  3 TABLE 0 0 0.1 1 0.1 2 0.3 -1
  4 CONSTANT 2.5
ELEMENTS
  100 TO 106 BEAM 10 11 MAT 1 SEC 1 AXIS2 0.3 0.1 0.7
  7 BEAM 17 20 MAT 5 SEC 2
  8 MASS 20 M 3 INERTIA 1 2 3 0.1 0.2 0.3
  9 MASS 21 M 0 INERTIA 1 2 3
  11 HINGE 1 10 AXIS 1 2 3
  12 UJOINT 17 20 AXIS1 1 1 0 AXIS2 -1 1 0.5
  13 SPHERICAL 20 21
  14 CLAMP 1 21
  15 PRISMATIC 1 20 AXIS 0 3 4
  16 RIGID 20 21 1
  17 CAME 1 20 CAM LINE ANGLE 33 OFFSET 0 1 2 PLANE 1 1 0 0 1 1 FOLLOWER CIRCLE 0.25 PLANE 0 0 1 1 0 0 &
     K 1e6 C 10 MU 0.3 VREG 0.01 CLIP OFF IMPACT_STEPS 4
  18 CAME 21 17 CAM SPLINE CLOSED 3 0 0 1 0 0 1 OFFSET 0.1 0 0 FOLLOWER POINT K 1
  19 CAME 21 20 CAM CIRCLE 0.5 FOLLOWER LINE ANGLE -90 K 2
LOADS
  GRAVITY 0 0 -9.81
  FORCE 17 1 2 3 FUNCTION 3
  MOMENT 20 0 0 1
ANALYSIS DYNAMIC ALPHA -0.3333333333 STEP 1e-3 END 0.5 MINSTEP 1e-7 MAXSTEP 1e-2 &
  ADAPTIVE TOLPOS 1e-5 TOLROT 1e-4 GROWTH 1.5 TOL 1e-9 TOLINC 1e-11 MAXIT 7
OUTPUT NODES NONE ELEMENTS 7 8 EVERY 3 DIR out/Rich VTK
END
this is not read",
        "NODES\n 1 0 0 0\nANALYSIS STATIC STEPS 4 TOL 1e-6\nOUTPUT ELEMENTS ALL NODES 1\n",
        "ANALYSIS DYNAMIC STEP 0.1 END 1\n",
        "ANALYSIS DYNAMIC GENALPHA RHOINF 0.9 STEP 0.1 END 1 ADAPTIVE TOLPOS 1e-5 TOLROT 1e-4\n",
        "ANALYSIS DYNAMIC STEP 0.1 END 1 GENALPHA\n",
        "ANALYSIS DYNAMIC ESDIRK5 STEP 0.1 END 1 ADAPTIVE TOLPOS 1e-5 TOLROT 1e-4 CARRY MODES\n",
    ];
    for deck in decks {
        let mut first = match parse_deck(deck, "rich.dat") {
            Ok(m) => m,
            Err(e) => panic!("{:?}", miette::Report::new(e)),
        };
        let text = write_deck(&first);
        let mut second = match parse_deck(&text, "written") {
            Ok(m) => m,
            Err(e) => panic!("{:?}\n{text}", miette::Report::new(e)),
        };
        strip_spans(&mut first);
        strip_spans(&mut second);
        assert_eq!(first, second, "round trip differs\n{text}");
        assert_eq!(write_deck(&second), text);
    }
    // GENALPHA reads to generalized-α (ρ∞ given, or the default), ALPHA alone to HHT.
    let scheme = |d: &str| match parse_deck(d, "d").expect("valid").analysis {
        mecano::model::Analysis::Dynamic { scheme, .. } => scheme,
        other => panic!("{other:?}"),
    };
    use mecano::model::Scheme;
    assert_eq!(scheme(decks[3]), Scheme::GeneralizedAlpha { rho_inf: 0.9 });
    assert_eq!(
        scheme(decks[4]),
        Scheme::GeneralizedAlpha {
            rho_inf: Scheme::DEFAULT_RHO_INF
        }
    );
    assert_eq!(
        scheme(decks[0]),
        Scheme::Hht {
            alpha: -0.3333333333
        }
    );
    let m = parse_deck(decks[0], "rich.dat").expect("valid");
    assert_eq!(m.title, "every   feature, with commas");
    assert_eq!(m.elements.len(), 7 + 12);
    let n = &m.nodes[&mecano::model::NodeId(17)];
    assert_eq!(n.position, nalgebra::Vector3::new(1.7, -0.3, 2.9));
    assert_eq!(n.fixed, [false, false, false, true, true, false]);
    assert_eq!(
        m.nodes[&mecano::model::NodeId(21)].fixed,
        [false, false, true, false, false, true]
    );
    let mat = &m.materials[&mecano::model::MaterialId(1)];
    assert!((mat.shear - 7e10 / 2.66).abs() < 1.0);
    match &m.elements[&mecano::model::ElementId(17)].kind {
        ElementKind::Came(c) => {
            let f = c.cam.frame;
            // Orthonormal and right-handed.
            assert!((f.transpose() * f - nalgebra::Matrix3::identity()).norm() < 1e-12);
            assert!((f.determinant() - 1.0).abs() < 1e-12);
            // Axis 3 of the plane is e1 x e2 normalised, unchanged by ANGLE.
            let e3 = nalgebra::Vector3::new(1.0, -1.0, 1.0) / 3f64.sqrt();
            assert!((f.column(2) - e3).norm() < 1e-12);
            assert!(!c.clip_tension);
            assert_eq!(c.impact_steps, 4);
        }
        other => panic!("{other:?}"),
    }
}

/// `ANALYSIS MODES n` reads to a model asking for n modes, prints back as the same card
/// (parse ∘ write = id, the text a fixed point); `MODES 0`, a missing count or another
/// field after it are located errors.
#[test]
fn modes_analysis_round_trips() {
    let deck = "MATERIALS\n 1 E 2.1e11 NU 0.3 RHO 7800\nSECTIONS\n 1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8\n\
NODES\n 1 0 0 0 FIX ALL\n 2 1 0 0\nELEMENTS\n 1 BEAM 1 2 MAT 1 SEC 1\nANALYSIS MODES 6\n";
    let mut first = parse_deck(deck, "modes").expect("parses");
    assert_eq!(first.modes, Some(6));
    let text = write_deck(&first);
    assert!(text.contains("\nANALYSIS MODES 6\n"), "{text}");
    let mut second = parse_deck(&text, "written").expect("written deck parses");
    strip_spans(&mut first);
    strip_spans(&mut second);
    assert_eq!(first, second);
    assert_eq!(write_deck(&second), text);
    // A deck without MODES asks for none.
    let dynamic = deck.replace("ANALYSIS MODES 6", "ANALYSIS DYNAMIC STEP 1e-3 END 1");
    assert_eq!(parse_deck(&dynamic, "d").expect("parses").modes, None);
    for (bad, at) in [
        ("ANALYSIS MODES 0", "0"),
        ("ANALYSIS MODES", ""),
        ("ANALYSIS MODES 3 STEP 1", "STEP"),
    ] {
        let text = deck.replace("ANALYSIS MODES 6", bad);
        let e = parse_deck(&text, "bad").expect_err(bad);
        let msg = format!("{:?}", miette::Report::new(e));
        assert!(
            msg.contains("bad:10:"),
            "{bad}: not located on its line: {msg}"
        );
        if !at.is_empty() {
            assert!(msg.contains(at), "{bad}: {msg}");
        }
    }
}
