//! The smooth time functions of a deck (`SPLINE`, `SINE`, `COSINE`, `RAMP`, `EXPR`;
//! issue 25 §1): their derivatives, a run that integrates loads scaled by each of them
//! against an independent quadrature, their canonical writing, and located errors.

use mecano::deck::{DeckErrors, load_deck, parse_deck, strip_spans, write_deck};
use mecano::model::{Function, FunctionId, Model};
use mecano::output::History;
use mecano::solver;
use std::f64::consts::PI;
use std::path::Path;

fn deck() -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("decks/smooth_functions.dat");
    load_deck(&path).unwrap_or_else(|e| panic!("{:?}", miette::Report::new(e)))
}

fn function(m: &Model, id: u32) -> &Function {
    &m.functions[&FunctionId(id)].function
}

/// Kane's spin-up angle, its rate and acceleration (Simo & Vu-Quoc 1986), closed form:
/// θ = (ω/T)(t²/2 + (T/2π)²(cos(2πt/T) − 1)), θ̇ = (ω/T)(t − (T/2π) sin(2πt/T)),
/// θ̈ = (ω/T)(1 − cos(2πt/T)) for t ≤ T; θ = ω(t − T/2), θ̇ = ω, θ̈ = 0 after.
fn spin_up(w: f64, period: f64, t: f64) -> [f64; 3] {
    if t > period {
        return [w * (t - period / 2.0), w, 0.0];
    }
    let k = 2.0 * PI / period;
    [
        w / period * (t * t / 2.0 + ((k * t).cos() - 1.0) / (k * k)),
        w / period * (t - (k * t).sin() / k),
        w / period * (1.0 - (k * t).cos()),
    ]
}

/// The deck's EXPR (the spin-up angle joined at T by `abs`) against the closed form, on
/// both sides of T and at T itself: 1e-13 of the scale ω T (a few tens of roundings);
/// C² at T (θ̈ → 0 from both sides).
#[test]
fn the_expression_is_the_spin_up_profile() {
    let m = deck();
    let f = function(&m, 6);
    assert!(f.has_derivatives());
    let (w, period) = (4.0, 1.5);
    for t in [0.0, 0.1, 0.37, 0.75, 1.2, 1.4999, 1.5, 1.5001, 1.9, 3.0] {
        let got = f.derivatives(t).unwrap();
        let want = spin_up(w, period, t);
        for k in 0..3 {
            assert!(
                (got[k] - want[k]).abs() <= 1e-13 * w * period * 4.0,
                "d{k} at {t}: {} vs {}",
                got[k],
                want[k]
            );
        }
        assert_eq!(f.eval(t), got[0]);
    }
    assert!(f.breakpoints().is_empty());
    // The deck's other functions have their derivatives (the model's unit tests check
    // them against differences and closed forms).
    for id in 1..=5 {
        assert!(function(&m, id).has_derivatives(), "function {id}");
    }
    assert_eq!(function(&m, 3).breakpoints(), vec![0.25]);
    assert_eq!(function(&m, 5).breakpoints(), vec![0.5, 1.5]);
    let Function::Harmonic { omega, .. } = function(&m, 3) else {
        panic!("SINE")
    };
    assert_eq!(*omega, 4.0 * PI, "FREQ 2 Hz is ω = 4π");
}

/// Cumulative `∫₀ᵗ f` and `∫₀ᵗ s f(s) ds` at the grid `k h` by Simpson's rule on each step
/// (the functions' kinks fall on grid points: error ~h⁵ max|f⁗|/2880 per step, 1e-16).
fn moments(f: &Function, h: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut i0, mut i1) = (vec![0.0], vec![0.0]);
    for k in 0..n {
        let (a, b) = (k as f64 * h, (k + 1) as f64 * h);
        let mid = 0.5 * (a + b);
        // One-sided values at the step's ends: the kinks sit on grid points.
        let (fa, fm, fb) = (f.eval(a + 1e-12), f.eval(mid), f.eval(b - 1e-12));
        i0.push(i0[k] + h / 6.0 * (fa + 4.0 * fm + fb));
        i1.push(i1[k] + h / 6.0 * (a * fa + 4.0 * mid * fm + b * fb));
    }
    (i0, i1)
}

