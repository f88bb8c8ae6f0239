//! Tests of the expression grammar: values, errors, nesting, expressions of `t`.

use super::*;

fn params(name: &str) -> Option<f64> {
    match name {
        "E" => Some(2.1e11),
        "k" => Some(4.0),
        "m" => Some(9.0),
        "zeta" => Some(0.05),
        "a_1" => Some(-2.0),
        _ => None,
    }
}

fn ev(t: &str) -> Result<f64, ExprError> {
    eval(t, &params)
}

#[test]
fn values_and_precedence() {
    assert_eq!(ev("$E"), Ok(2.1e11));
    assert_eq!(ev("2*$zeta*sqrt($k*$m)"), Ok(2.0 * 0.05 * 6.0));
    assert_eq!(ev("1+2*3"), Ok(7.0));
    assert_eq!(ev("(1+2)*3"), Ok(9.0));
    assert_eq!(ev("2^3^2"), Ok(512.0));
    assert_eq!(ev("-2^2"), Ok(-4.0));
    assert_eq!(ev("2^-1"), Ok(0.5));
    assert_eq!(ev("8/4/2"), Ok(1.0));
    assert_eq!(ev("1-2-3"), Ok(-4.0));
    assert_eq!(ev("--3"), Ok(3.0));
    assert_eq!(ev("1e-3*$a_1"), Ok(-2e-3));
    assert_eq!(ev(".5E+1"), Ok(5.0));
    assert_eq!(ev(" ( 1 + 2 ) * 3 "), Ok(9.0));
    assert_eq!(ev("PI"), Ok(std::f64::consts::PI));
    assert_eq!(ev("cos(pi)"), Ok(-1.0));
    assert_eq!(ev("SIN(0)"), Ok(0.0));
    assert_eq!(ev("exp(log(3))"), Ok(3.0f64.ln().exp()));
    assert_eq!(ev("abs(-$k)"), Ok(4.0));
}

#[test]
fn errors_are_located() {
    let e = ev("2*$F").unwrap_err();
    assert_eq!((e.at, e.len), (2, 2));
    assert_eq!(
        e.kind,
        ExprErrorKind::UndefinedParameter { name: "F".into() }
    );
    let e = ev("2*").unwrap_err();
    assert_eq!(e.at, 2);
    assert!(
        matches!(e.kind, ExprErrorKind::Syntax { ref found, .. } if found == "the end of the expression")
    );
    let e = ev("(1+2").unwrap_err();
    assert_eq!(e.at, 4);
    let e = ev("1+2)").unwrap_err();
    assert_eq!(e.at, 3);
    let e = ev("tan(1)").unwrap_err();
    assert_eq!((e.at, e.len), (0, 3));
    assert!(matches!(e.kind, ExprErrorKind::UnknownFunction { .. }));
    let e = ev("sqrt(-1)").unwrap_err();
    assert!(matches!(e.kind, ExprErrorKind::NotFinite { .. }));
    assert!(matches!(
        ev("1/(1-1)").unwrap_err().kind,
        ExprErrorKind::NotFinite { .. }
    ));
    let e = ev("2.1e").unwrap_err();
    assert_eq!(e.at, 4);
    let e = ev("$ 1").unwrap_err();
    assert_eq!(e.at, 1);
    let e = ev("1 é").unwrap_err();
    assert_eq!((e.at, e.len), (2, 2));
    assert!(ev("").is_err());
    assert!(ev("sqrt 2").is_err());
}

/// Issue 28 §2: 100,000 nested parentheses, calls, signs or powers are a located
/// error at the first level past [`MAX_DEPTH`], not a stack overflow.
#[test]
fn deep_nesting_is_a_located_error() {
    let n = 100_000;
    let cases = [
        format!("{}1{}", "(".repeat(n), ")".repeat(n)),
        format!("{}1{}", "sqrt(".repeat(n), ")".repeat(n)),
        format!("{}1", "-".repeat(n)),
        vec!["1"; n].join("^"),
        format!("{}1", "+ -".repeat(n)),
    ];
    for text in &cases {
        let e = ev(text).unwrap_err();
        assert_eq!(e.kind, ExprErrorKind::TooDeep, "{}", &text[..20]);
        assert!(e.at > 0 && e.at < 1000, "{}", e.at);
    }
    // At the limit it still evaluates: MAX_DEPTH parentheses, calls or signs (grammar.md:
    // "100 levels"; the expression itself is not one), MAX_DEPTH powers; one more is an
    // error.
    for (open, close) in [("(", ")"), ("sqrt(", ")"), ("-", "")] {
        let nest = |k: usize| format!("{}4{}", open.repeat(k), close.repeat(k));
        assert!(ev(&nest(MAX_DEPTH)).is_ok(), "{open}");
        assert_eq!(
            ev(&nest(MAX_DEPTH + 1)).unwrap_err().kind,
            ExprErrorKind::TooDeep
        );
    }
    let ok = vec!["1"; MAX_DEPTH + 1].join("^");
    assert_eq!(ev(&ok), Ok(1.0));
    let deep = vec!["1"; MAX_DEPTH + 2].join("^");
    assert_eq!(ev(&deep).unwrap_err().kind, ExprErrorKind::TooDeep);
}

