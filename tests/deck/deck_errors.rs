//! Malformed decks: each gives a clear error at the right line and column, and the parser
//! never panics.

use mecano::deck::{DeckErrors, load_deck, parse_deck};

/// A valid preamble of 7 lines: material 1, section 1, nodes 1 (origin) and 2 (1, 0, 0).
const P: &str =
    "MATERIALS\n 1 E 1 NU 0.3 RHO 1\nSECTIONS\n 1 A 1 I2 1 I3 1 J 1\nNODES\n 1 0 0 0\n 2 1 0 0\n";
const A: &str = "ANALYSIS STATIC\n";

fn errors_of(deck: &str) -> DeckErrors {
    match std::panic::catch_unwind(|| parse_deck(deck, "test.dat")) {
        Ok(Ok(_)) => panic!("deck should be rejected:\n{deck}"),
        Ok(Err(e)) => e,
        Err(_) => panic!("parse_deck panicked on:\n{deck}"),
    }
}

#[test]
fn malformed_decks_table() {
    let el = |card: &str| format!("{P}ELEMENTS\n{card}\n{A}"); // the card is on line 9
    let cases: Vec<(String, usize, usize, &str)> = vec![
        // empty deck, missing or repeated analysis
        ("".into(), 1, 1, "empty deck"),
        (
            "! only a comment\n\n   # another\n".into(),
            1,
            1,
            "empty deck",
        ),
        ("TITLE x\n".into(), 2, 1, "no ANALYSIS card"),
        (
            format!("{A}ANALYSIS DYNAMIC STEP 1 END 2\n"),
            2,
            1,
            "second ANALYSIS card",
        ),
        // unknown keywords
        (
            "MATERIAL\n 1 E 1 NU 0.3 RHO 1\n".into(),
            1,
            1,
            "unknown keyword `MATERIAL`",
        ),
        (
            format!("NODES\n 1 0 0 0\n FOO 1\n{A}"),
            3,
            2,
            "unknown keyword `FOO`",
        ),
        (format!("1 0 0 0\n{A}"), 1, 1, "outside a section"),
        (
            el(" 1 BAEM 1 2 MAT 1 SEC 1"),
            9,
            4,
            "unknown element type `BAEM`",
        ),
        (
            "ANALYSIS DYNAMIC STEP 1 END 2 BETA 3\n".into(),
            1,
            31,
            "unexpected `BETA`",
        ),
        (
            format!("MATERIALS\n 1 E 1 NU 0.3 RHO 1 COLOR 2\n{A}"),
            2,
            21,
            "unexpected `COLOR`",
        ),
        (
            "ANALYSIS QUASI\n".into(),
            1,
            10,
            "expected DYNAMIC, STATIC or MODES",
        ),
        (format!("{P}FIX 1 Q\n{A}"), 8, 7, "unexpected `Q`"),
        // malformed or missing numbers, field counts
        (
            format!("MATERIALS\n 1 E 2.1e NU 0.3 RHO 1\n{A}"),
            2,
            6,
            "found `2.1e` (not a number)",
        ),
        (format!("NODES\n 1 0 abc 0\n{A}"), 2, 6, "found `abc`"),
        (
            format!("NODES\n 1 0 0\n{A}"),
            2,
            7,
            "missing coordinates z component",
        ),
        (format!("NODES\n 1 0 0 0 5\n{A}"), 2, 10, "unexpected `5`"),
        (format!("NODES\n 1.5 0 0 0\n{A}"), 2, 2, "whole number"),
        (
            format!("NODES\n 1 0 1e999 0\n{A}"),
            2,
            6,
            "not a finite value",
        ),
        ("ANALYSIS STATIC MAXIT 1.5\n".into(), 1, 23, "whole number"),
        (
            "ANALYSIS STATIC NEWTON FAST\n".into(),
            1,
            24,
            "FULL or MODIFIED",
        ),
        (
            format!("FUNCTIONS\n 1 TABLE 0 0 1\n{A}"),
            2,
            2,
            "come in pairs",
        ),
        (
            el(" 3 HINGE 1 2 AXIS 0 0"),
            9,
            22,
            "missing HINGE AXIS z component",
        ),
        (
            el(" 3 CAME 1 2 CAM LINE FOLLOWER POINT C 1"),
            9,
            40,
            "needs K",
        ),
        (format!("MATERIALS\n 1 E 1 RHO 1\n{A}"), 2, 13, "needs NU"),
        (
            format!("MATERIALS\n 1 E 1 NU 0.3 G 1 RHO 1\n{A}"),
            2,
            15,
            "cannot both be given",
        ),
        (
            format!("MATERIALS\n 1 E 1 E 2 NU 0.3 RHO 1\n{A}"),
            2,
            8,
            "`E` given twice",
        ),
        // duplicates
        (
            format!("NODES\n 1 0 0 0\n 1 1 0 0\n{A}"),
            3,
            2,
            "duplicate node number 1: already defined on line 2",
        ),
        (
            el(" 1 BEAM 1 2 MAT 1 SEC 1\n 1 BEAM 2 1 MAT 1 SEC 1"),
            10,
            2,
            "duplicate element number 1",
        ),
        (
            format!("MATERIALS\n 7 E 1 G 1 RHO 1\n 7 E 1 G 1 RHO 1\n{A}"),
            3,
            2,
            "duplicate material number 7",
        ),
        (
            format!("SECTIONS\n 1 A 1 I2 1 I3 1 J 1\n 1 A 1 I2 1 I3 1 J 1\n{A}"),
            3,
            2,
            "duplicate section number 1",
        ),
        (
            format!("FUNCTIONS\n 1 CONSTANT 1\n 1 CONSTANT 2\n{A}"),
            3,
            2,
            "duplicate function number 1",
        ),
        (
            format!("{P}NODES\n 3 TO 5 LINE 0 0 0 1 1 1\n 6 TO 8 LINE 0 0 0 1 1 1\n 4 0 0 0\n{A}"),
            11,
            2,
            "duplicate node number 4",
        ),
        // undefined references
        (el(" 1 BEAM 1 3 MAT 1 SEC 1"), 9, 11, "undefined node 3"),
        (el(" 1 BEAM 1 2 MAT 2 SEC 1"), 9, 17, "undefined material 2"),
        (el(" 1 BEAM 1 2 MAT 1 SEC 9"), 9, 23, "undefined section 9"),
        (
            format!("{P}LOADS\n MOMENT 2 0 0 1 FUNCTION 4\n{A}"),
            9,
            26,
            "undefined function 4",
        ),
        (
            format!("{P}LOADS\n FORCE 5 0 0 1\n{A}"),
            9,
            8,
            "undefined node 5",
        ),
        (
            el(" 1 TO 3 BEAM 1 2 MAT 1 SEC 1"),
            9,
            16,
            "undefined node 3",
        ),
        (
            format!("{P}OUTPUT NODES 1 2 9\n{A}"),
            8,
            18,
            "undefined node 9",
        ),
        // geometry
        (
            el(" 1 BEAM 2 2 MAT 1 SEC 1"),
            9,
            9,
            "joins node 2 to itself",
        ),
        (
            format!("{P} 3 1 0 0\nELEMENTS\n 1 BEAM 2 3 MAT 1 SEC 1\n{A}"),
            10,
            9,
            "zero length",
        ),
        (
            el(" 1 HINGE 1 2 AXIS 0 0 0"),
            9,
            19,
            "HINGE AXIS must be a non-zero finite vector",
        ),
        (
            el(" 1 PRISMATIC 1 2 AXIS 0 0 0"),
            9,
            23,
            "PRISMATIC AXIS must be a non-zero",
        ),
        (
            el(" 1 UJOINT 1 2 AXIS1 0 0 1 AXIS2 0 0.1 1"),
            9,
            21,
            "must be perpendicular",
        ),
        (
            el(" 1 UJOINT 1 2 AXIS1 0 0 0 AXIS2 0 1 0"),
            9,
            21,
            "UJOINT AXIS1 must be a non-zero",
        ),
        (
            el(" 1 BEAM 1 2 MAT 1 SEC 1 AXIS2 2 0 0"),
            9,
            31,
            "parallel to the beam",
        ),
        (
            el(" 1 BEAM 1 2 MAT 1 SEC 1 AXIS2 0 0 0"),
            9,
            31,
            "AXIS2 must be a non-zero",
        ),
        (
            el(" 1 BEAM 1 2 MAT 1 SEC 1 DIVIDE 0"),
            9,
            32,
            "DIVIDE = 0 is out of range: expected 1 to 1000000 elements",
        ),
        (
            el(" 1 BEAM 1 2 MAT 1 SEC 1 DIVIDE 2.5"),
            9,
            32,
            "DIVIDE (number of elements)",
        ),
        (
            el(" 1 CAME 1 2 CAM LINE PLANE 1 0 0 2 0 0 FOLLOWER POINT K 1"),
            9,
            22,
            "PLANE vectors",
        ),
        // ranges
        (
            format!("MATERIALS\n 1 E 0 NU 0.3 RHO 1\n{A}"),
            2,
            6,
            "E (Young's modulus) = 0 is out of range",
        ),
        (
            format!("MATERIALS\n 1 E -2.1e11 NU 0.3 RHO 1\n{A}"),
            2,
            6,
            "expected > 0",
        ),
        (
            format!("MATERIALS\n 1 E 1 NU 0.3 RHO -1\n{A}"),
            2,
            19,
            "RHO (density) = -1 is out of range",
        ),
        (
            format!("MATERIALS\n 1 E 1 NU 0.5 RHO 1\n{A}"),
            2,
            11,
            "-1 < nu < 0.5",
        ),
        (
            format!("MATERIALS\n 1 E 1 NU -1 RHO 1\n{A}"),
            2,
            11,
            "NU (Poisson's ratio) = -1",
        ),
        (
            format!("SECTIONS\n 1 A 0 I2 1 I3 1 J 1\n{A}"),
            2,
            6,
            "A = 0 is out of range",
        ),
        (
            format!("SECTIONS\n 1 A 1 I2 1 I3 1 J 1 K 1.2\n{A}"),
            2,
            24,
            "0 < k <= 1",
        ),
        (
            "ANALYSIS DYNAMIC ALPHA -0.5 STEP 1e-3 END 1\n".into(),
            1,
            24,
            "-1/3 <= alpha <= 0",
        ),
        (
            "ANALYSIS DYNAMIC ALPHA 0.1 STEP 1e-3 END 1\n".into(),
            1,
            24,
            "ALPHA (HHT) = 0.1",
        ),
        (
            "ANALYSIS DYNAMIC GENALPHA RHOINF 1.5 STEP 1e-3 END 1\n".into(),
            1,
            34,
            "0 <= rho_inf <= 1",
        ),
        (
            "ANALYSIS DYNAMIC ALPHA -0.1 GENALPHA STEP 1e-3 END 1\n".into(),
            1,
            29,
            "ALPHA and GENALPHA cannot both be given",
        ),
        (
            "ANALYSIS DYNAMIC RHOINF 0.5 STEP 1e-3 END 1\n".into(),
            1,
            44,
            "GENALPHA",
        ),
        // CARRY: a value, with ADAPTIVE, and MODES only for the ESDIRK schemes
        (
            "ANALYSIS DYNAMIC ESDIRK5 STEP 1e-3 END 1 ADAPTIVE TOLPOS 1 TOLROT 1 CARRY ALL\n"
                .into(),
            1,
            75,
            "RUN or MODES",
        ),
        (
            "ANALYSIS DYNAMIC ESDIRK5 STEP 1e-3 END 1 CARRY MODES\n".into(),
            1,
            53,
            "ADAPTIVE",
        ),
        (
            "ANALYSIS DYNAMIC STEP 1e-3 END 1 ADAPTIVE TOLPOS 1 TOLROT 1 CARRY MODES\n".into(),
            1,
            61,
            "ESDIRK3 or ESDIRK5",
        ),
        (
            "ANALYSIS DYNAMIC STEP 0 END 1\n".into(),
            1,
            23,
            "STEP (time step) = 0 is out of range",
        ),
        (
            "ANALYSIS DYNAMIC STEP -1e-3 END 1\n".into(),
            1,
            23,
            "STEP (time step) = -1e-3",
        ),
        (
            "ANALYSIS DYNAMIC STEP 1e-3 END -1\n".into(),
            1,
            32,
            "END (end time) = -1 is out of range",
        ),
        (
            "ANALYSIS DYNAMIC STEP 1e-3 END 1 MINSTEP 1\n".into(),
            1,
            42,
            "0 < MINSTEP <= STEP",
        ),
        (
            "ANALYSIS DYNAMIC STEP 1e-3 &\n  END 1 MAXIT 0\n".into(),
            2,
            15,
            "MAXIT = 0",
        ),
        ("ANALYSIS DYNAMIC END 1\n".into(), 1, 23, "needs STEP"),
        (
            format!("FUNCTIONS\n 1 TABLE 0 0 0.02 1 0.01 0\n{A}"),
            2,
            21,
            "t = 0.01 comes after t = 0.02",
        ),
        (
            format!("{P}NODES\n 5 TO 3 LINE 0 0 0 1 1 1\n{A}"),
            9,
            2,
            "bad generation `5 TO 3`",
        ),
        (
            el(" 5 TO 5 BEAM 1 2 MAT 1 SEC 1"),
            9,
            2,
            "bad generation `5 TO 5`",
        ),
        // a typo that would ask for billions of items is an error, not an exhausted memory
        (
            format!("{P}NODES\n 3 TO 4294967295 LINE 0 0 0 1 1 1\n{A}"),
            9,
            2,
            "4294967293 items, more than the 1000000",
        ),
        (
            el(" 5 TO 2000000 BEAM 1 2 MAT 1 SEC 1"),
            9,
            2,
            "1999996 items",
        ),
        (el(" 1 MASS 2 M -1"), 9, 13, "M (mass) = -1 is out of range"),
        (
            el(" 1 CAME 1 2 CAM CIRCLE 0 FOLLOWER POINT K 1"),
            9,
            24,
            "CIRCLE radius = 0",
        ),
        (
            el(" 1 CAME 1 2 CAM SPLINE CLOSED 2 0 0 1 1 FOLLOWER POINT K 1"),
            9,
            31,
            ">= 3 points",
        ),
        (
            el(" 1 CAME 1 2 CAM LINE FOLLOWER POINT K 0"),
            9,
            39,
            "K (contact stiffness) = 0",
        ),
        // end, unicode columns
        (format!("{A}END now\n"), 2, 5, "unexpected `now`"),
        (format!("TITLE é\nNODES\n 1 é 0 0\n{A}"), 3, 4, "found `é`"),
        (format!("NODES\n 1 0 0 &\n   zz\n{A}"), 3, 4, "found `zz`"),
        // CONTROL laws (issue 36 §6): sensors checked and located inside the law's field
        (
            el(" 1 HINGE 1 2 AXIS 0 0 1\n 2 CONTROL TORQUE 1 LAW (-4*angel(1))"),
            10,
            29,
            "a sensor (angle(h), rate(h)",
        ),
        (
            el(" 1 HINGE 1 2 AXIS 0 0 1\n 2 MASS 2 M 1\n 3 CONTROL TORQUE 1 LAW (-4*rate(2))"),
            11,
            29,
            "CONTROL element 3 names element 2, a MASS",
        ),
        (
            el(" 1 HINGE 1 2 AXIS 0 0 1\n 2 CONTROL FORCE 2 X LAW -4*vx(9)"),
            10,
            29,
            "undefined node 9",
        ),
        (
            el(" 1 HINGE 1 2 AXIS 0 0 1\n 2 CONTROL TORQUE 1 LAW (1+1/angle(1))"),
            10,
            28,
            "`1/angle(1)` in `(1+1/angle(1))`: its value is not finite at t = 0 s",
        ),
        (
            el(" 1 HINGE 1 2 AXIS 0 0 1\n 2 CONTROL TORQUE 1 LAW (-angle(1.5))"),
            10,
            33,
            "a whole number >= 1",
        ),
        (
            el(" 1 HINGE 1 2 AXIS 0 0 1\n 2 CONTROL TORQUE 1"),
            10,
            20,
            "LAW",
        ),
    ];
    assert!(cases.len() >= 30);
    let mut failures = Vec::new();
    for (deck, line, col, gist) in &cases {
        let errs = errors_of(deck);
        let first = &errs.errors()[0];
        let msg = first.to_string();
        let at = errs.line_col(0);
        if at != Some((*line, *col)) || !msg.contains(gist) {
            failures.push(format!(
                "deck {deck:?}\n  expected {line}:{col} \"{gist}\"\n  got      {at:?} \"{msg}\" ({} errors)",
                errs.errors().len()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn every_error_of_a_deck_is_reported() {
    let deck = format!(
        "{P}ELEMENTS\n 1 BEAM 1 2 MAT 1 SEC 1\n 2 BEAM 1 7 MAT 1 SEC 1\n 3 HINGE 1 2 AXIS 0 0 0\nFUNCTIONS\n 1 TABLE 1 0 0 1\n{A}"
    );
    let errs = errors_of(&deck);
    let lc: Vec<_> = (0..errs.errors().len()).map(|i| errs.line_col(i)).collect();
    assert_eq!(errs.errors().len(), 3, "{lc:?} {:?}", errs.errors());
    assert_eq!(lc, vec![Some((10, 11)), Some((11, 19)), Some((13, 14))]);
    // The miette report shows all of them.
    let report = format!("{:?}", miette::Report::new(errs));
    assert!(report.contains("undefined node 7"), "{report}");
    assert!(report.contains("HINGE AXIS must be a non-zero"), "{report}");
    assert!(
        report.contains("TABLE times must be non-decreasing"),
        "{report}"
    );
    assert!(report.contains("test.dat"), "{report}");
}

#[test]
fn keywords_are_case_insensitive() {
    let deck = "title Small\nnodes\n 1 0 0 0 fix all\n 2 1 0 0\nElements\n 1 hinge 1 2 axis 0 0 1\nanalysis Static steps 2\nend\n";
    let m = parse_deck(deck, "t.dat")
        .map_err(miette::Report::new)
        .expect("valid");
    assert_eq!(m.title, "Small");
    assert_eq!(m.nodes.len(), 2);
}

#[test]
fn missing_file() {
    let path = std::env::temp_dir().join("mecano_no_such_deck_4711.dat");
    let _ = std::fs::remove_file(&path);
    let errs = load_deck(&path).expect_err("missing file");
    assert_eq!(errs.errors().len(), 1);
    assert_eq!(errs.errors()[0].span, None);
    assert_eq!(errs.line_col(0), None);
    let msg = errs.to_string();
    assert!(
        msg.contains("cannot read deck file") && msg.contains("mecano_no_such_deck_4711.dat"),
        "{msg}"
    );
    let _ = format!("{:?}", miette::Report::new(errs)); // renders without source
}

#[test]
fn not_utf8_file() {
    let path = std::env::temp_dir().join(format!("mecano_bad_utf8_{}.dat", std::process::id()));
    std::fs::write(&path, b"TITLE caf\xe9\nANALYSIS STATIC\n").expect("temp file");
    let errs = load_deck(&path).expect_err("not UTF-8");
    let _ = std::fs::remove_file(&path);
    let msg = errs.to_string();
    assert!(
        msg.contains("not UTF-8") && msg.contains("offset 9"),
        "{msg}"
    );
    // Issue 28 §5: located (line 1, column 10), not only an offset.
    assert_eq!(errs.line_col(0), Some((1, 10)));
}