/// Each 1 kg particle pushed by 1 N × f(t) from rest: x(t) = t ∫₀ᵗ f − ∫₀ᵗ s f(s) ds.
/// HHT with α = 0 is the trapezoidal rule for this linear problem: the velocity is the
/// trapezoid of f (error ≤ t h² max|f̈|/12) and the position the trapezoid of the velocity
/// (≤ t h² max|ḟ|/12 + the velocity's error integrated, t² h² max|f̈|/24). The maxima of
/// |ḟ|, |f̈| are taken at every 1 ms with a 10 % margin (the functions vary over 0.1 s
/// or more).
#[test]
fn loads_scaled_by_each_function_integrate_to_the_quadrature() {
    let m = deck();
    let mut hist = History::new(1);
    let report = solver::run(&m, &mut hist).expect("runs");
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let h = 1e-3;
    let n = 2000;
    assert_eq!(hist.t.len(), n + 1);
    for id in 1..=6u32 {
        let f = function(&m, id);
        let (mut d1, mut d2) = (0.0f64, 0.0f64);
        for k in 0..=n {
            let [_, a, b] = f.derivatives(k as f64 * h).unwrap();
            d1 = d1.max(a.abs());
            d2 = d2.max(b.abs());
        }
        let (d1, d2) = (1.1 * d1, 1.1 * d2);
        let (i0, i1) = moments(f, h, n);
        let node = m.nodes.get_index_of(&mecano::model::NodeId(id)).unwrap();
        let mut worst: f64 = 0.0;
        for (k, t) in hist.t.iter().enumerate() {
            let kk = (t / h).round() as usize;
            assert!((t - kk as f64 * h).abs() < 1e-9, "steps on the grid");
            let want = t * i0[kk] - i1[kk];
            let got = hist.nodes[k][node].x.x;
            let tol = h * h * (t * d1 / 12.0 + t * t * d2 / 24.0) + 1e-12;
            assert!(
                (got - want).abs() <= tol,
                "function {id} at t = {t}: x = {got}, quadrature {want}, tol {tol:e}"
            );
            worst = worst.max((got - want).abs() / tol);
        }
        assert!(
            worst > 1e-3,
            "function {id}: the bound is not vacuous ({worst})"
        );
    }
}

/// The canonical writer writes every kind so that it reads back to the same model, and
/// its text is a fixed point (`decks/smooth_functions.dat` is also in deck_roundtrip's
/// list); an EXPR keeps its text, a SINE's FREQ becomes OMEGA.
#[test]
fn functions_round_trip() {
    let mut first = deck();
    let text = write_deck(&first);
    assert!(
        text.contains(" SPLINE 0.0 0.0 1.0 0.5 2.0 1.0 SLOPES 0.0 0.0"),
        "{text}"
    );
    assert!(
        text.contains("3 SINE 0.1 OMEGA 12.566370614359172 START 0.25"),
        "{text}"
    );
    assert!(text.contains("6 EXPR ($ws/$T*"), "{text}");
    let mut second = parse_deck(&text, "written").unwrap();
    strip_spans(&mut first);
    strip_spans(&mut second);
    assert_eq!(first, second);
    assert_eq!(write_deck(&second), text);
}

fn errors_of(deck: &str) -> DeckErrors {
    match std::panic::catch_unwind(|| parse_deck(deck, "test.dat")) {
        Ok(Ok(_)) => panic!("deck should be rejected:\n{deck}"),
        Ok(Err(e)) => e,
        Err(_) => panic!("parse_deck panicked on:\n{deck}"),
    }
}

