//! Tests of the smooth kinds: spline, harmonic, ramp (the expression's are in
//! `model/expr.rs`, `deck/expr.rs` and `tests/functions.rs`).

use super::{CubicSpline, Function, SplineError};

const EPS: f64 = f64::EPSILON;

/// Checks `ḟ` and `f̈` of `f` at `t` against central differences of `f` and of `ḟ` with
/// step `d`, with tolerances derived from the difference formula: truncation
/// `d²/6 · max|f⁽ᵏ⁺²⁾|` plus round-off `2 · 8ε · max|f⁽ᵏ⁾| / d` (each evaluation is a few
/// roundings: 8ε of its magnitude). `bounds` = `[max|f|, max|ḟ|, max|f⃛|, max|f⁗|]`
/// near `t`.
fn check_differences(f: &Function, t: f64, d: f64, bounds: [f64; 4]) {
    let [m0, m1, m3, m4] = bounds;
    let at = |t: f64| f.derivatives(t).expect("smooth");
    let [v, v1, v2] = at(t);
    assert_eq!(v, f.eval(t), "eval and derivatives agree at {t}");
    let fd1 = (at(t + d)[0] - at(t - d)[0]) / (2.0 * d);
    let fd2 = (at(t + d)[1] - at(t - d)[1]) / (2.0 * d);
    let tol1 = d * d / 6.0 * m3 + 16.0 * EPS * m0 / d;
    let tol2 = d * d / 6.0 * m4 + 16.0 * EPS * m1 / d;
    assert!(
        (v1 - fd1).abs() <= tol1,
        "f' at {t}: {v1} vs {fd1} (tol {tol1:e})"
    );
    assert!(
        (v2 - fd2).abs() <= tol2,
        "f'' at {t}: {v2} vs {fd2} (tol {tol2:e})"
    );
}

/// A clamped spline reproduces a cubic exactly when given the cubic's end slopes (the
/// cubic meets every condition and the spline is unique); a natural one reproduces a
/// straight line. Agreement to round-off: 1e-13 of the values' scale (~10).
#[test]
fn spline_reproduces_cubics_and_lines() {
    let p = |t: f64| {
        [
            1.0 - 2.0 * t + 0.5 * t * t + 0.3 * t * t * t,
            -2.0 + t + 0.9 * t * t,
            1.0 + 1.8 * t,
        ]
    };
    let knots = [-1.0, 0.2, 0.5, 1.7, 2.0, 3.1];
    let pts: Vec<(f64, f64)> = knots.iter().map(|&t| (t, p(t)[0])).collect();
    let s = CubicSpline::new(pts, Some((p(-1.0)[1], p(3.1)[1]))).unwrap();
    for k in 0..=100 {
        let t = -1.0 + 4.1 * k as f64 / 100.0;
        let (got, want) = (s.derivatives(t), p(t));
        for i in 0..3 {
            assert!((got[i] - want[i]).abs() < 1e-13 * 20.0, "d{i} at {t}");
        }
    }
    let line: Vec<(f64, f64)> = knots.iter().map(|&t| (t, 3.0 - 0.5 * t)).collect();
    let s = CubicSpline::new(line, None).unwrap();
    for t in [-3.0, -1.0, 0.33, 2.0, 3.1, 7.0] {
        let [v, v1, v2] = s.derivatives(t);
        assert!((v - (3.0 - 0.5 * t)).abs() < 1e-14 * 10.0 && (v1 + 0.5).abs() < 1e-14);
        assert!(v2.abs() < 1e-14, "{v2}");
    }
}

/// Interpolation at the knots, continuity of S, S′, S″ across them (a step ±δ each side
/// changes S⁽ᵏ⁾ by at most 2δ max|S⁽ᵏ⁺¹⁾| plus round-off), the end conditions, and the
/// derivatives against differences inside the intervals (S⁗ = 0 there; |S⃛| ≤
/// max |ΔM/h|).
#[test]
fn spline_is_c2_and_interpolates() {
    let pts = vec![(0.0, 0.0), (0.5, 0.8), (1.0, 1.0), (2.5, -0.4), (3.0, 0.2)];
    for slopes in [None, Some((0.0, 1.5))] {
        let s = CubicSpline::new(pts.clone(), slopes).unwrap();
        let m = s.moments().to_vec();
        let m2 = m.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let m3 = (0..m.len() - 1)
            .map(|i| ((m[i + 1] - m[i]) / (pts[i + 1].0 - pts[i].0)).abs())
            .fold(0.0f64, f64::max);
        // |S′| ≤ its value at the knots plus the swing of S″ over an interval.
        let m1 = (0..=300)
            .map(|k| s.derivatives(3.0 * k as f64 / 300.0)[1].abs())
            .fold(0.0f64, f64::max)
            + m2 * 0.01;
        let m0 = 2.0;
        for (i, &(t, v)) in pts.iter().enumerate() {
            assert!((s.derivatives(t)[0] - v).abs() <= 4.0 * EPS, "S({t})");
            let delta = 1e-9;
            let (l, r) = (s.derivatives(t - delta), s.derivatives(t + delta));
            let bound = [m1, m2, m3];
            // A clamped spline's S″ jumps to 0 beyond its end points (a breakpoint).
            let end = i == 0 || i == pts.len() - 1;
            let orders = if end && slopes.is_some() { 2 } else { 3 };
            for k in 0..orders {
                let tol = 2.0 * delta * bound[k] + 64.0 * EPS * [m0, m1, m2][k];
                assert!(
                    (l[k] - r[k]).abs() <= tol,
                    "jump of S^{k} at {t}: {l:?} {r:?}"
                );
            }
        }
        match slopes {
            None => assert!(m[0] == 0.0 && m[4] == 0.0, "natural: S'' = 0 at the ends"),
            Some((s0, sn)) => {
                assert!((s.derivatives(0.0)[1] - s0).abs() < 1e-14);
                assert!((s.derivatives(3.0)[1] - sn).abs() < 1e-14);
            }
        }
        let f = Function::Spline(s);
        for t in [0.1, 0.7, 1.9, 2.8] {
            check_differences(&f, t, 1e-5, [m0, m1, m3, 0.0]);
        }
        let b = f.breakpoints();
        assert_eq!(b.len(), if slopes.is_some() { 2 } else { 0 });
        // Beyond the ends: straight lines of the end value and slope.
        let [v, v1, v2] = f.derivatives(4.0).unwrap();
        let [ve, ve1, _] = f.derivatives(3.0).unwrap();
        assert!((v - (ve + ve1)).abs() < 1e-14 && v1 == ve1 && v2 == 0.0);
    }
}

