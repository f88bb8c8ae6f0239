//! Beams against closed forms: the Timoshenko cantilever with a tip mass, the convergence
//! of two-node beams, the free-free slender beam.

use super::*;

#[test]
fn one_beam_of_order_12_gives_the_timoshenko_frequencies_of_the_cantilever() {
    let model = load(&deck("cantilever_modes.dat"), &[], 1, None).unwrap();
    let a = modes(&model, About::Initial, 8);
    assert_eq!(a.rigid_modes, 0);
    let f: Vec<f64> = a.modes.iter().map(|m| m.natural_hz).collect();
    eprintln!("cantilever, one beam of order 12: {f:?}");
    for target in TIMOSHENKO_HZ {
        // 1e-6 relative (the target) plus half a unit of the reference's last digit.
        let tol = 1e-6 * target + 0.5e-5;
        let hits: Vec<f64> = f
            .iter()
            .copied()
            .filter(|x| (x - target).abs() <= tol)
            .collect();
        let rel = hits
            .iter()
            .map(|x| (x - target).abs() / target)
            .fold(0.0, f64::max);
        eprintln!(
            "  {target} Hz: {} modes, largest relative difference {rel:.2e}",
            hits.len()
        );
        // Each bending frequency twice: the XY and XZ planes (I2 = I3).
        assert_eq!(hits.len(), 2, "{target} Hz in {f:?}");
    }
    // Conservative, undamped: real frequencies.
    assert!(
        a.modes
            .iter()
            .all(|m| m.damping_ratio == 0.0 && m.kind == ModeKind::Elastic)
    );
}

#[test]
fn two_node_beams_converge_at_order_two() {
    // The same cantilever meshed with k two-node beams (--order 1 --refine k): the
    // relative error of the first two bending frequencies falls as k⁻².
    let mut errors = Vec::new();
    for k in [8, 16, 32] {
        let model = load(&deck("cantilever_modes.dat"), &[], k, Some(1)).unwrap();
        let a = modes(&model, About::Initial, 4);
        // Modes 1–2 are the first bending pair, 3–4 the second.
        let e: Vec<f64> = [(0, 0), (2, 1)]
            .iter()
            .map(|&(m, t)| (a.modes[m].natural_hz - TIMOSHENKO_HZ[t]).abs() / TIMOSHENKO_HZ[t])
            .collect();
        errors.push(e);
    }
    for mode in 0..2 {
        let orders: Vec<f64> = errors
            .windows(2)
            .map(|w| (w[0][mode] / w[1][mode]).log2())
            .collect();
        eprintln!(
            "two-node beams, bending mode {}: errors (k = 8, 16, 32) {:?}, observed orders {orders:?}",
            mode + 1,
            errors.iter().map(|e| e[mode]).collect::<Vec<_>>()
        );
        // Second order: the last observed order within 0.1 of 2 (the next term of the
        // error is O(h⁴): a relative (1/16)² ≈ 4e-3 change of the ratio 4, i.e. 3e-3 in
        // the order; 0.1 leaves room for the O(h³) pre-asymptotic term of mode 2).
        assert!((orders[1] - 2.0).abs() < 0.1, "{orders:?}");
    }
}

/// Free-free slender beam: steel, L = 10 m, A = 9e-4 m², I = 8.3e-8 m² (radius of
/// gyration r = 9.6e-3 m, slenderness L/r = 1041), four elements of order 8.
const FREE_FREE: &str = "TITLE free-free beam
MATERIALS
  1 E 2.1e11 NU 0.3 RHO 7800
SECTIONS
  1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 1.66e-7 K 0.8333333333333334
NODES
  1 0 0 0
  2 10 0 0
ELEMENTS
  1 BEAM 1 2 MAT 1 SEC 1 DIVIDE 4 ORDER 8
ANALYSIS DYNAMIC ALPHA -0.1 STEP 1e-3 END 1
OUTPUT NODES ALL ELEMENTS NONE
";

#[test]
fn free_free_beam_has_six_zero_modes_and_the_euler_bernoulli_frequencies() {
    let model = model_from(FREE_FREE);
    let a = modes(&model, About::Initial, 12);
    let f: Vec<f64> = a.modes.iter().map(|m| m.natural_hz).collect();
    eprintln!("free-free: {f:?}; highest {:.3e} Hz", a.highest_hz);
    assert_eq!(a.rigid_modes, 6, "{f:?}");
    let first_elastic = f[6];
    for m in &a.modes[..6] {
        assert_eq!(m.kind, ModeKind::Rigid);
        assert!(m.natural_hz < 1e-6 * first_elastic);
    }
    // Euler–Bernoulli free-free: ω = (βL)² √(EI/(ρA L⁴)), βL = 4.7300407, 7.8532046,
    // 10.9956078 (each twice: two bending planes).
    let (e, g, rho, area, i, l, kappa) = (
        2.1e11f64,
        2.1e11 / 2.6,
        7800.0f64,
        9e-4f64,
        8.3e-8f64,
        10.0f64,
        5.0f64 / 6.0,
    );
    let r2 = i / area;
    for (n, bl) in [4.7300407f64, 7.8532046, 10.9956078].iter().enumerate() {
        let exact = bl * bl * (e * i / (rho * area * l.powi(4))).sqrt() / (2.0 * PI);
        // Tolerance: the Timoshenko beam (shear, rotary inertia) is softer by
        // ½ (βL)² (r/L)² (1 + E/κG) to first order (Rayleigh–Timoshenko); we allow twice
        // that (3e-5, 8e-5, 1.6e-4 here), the discretisation (order 8, 4 elements) being
        // far smaller, and ask that the beam be the softer.
        let bound = bl * bl * r2 / (l * l) * (1.0 + e / (kappa * g));
        for m in [6 + 2 * n, 7 + 2 * n] {
            let rel = f[m] / exact - 1.0;
            eprintln!(
                "  βL = {bl}: {} Hz vs {exact} Hz, relative {rel:.3e} (bound {bound:.2e})",
                f[m]
            );
            assert!(rel < 0.0 && -rel < bound, "mode {}: {rel:e}", m + 1);
        }
    }
}