#[test]
fn what_looks_like_an_expression() {
    for t in ["$E", "2*3", "(1)", "pi", "1-2", "a/b", "2^2", "-$x"] {
        assert!(looks_like_expression(t), "{t}");
    }
    for t in ["E", "2.1e", "2.1e-", "-", "+", "IMPACT_STEPS", "abc", "1e5"] {
        assert!(!looks_like_expression(t), "{t}");
    }
}

proptest::proptest! {
    /// Any text: a value or a located error, never a panic, and an error's span lies
    /// within the text on character boundaries.
    #[test]
    fn never_panics(s in "[-+*/^()$a-zE_0-9. é,]{0,24}") {
        match ev(&s) {
            Ok(v) => proptest::prop_assert!(v.is_finite()),
            Err(e) => {
                proptest::prop_assert!(e.at + e.len <= s.len());
                proptest::prop_assert!(s.is_char_boundary(e.at) && s.is_char_boundary(e.at + e.len));
            }
        }
    }
}

/// An expression of `t`: its tree's jets against the closed forms of
/// `k t² sin t − e⁻ᵗ/(1 + t) + √t cos t + ln t + |−t|` (k = 4), term by term, to
/// 1e-13 relative (a few roundings per term); parameters are constants; `t` is an
/// unknown name elsewhere; a constant part is still checked as it is read.
#[test]
fn expressions_of_time() {
    let text = "$k*t^2*sin(t) - exp(-t)/(1+t) + sqrt(t)*cos(T) + log(t) + abs(-t)";
    let e = parse_time(text, &params).unwrap();
    assert!(e.depends_on_time());
    for x in [0.3f64, 1.1, 2.7] {
        let (s, c, ex, u, r) = (x.sin(), x.cos(), (-x).exp(), 1.0 + x, x.sqrt());
        let want = [
            4.0 * x * x * s - ex / u + r * c + x.ln() + x,
            4.0 * (2.0 * x * s + x * x * c) + ex / u + ex / (u * u) + 0.5 / r * c - r * s
                + 1.0 / x
                + 1.0,
            4.0 * (2.0 * s + 4.0 * x * c - x * x * s)
                - ex / u
                - 2.0 * ex / (u * u)
                - 2.0 * ex / (u * u * u)
                - 0.25 / (x * r) * c
                - s / r
                - r * c
                - 1.0 / (x * x),
        ];
        let j = e.jet(x);
        for (k, (a, w)) in [j.v, j.d1, j.d2].iter().zip(want).enumerate() {
            assert!(
                (a - w).abs() <= 1e-13 * (1.0 + w.abs()),
                "d{k} at {x}: {a} {w}"
            );
        }
    }
    let c = parse_time("2*$m^0.5", &params).unwrap();
    assert!(!c.depends_on_time());
    assert_eq!(c.jet(1.0), crate::dual::Jet2::constant(6.0));
    let err = ev("2*t").unwrap_err();
    assert_eq!((err.at, err.len), (2, 1));
    assert_eq!(
        err.kind,
        ExprErrorKind::UnknownFunction { name: "t".into() }
    );
    let err = parse_time("t + 1/0", &params).unwrap_err();
    // The quotient's span starts after the `+` (its blank included).
    assert_eq!((err.at, err.len), (3, 4));
    assert!(matches!(err.kind, ExprErrorKind::NotFinite { .. }));
    let err = parse_time("t*$w", &params).unwrap_err();
    assert_eq!((err.at, err.len), (2, 2));
    assert!(parse_time("t(1)", &params).is_err());
}

#[test]
fn names() {
    assert!(is_name("E") && is_name("_x1") && is_name("k_cont"));
    assert!(!is_name("") && !is_name("1a") && !is_name("a-b") && !is_name("é"));
}

// The proof that an expression is finite on a domain (model/expr/proof.rs).

fn parse(text: &str) -> Expr {
    parse_time(text, &params).unwrap()
}

/// The case: a pole between the instants a sampling of [0, 0.1] s at 1001
/// points looks at (t = 0.0123457 s) is found, located at the quotient, on a piece a
/// few ulps wide around it; the same expression on a domain without the pole is shown
/// finite, and so are functions that are finite everywhere though their parts'
/// enclosures are wide (`1/(2 + sin(1000 t))`, `exp(-t^2)`).
#[test]
fn a_pole_between_samples_is_found_and_located() {
    let text = "1/(t-0.0123457)";
    let e = parse(text);
    let b = e.prove_finite(0.0, 0.1, 0).unwrap_err();
    assert!(b.piece.0 <= 0.0123457 && 0.0123457 <= b.piece.1, "{b:?}");
    assert!(b.piece.1 - b.piece.0 < 1e-12, "{b:?}");
    assert_eq!(
        &text[b.at.start as usize..(b.at.start + b.at.len) as usize],
        text
    );
    assert!(e.prove_finite(0.02, 0.1, 2).is_ok());
    for ok in [
        "1/(2 + sin(1000*t))",
        "exp(-t^2)",
        "t^2 - 3*t",
        "sqrt(1 + t^2)",
        "abs(t - 0.5)",
    ] {
        assert!(parse(ok).prove_finite(0.0, 30.0, 2).is_ok(), "{ok}");
    }
}