#[test]
fn spline_errors() {
    assert_eq!(
        CubicSpline::new(vec![(0.0, 1.0)], None),
        Err(SplineError::TooFewPoints { count: 1 })
    );
    assert_eq!(
        CubicSpline::new(vec![(0.0, 1.0), (1.0, 2.0), (1.0, 3.0)], None),
        Err(SplineError::NotIncreasing { index: 2 })
    );
    assert_eq!(
        CubicSpline::new(vec![(0.0, 1.0), (-1.0, 2.0)], None),
        Err(SplineError::NotIncreasing { index: 1 })
    );
    assert_eq!(
        CubicSpline::new(vec![(0.0, 1.0), (1.0, f64::NAN)], None),
        Err(SplineError::NotFinite)
    );
}

/// The harmonic: closed-form values, derivatives against differences (|f⁽ᵏ⁾| ≤ A ωᵏ),
/// zero before its start, its start a breakpoint, and its magnitude.
#[test]
fn harmonic_values_and_derivatives() {
    let (a, w) = (0.3, 2.0 * std::f64::consts::PI * 1.5);
    for cosine in [false, true] {
        let f = Function::Harmonic {
            cosine,
            amplitude: a,
            omega: w,
            phase: 0.4,
            start: Some(0.5),
        };
        assert_eq!(f.derivatives(0.49), Some([0.0, 0.0, 0.0]));
        let x = w * (0.8 - 0.5) + 0.4;
        let want = if cosine { a * x.cos() } else { a * x.sin() };
        assert!((f.eval(0.8) - want).abs() < 1e-15);
        for t in [0.51, 0.8, 1.37, 2.0] {
            check_differences(&f, t, 1e-5, [a, a * w, a * w.powi(3), a * w.powi(4)]);
        }
        assert_eq!(f.breakpoints(), vec![0.5]);
        assert_eq!(f.max_abs(0.0, 1.0), a);
    }
    let f = Function::Harmonic {
        cosine: false,
        amplitude: 2.0,
        omega: 1.0,
        phase: 0.0,
        start: None,
    };
    assert!(f.breakpoints().is_empty());
    assert_eq!(f.derivatives(0.0), Some([0.0, 2.0, -0.0]));
}

/// The quintic ramp: end values, mid value, peak velocity 1.875 Δ/T at mid-ramp, zero
/// velocity and acceleration at both ends (C²), derivatives against differences
/// (|f⃛| ≤ 60 Δ/T³, |f⁗| ≤ 360 Δ/T⁴), breakpoints at its ends.
#[test]
fn ramp_is_c2_with_known_peaks() {
    let (t0, f0, t1, f1) = (1.0, -0.5, 3.0, 1.5);
    let f = Function::Ramp { t0, f0, t1, f1 };
    let (dv, span) = (f1 - f0, t1 - t0);
    assert_eq!(f.derivatives(0.0), Some([f0, 0.0, 0.0]));
    assert_eq!(f.derivatives(t0), Some([f0, 0.0, 0.0]));
    assert_eq!(f.derivatives(t1), Some([f1, 0.0, 0.0]));
    assert_eq!(f.derivatives(9.0), Some([f1, 0.0, 0.0]));
    let [v, v1, v2] = f.derivatives(2.0).unwrap();
    assert!((v - 0.5).abs() < 1e-15 && (v1 - 1.875 * dv / span).abs() < 1e-15);
    assert!(v2.abs() < 1e-15);
    let s = (3.0 - 3f64.sqrt()) / 6.0;
    let peak = f.derivatives(t0 + s * span).unwrap()[2];
    assert!((peak - 10.0 / 3f64.sqrt() * dv / (span * span)).abs() < 1e-14);
    let m = [
        1.5,
        1.875 * dv / span,
        60.0 * dv / span.powi(3),
        360.0 * dv / span.powi(4),
    ];
    for t in [1.1, 1.5, 2.2, 2.9] {
        check_differences(&f, t, 1e-5, m);
    }
    assert_eq!(f.breakpoints(), vec![t0, t1]);
    assert_eq!(f.max_abs(0.0, 5.0), 1.5);
    assert!(f.first_non_finite(0.0, 5.0).is_none());
}
