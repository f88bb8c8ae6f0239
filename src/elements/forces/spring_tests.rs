//! Unit tests of the SPRING element: exact tangent, objectivity, energy consistent with the
//! force, the curve's integral, and the refusal of zero length.

use super::*;
use crate::elements::testing::*;
use crate::rotation;

fn table() -> Function {
    // A stiffening curve: slope 100 N/m to 0.01 m, 400 N/m beyond, and softer in compression.
    Function::Table(vec![(-0.05, -2.0), (0.0, 0.0), (0.01, 1.0), (0.05, 17.0)])
}

fn spring(length: SpringLength, curve: bool) -> Spring {
    let data = SpringData {
        stiffness: 250.0,
        damping: 3.0,
        length,
        curve: curve.then_some(crate::model::FunctionId(1)),
    };
    let x0 = [Vector3::new(0.1, 0.2, 0.3), Vector3::new(0.4, -0.2, 0.5)];
    Spring::new(ElementId(1), [0, 1], x0, &data, curve.then(table)).expect("spring")
}

/// The iteration matrix against central differences of the residual (dynamic and static
/// contexts), linear, preloaded and with a TABLE curve (random states keep δ inside one
/// segment of the table with probability ~1, where the curve is linear): tolerance 1e-6 of
/// the largest entry (ε = 1e-6: truncation O(ε²), round-off O(1e-10) relative).
#[test]
fn tangent_matches_finite_differences() {
    let x0 = [Vector3::new(0.1, 0.2, 0.3), Vector3::new(0.4, -0.2, 0.5)];
    for (k, (len, curve)) in [
        (SpringLength::Initial, false),
        (SpringLength::Free(0.3), false),
        (SpringLength::Preload(-40.0), false),
        (SpringLength::Initial, true),
    ]
    .into_iter()
    .enumerate()
    {
        let s = spring(len, curve);
        let st = random_states(&x0, 0.01, 0.3, 21 + k as u64);
        check_tangent(&s, &dyn_ctx(), &st, &[], 1e-6);
        check_tangent(&s, &static_ctx(), &st, &[], 1e-6);
        check_objectivity(&s, &dyn_ctx(), &st, 1e-12);
    }
}

/// The elastic tension is the derivative of the strain energy along the line (central
/// difference of U over ±1e-6 m: error O(1e-12 F'')), with and without the curve; the
/// damper's dissipated power is c ℓ̇².
#[test]
fn energy_is_the_potential_of_the_force() {
    for curve in [false, true] {
        let s = spring(SpringLength::Preload(7.0), curve);
        let x0 = [Vector3::new(0.1, 0.2, 0.3), Vector3::new(0.4, -0.2, 0.5)];
        let e = (x0[1] - x0[0]).normalize();
        let g = Vector3::zeros();
        for stretch in [-0.03, 0.004, 0.02] {
            let mut st = vec![
                NodeState::at_rest(x0[0]),
                NodeState::at_rest(x0[1] + e * stretch),
            ];
            let h = 1e-6;
            let u = |st: &mut Vec<NodeState>, d: f64| {
                st[1].x = x0[1] + e * (stretch + d);
                s.energies(st, &g).strain
            };
            let du = (u(&mut st, h) - u(&mut st, -h)) / (2.0 * h);
            st[1].x = x0[1] + e * stretch;
            let row = s.output_row(&dyn_ctx(), &st, &[]);
            assert!(
                (row[3] - du).abs() < 1e-6 * (1.0 + du.abs()),
                "{} vs {du}",
                row[3]
            );
            st[1].v = e * 0.5 + Vector3::new(0.0, 0.0, 0.3);
            let rate = e.dot(&st[1].v);
            assert!((s.dissipated_power(&st) - 3.0 * rate * rate).abs() < 1e-12);
        }
    }
}

/// The TABLE's integral in closed form: ∫₀^0.03 = 0.5·0.01·1 + (1 + 9)/2·0.02 = 0.105,
/// ∫₀^−0.05 = −(−2·0.05/2) = 0.05, and beyond the last point the constant 17.
#[test]
fn table_integral_is_exact() {
    let f = table();
    for (x, want) in [
        (0.03, 0.105),
        (-0.05, 0.05),
        (0.06, 0.005 + 0.5 * (1.0 + 17.0) * 0.04 + 17.0 * 0.01),
    ] {
        let got = curve_integral(&f, x);
        assert!((got - want).abs() < 1e-15, "∫ to {x}: {got} vs {want}");
    }
    let (v, d) = curve_value(&f, 0.03);
    assert!(
        (v - 9.0).abs() < 1e-14 && (d - 400.0).abs() < 1e-10,
        "{v} {d}"
    );
    assert_eq!(curve_value(&f, 0.2), (17.0, 0.0));
    let s = Function::Constant(2.0);
    assert!((curve_integral(&s, 0.3) - 0.6).abs() < 1e-14);
}

/// Nodes that meet, or pass through each other since the last accepted step: an infinite
/// residual (never a NaN), finite energies and outputs, and a diagnosis naming the spring.
#[test]
fn zero_length_is_refused_without_nan() {
    let s = spring(SpringLength::Free(0.2), false);
    let x0 = [Vector3::new(0.1, 0.2, 0.3), Vector3::new(0.4, -0.2, 0.5)];
    for x2 in [x0[0], x0[0] - (x0[1] - x0[0]) * 0.1] {
        let st = vec![NodeState::at_rest(x0[0]), NodeState::at_rest(x2)];
        let mut out = Local::new(12);
        s.evaluate(&dyn_ctx(), &st, &[], true, &mut out);
        assert!(out.res.iter().all(|v| !v.is_nan()));
        assert!(out.res.iter().any(|v| v.is_infinite()));
        assert!(out.tan.iter().all(|v| v.is_finite()));
        assert!(s.energies(&st, &Vector3::zeros()).strain.is_finite());
        assert!(
            s.output_row(&dyn_ctx(), &st, &[])
                .iter()
                .all(|v| v.is_finite())
        );
        assert!(s.dissipated_power(&st).is_finite());
        let d = s.diagnose(&st).expect("a diagnosis");
        assert!(
            d.contains("element 1 (SPRING)") && d.contains("zero length"),
            "{d}"
        );
    }
    let ok = vec![NodeState::at_rest(x0[0]), NodeState::at_rest(x0[1])];
    assert!(s.diagnose(&ok).is_none());
    // Coincident nodes at t = 0 are refused when the element is built.
    let data = SpringData {
        stiffness: 1.0,
        damping: 0.0,
        length: SpringLength::Free(1.0),
        curve: None,
    };
    assert!(Spring::new(ElementId(3), [0, 1], [x0[0], x0[0]], &data, None).is_err());
    // The committed direction follows a spring turned by 170° in small steps: no refusal.
    let mut s = spring(SpringLength::Initial, false);
    let d0 = x0[1] - x0[0];
    for i in 1..=17 {
        let q = rotation::exp(&(Vector3::z() * (0.1 * i as f64)));
        let st = vec![
            NodeState::at_rest(x0[0]),
            NodeState::at_rest(x0[0] + q * d0),
        ];
        assert!(s.diagnose(&st).is_none(), "step {i}");
        s.commit(&dyn_ctx(), &st, &[]);
    }
}