/// Where the derivatives are asked for: `sqrt(t)` is finite on [0, 1] but its slope is
/// not at 0 (order 1 fails there, located at the call), `t^1.5` has a finite slope and
/// an infinite curvature at 0; `log(t - 1)` is undefined below 1; an overflow
/// (`exp(t)` past 709.78) is found at the exponential.
#[test]
fn derivatives_and_domains() {
    let e = parse("sqrt(t)");
    assert!(e.prove_finite(0.0, 1.0, 0).is_ok());
    let b = e.prove_finite(0.0, 1.0, 1).unwrap_err();
    assert_eq!((b.order, b.piece.0, b.point), (1, 0.0, Some(0.0)), "{b:?}");
    let e = parse("t^1.5");
    assert!(e.prove_finite(0.0, 1.0, 1).is_ok());
    assert_eq!(e.prove_finite(0.0, 1.0, 2).unwrap_err().order, 2);
    let text = "2 + log(t - 1)";
    let b = parse(text).prove_finite(0.0, 3.0, 0).unwrap_err();
    assert_eq!(
        &text[b.at.start as usize..(b.at.start + b.at.len) as usize],
        "log(t - 1)"
    );
    let text = "1 + exp(t)";
    let b = parse(text).prove_finite(700.0, 710.0, 0).unwrap_err();
    assert!(b.piece.0 <= 709.79 && b.piece.1 >= 709.78, "{b:?}");
    assert_eq!(
        &text[b.at.start as usize..(b.at.start + b.at.len) as usize],
        "exp(t)"
    );
}

/// The enclosures hold the f64 jets at sampled points (random expressions' pieces).
#[test]
fn enclosures_hold_the_pointwise_jets() {
    for text in [
        "t^2*sin(t) - 3/(t + 5)",
        "exp(-t)*cos(7*t) + sqrt(t + 1)",
        "(1 + t)^t",
        "abs(sin(t)) * log(2 + t)",
        "-t^3 + 2^t",
    ] {
        let e = parse(text);
        for k in 0..200 {
            let a = 0.05 * k as f64;
            let x = crate::interval::Interval::new(a, a + 0.05);
            let j = e.interval_jet(x, 2).unwrap();
            for s in [0.0, 0.013, 0.031, 0.05] {
                let p = e.jet(a + s);
                assert!(
                    j.v.contains(p.v) && j.d1.contains(p.d1) && j.d2.contains(p.d2),
                    "{text} at {}: {p:?} not in {j:?}",
                    a + s
                );
            }
        }
    }
}

/// A control law's sensors: each distinct sensor once (in order of first appearance, the
/// index its tree nodes carry), names case-insensitive, the argument a constant whole
/// number (`$name` allowed); outside a law a sensor's name is an unknown function.
#[test]
fn law_sensors_are_numbered_once_and_checked() {
    use crate::model::control::Sensor;
    use crate::model::{ElementId, NodeId};
    let (e, s) = parse_law("-$k*(ANGLE(3)-t)-rate(3)+angle(3)*vz(2*$k)", &params).unwrap();
    let sensors: Vec<Sensor> = s.iter().map(|r| r.0).collect();
    assert_eq!(
        sensors,
        [
            Sensor::HingeAngle(ElementId(3)),
            Sensor::HingeRate(ElementId(3)),
            Sensor::Velocity(NodeId(8), 2),
        ]
    );
    // u = -4 (a - t) - r + a vz: ∂u/∂a = -4 + vz, ∂u/∂r = -1, ∂u/∂vz = a.
    let mut g = [0.0; 3];
    let u = e.law(0.5, &[0.2, 1.5, -3.0], Some(&mut g));
    assert_eq!(u, -4.0 * (0.2 - 0.5) - 1.5 + 0.2 * -3.0);
    assert_eq!(g, [-4.0 - 3.0, -1.0, 0.2]);
    for (text, at) in [("angle(0)", 6), ("x(1.5)", 2), ("rate(t)", 5), ("vx 3", 3)] {
        let err = parse_law(text, &params).unwrap_err();
        assert_eq!(err.at, at, "{text}: {err:?}");
    }
    let err = parse_time("angle(1)", &params).unwrap_err();
    assert!(
        matches!(err.kind, ExprErrorKind::UnknownFunction { .. }),
        "{err:?}"
    );
}