/// Bad FUNCTIONS cards: one located error each (line, column of its first character),
/// with what was expected.
#[test]
fn bad_functions_are_located_errors() {
    let a = "ANALYSIS DYNAMIC STEP 0.1 END 2\n";
    // The card is on line 4.
    let f = |card: &str| format!("PARAMETERS\n w 2\nFUNCTIONS\n{card}\n{a}");
    let cases: Vec<(String, usize, usize, &str)> = vec![
        (f(" 1 SPLINE 0 0"), 4, 2, "at least two points, found 1"),
        (f(" 1 SPLINE 0 0 1"), 4, 2, "come in pairs"),
        (f(" 1 SPLINE 0 0 1 1 1 2"), 4, 19, "times must increase"),
        (
            f(" 1 SPLINE 0 0 2 1 1 2"),
            4,
            19,
            "point 2 does not come after point 1",
        ),
        (
            f(" 1 SPLINE 0 0 1 1 SLOPES 0"),
            4,
            27,
            "the slope at the last point",
        ),
        (f(" 1 SPLINE 0 0 1 1 SLOPES 0 0 0"), 4, 30, "unexpected `0`"),
        (
            f(" 1 SINE 1 PHASE 0.1"),
            4,
            20,
            "FREQ <Hz> or OMEGA <rad/s>",
        ),
        (f(" 1 SINE 1 FREQ 1 OMEGA 2"), 4, 18, "OMEGA"),
        (f(" 1 COSINE 1 FREQ 0"), 4, 18, "> 0 Hz"),
        (f(" 1 SINE 1 FREQ 1 SPEED 3"), 4, 18, "unexpected `SPEED`"),
        (f(" 1 RAMP 1 0 1 1"), 4, 13, "> t0"),
        (f(" 1 RAMP 1 0 2"), 4, 14, "the ramp's end value f1"),
        (f(" 1 EXPR 2*tan(t)"), 4, 11, "unknown function `tan`"),
        (f(" 1 EXPR 2*$v*t"), 4, 11, "undefined parameter `v`"),
        (f(" 1 EXPR (2*t"), 4, 13, "`)`"),
        (f(" 1 EXPR"), 4, 8, "an expression of t"),
        (f(" 1 EXPR t+1/0"), 4, 11, "not a finite number"),
        (
            f(" 1 EXPR sqrt(t)"),
            4,
            9,
            "first derivative is not finite at t = 0 s",
        ),
        (
            f(" 1 EXPR log(1.5-t)"),
            4,
            9,
            "value is not finite at t = 1.5 s",
        ),
        // A pole between the 1001 instants the old sampling checked (issue 35).
        (
            f(" 1 EXPR 1+1/(t-0.0123457)"),
            4,
            11,
            "value could not be shown finite (its enclosure stays unbounded) at t = 0.0123457 s",
        ),
        (f(" 1 TABLE 0 0 1 sin(t)"), 4, 20, "unknown function `t`"),
        (f(" 1 WAVE 1"), 4, 4, "expected one of TABLE, CONSTANT"),
    ];
    let mut wrong = Vec::new();
    for (deck, line, col, msg) in cases {
        let e = errors_of(&deck);
        let texts: Vec<String> = e.errors().iter().map(|x| x.to_string()).collect();
        let at = e.line_col(0);
        if texts.len() != 1 || at != Some((line, col)) || !texts[0].contains(msg) {
            wrong.push(format!(
                "{}: {at:?} {texts:?}",
                deck.lines().nth(3).unwrap_or("")
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// An expression that does not depend on `t` is a constant function; `t` in a static
/// analysis is its load-step parameter in [0, 1].
#[test]
fn constant_expressions_and_static_spans() {
    let m = parse_deck(
        "PARAMETERS\n w 2\nFUNCTIONS\n 1 EXPR 3*$w\n 2 EXPR log(2-t)\nANALYSIS STATIC\n",
        "t.dat",
    )
    .unwrap();
    assert_eq!(function(&m, 1).derivatives(7.0), Some([6.0, 0.0, 0.0]));
    assert!(function(&m, 2).derivatives(1.0).unwrap()[0].abs() < 1e-16);
}

/// The deck `name` with `from` replaced by `to` (one occurrence, which must exist).
fn edited(name: &str, from: &str, to: &str) -> String {
    let text =
        std::fs::read_to_string(format!("{}/decks/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap();
    assert!(text.contains(from), "{name} has no `{from}`");
    text.replacen(from, to, 1)
}

/// The first error of a deck (a refused element also leaves its references undefined):
/// its text and (line, column).
fn one_error(deck: &str) -> (String, Option<(usize, usize)>) {
    let e = errors_of(deck);
    (e.errors()[0].to_string(), e.line_col(0))
}

/// Issue 35, "functions proven finite": an EXPR used as a SPRING's force–deflection law is
/// shown finite on the deflections the spring can reach ([−L_ref, D], here [−1, 1] m for
/// the 1 m spring of `spring_mass.dat`, whose nodes span 1 m): a pole at δ = 0.3 m, which
/// the run crosses only if stretched that far, is refused and located at the quotient,
/// naming the deflection; a law finite there (a cubic) is accepted. The old check read
/// such a curve over [0, END] as if it were a time function.
#[test]
fn a_spring_law_is_proven_finite_on_its_deflections() {
    let with = |law: &str| {
        edited(
            "spring_mass.dat",
            "ELEMENTS\n  1  SPRING 1 2  K $k  C $c",
            &format!("FUNCTIONS\n  7 EXPR {law}\nELEMENTS\n  1  SPRING 1 2  K $k  C $c  CURVE 7"),
        )
    };
    let (msg, at) = one_error(&with("5/(t-0.3)"));
    assert!(
        msg.contains("`5/(t-0.3)`") && msg.contains("deflection = 0.3 m"),
        "{msg}"
    );
    assert_eq!(at, Some((17, 10)), "{msg}");
    parse_deck(&with("1e3*t^3"), "s.dat").expect("a cubic law is finite on [-1, 1] m");
}

/// A driver's law whose velocity jumps is refused, located at the `abs` whose kink it is
/// (`0.3 (|t − 0.5| − 0.5)`: ḟ jumps from −0.3 to 0.3 at 0.5 s, by 0.6, measured by interval arithmetic on
/// both sides), and so is a SINE started inside the run (its velocity jumps by A ω); kinks
/// that cancel (the spin-up law of `decks/benchmarks/spinup.dat`, `min(t, T)` written with
/// `abs`) are not, nor is a HAVERSINE.
#[test]
fn a_driver_whose_velocity_jumps_is_refused() {
    let kinked = edited(
        "driven_arm.dat",
        "  1 HAVERSINE 0 $T",
        "  1 EXPR 0.3*(abs(t-0.5)-0.5)",
    );
    let (msg, at) = one_error(&kinked);
    assert!(
        msg.contains("velocity jumps by 6.000000e-1") && msg.contains("t = 0.5 s"),
        "{msg}"
    );
    assert!(msg.contains("abs(t-0.5)"), "{msg}");
    assert_eq!(at, Some((19, 15)), "{msg}");
    let started = edited(
        "driven_arm.dat",
        "  1 HAVERSINE 0 $T",
        "  1 SINE 0.5 FREQ 1 START 0.2",
    );
    let (msg, _) = one_error(&started);
    assert!(msg.contains("START 0.2"), "{msg}");
    parse_deck(
        &std::fs::read_to_string(format!(
            "{}/decks/benchmarks/spinup.dat",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap(),
        "spinup.dat",
    )
    .expect("kinks that cancel are no jump");
}

/// `CLEARANCE … LAW LN K e EXPONENT n`: an exponent outside the derived range (where
/// `K δⁿ` underflows to no force over the penetrations that matter: the 1e308 let
/// the journal 0.7 mm through its 0.5 mm clearance with no force) is refused, located,
/// with the range; 1.5 and 10 are accepted. (1e308 itself is refused earlier, as every
/// magnitude beyond 1e100: `hostile::loop_bounds_and_magnitudes_are_refused_at_their_field`;
/// 1000 is a magnitude the deck allows and the law's range does not.)
#[test]
fn a_clearance_exponent_beyond_its_derived_range_is_refused() {
    let law = "LAW LN 1e10 0.8";
    let (msg, at) = one_error(&edited(
        "clearance_impact.dat",
        law,
        "LAW LN 1e10 0.8 EXPONENT 1000",
    ));
    assert!(
        msg.contains("EXPONENT") && msg.contains("in [0.000, 16.759]"),
        "{msg}"
    );
    assert!(at.is_some_and(|(l, _)| l == 15), "{at:?}");
    for ok in ["1.5", "10"] {
        parse_deck(
            &edited("clearance_impact.dat", law, &format!("{law} EXPONENT {ok}")),
            "c.dat",
        )
        .unwrap_or_else(|e| panic!("EXPONENT {ok}: {e}"));
    }
}
