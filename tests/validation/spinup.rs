//! Kane's spin-up beam (issue 25 §6; decks/benchmarks/spinup.dat, docs/benchmarks.md):
//! the tip's transverse deflection in the rotating frame against an independent route
//! computed here, the linearised rotating-frame Euler–Bernoulli beam with centrifugal
//! stiffening, by Galerkin on clamped-free modes and RK4; and the known failure of the
//! same model without the stiffening at ω_s = 10 rad/s.

use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

/// The benchmark's beam (Simo & Vu-Quoc 1986): L, EI, ρA.
const L: f64 = 10.0;
const EI: f64 = 1.4e4;
const RHO_A: f64 = 1.2;
/// Spin-up time, s.
const T_S: f64 = 15.0;

/// Kane's hub angle: θ, θ̇, θ̈ (closed form; `θ = (ω/T)(t²/2 + (T/2π)²(cos(2πt/T) − 1))`
/// up to T, `ω(t − T/2)` after).
fn hub(w: f64, t: f64) -> [f64; 3] {
    if t > T_S {
        return [w * (t - T_S / 2.0), w, 0.0];
    }
    let k = 2.0 * PI / T_S;
    [
        w / T_S * (t * t / 2.0 + ((k * t).cos() - 1.0) / (k * k)),
        w / T_S * (t - (k * t).sin() / k),
        w / T_S * (1.0 - (k * t).cos()),
    ]
}

/// The `k`-th root (from 1) of `cos z cosh z + 1 = 0` (clamped-free beam), by Newton
/// from `(2k − 1)π/2`.
fn clamped_free_root(k: usize) -> f64 {
    let mut z = (2 * k - 1) as f64 * PI / 2.0 + if k == 1 { 0.3 } else { 0.0 };
    for _ in 0..100 {
        let g = z.cos() * z.cosh() + 1.0;
        let dg = -z.sin() * z.cosh() + z.cos() * z.sinh();
        let dz = g / dg;
        z -= dz;
        if dz.abs() < 1e-15 * z {
            break;
        }
    }
    z
}

/// Clamped-free mode `k`: `[φ, φ′, φ″]` at `x`,
/// `φ = cosh βx − cos βx − σ(sinh βx − sin βx)`, `σ = (cosh βL + cos βL)/(sinh βL + sin βL)`.
fn mode(k: usize, x: f64) -> [f64; 3] {
    let b = clamped_free_root(k) / L;
    let bl = b * L;
    let s = (bl.cosh() + bl.cos()) / (bl.sinh() + bl.sin());
    let (ch, c, sh, sn) = ((b * x).cosh(), (b * x).cos(), (b * x).sinh(), (b * x).sin());
    [
        ch - c - s * (sh - sn),
        b * (sh + sn - s * (ch - c)),
        b * b * (ch + c - s * (sh + sn)),
    ]
}

/// The Galerkin model `M q̈ + (K + θ̇² (G − M)) q = −θ̈ b` of the linearised transverse
/// motion `v(x, t) = Σ qₖ φₖ(x)` in the rotating frame:
/// `ρA (v̈ + θ̈ x − θ̇² v) + EI v⁗ − (N v′)′ = 0`, `N = ρA θ̇² (L² − x²)/2` the centrifugal
/// tension (the stiffening); Coriolis coupling to the axial motion and the axial stretch
/// are left out (relative size ρA ω² L²/EA ≤ 4e-4 at ω = 10).
/// `M = ρA∫φφ`, `K = EI∫φ″φ″`, `G = ∫ρA (L² − x²)/2 φ′φ′`, `b = ρA∫xφ`; quadrature by 40
/// panels of 10-point Gauss (exact to round-off for these entire functions).
struct Galerkin {
    m_inv: DMatrix<f64>,
    k: DMatrix<f64>,
    g: DMatrix<f64>,
    m: DMatrix<f64>,
    b: DVector<f64>,
    tip: DVector<f64>,
}

fn galerkin(modes: usize) -> Galerkin {
    let (gx, gw) = mecano::lagrange::gauss(10);
    let panels = 40;
    let (mut m, mut k, mut g) = (
        DMatrix::zeros(modes, modes),
        DMatrix::zeros(modes, modes),
        DMatrix::zeros(modes, modes),
    );
    let mut b = DVector::zeros(modes);
    let hp = L / panels as f64;
    for p in 0..panels {
        for (xi, wi) in gx.iter().zip(&gw) {
            let x = hp * (p as f64 + 0.5 * (xi + 1.0));
            let w = 0.5 * hp * wi;
            let phi: Vec<[f64; 3]> = (1..=modes).map(|i| mode(i, x)).collect();
            for i in 0..modes {
                b[i] += w * RHO_A * x * phi[i][0];
                for j in 0..modes {
                    m[(i, j)] += w * RHO_A * phi[i][0] * phi[j][0];
                    k[(i, j)] += w * EI * phi[i][2] * phi[j][2];
                    g[(i, j)] += w * RHO_A * (L * L - x * x) / 2.0 * phi[i][1] * phi[j][1];
                }
            }
        }
    }
    let tip = DVector::from_iterator(modes, (1..=modes).map(|i| mode(i, L)[0]));
    Galerkin {
        m_inv: m.clone().try_inverse().expect("M is positive definite"),
        k,
        g,
        m,
        b,
        tip,
    }
}

/// The tip's transverse deflection every `every` RK4 steps of `h` up to `end`, from rest,
/// with or without the centrifugal stiffening `G`.
fn reference(
    gal: &Galerkin,
    w: f64,
    stiffening: bool,
    h: f64,
    end: f64,
    every: usize,
) -> Vec<(f64, f64)> {
    let n = gal.b.len();
    let rhs = |t: f64, q: &DVector<f64>, v: &DVector<f64>| -> (DVector<f64>, DVector<f64>) {
        let [_, rate, acc] = hub(w, t);
        let mut stiff = gal.k.clone() - rate * rate * &gal.m;
        if stiffening {
            stiff += rate * rate * &gal.g;
        }
        let a = &gal.m_inv * (-acc * &gal.b - stiff * q);
        (v.clone(), a)
    };
    let (mut q, mut v) = (DVector::zeros(n), DVector::zeros(n));
    let steps = (end / h).round() as usize;
    let mut out = vec![(0.0, 0.0)];
    for s in 0..steps {
        let t = s as f64 * h;
        let (k1q, k1v) = rhs(t, &q, &v);
        let (k2q, k2v) = rhs(t + h / 2.0, &(&q + h / 2.0 * &k1q), &(&v + h / 2.0 * &k1v));
        let (k3q, k3v) = rhs(t + h / 2.0, &(&q + h / 2.0 * &k2q), &(&v + h / 2.0 * &k2v));
        let (k4q, k4v) = rhs(t + h, &(&q + h * &k3q), &(&v + h * &k3v));
        q += h / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if (s + 1) % every == 0 {
            out.push(((s + 1) as f64 * h, gal.tip.dot(&q)));
        }
    }
    out
}

/// The deck run at `ws` with `n` beams and step `h` up to `end`: the tip's transverse
/// deflection in the rotating frame, `−x sin θ + y cos θ` (θ the prescribed hub angle),
/// at every recorded step, and the CPU time of the run.
fn run_deck(ws: f64, n: u32, h: f64, end: f64) -> (Vec<(f64, f64)>, f64) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("decks/benchmarks/spinup.dat");
    let set = |k: &str, v: f64| (k.to_string(), v);
    let model = mecano::deck::load_deck_with(
        &path,
        &[
            set("ws", ws),
            set("n", f64::from(n)),
            set("h", h),
            set("tend", end),
        ],
    )
    .unwrap_or_else(|e| panic!("{:?}", miette::Report::new(e)));
    let tip = model
        .nodes
        .get_index_of(&mecano::model::NodeId(3))
        .expect("node 3");
    let mut hist = mecano::output::History::new(1);
    let start = std::time::Instant::now();
    let report = mecano::solver::run(&model, &mut hist).expect("runs");
    let cpu = start.elapsed().as_secs_f64();
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let out = hist
        .t
        .iter()
        .zip(&hist.nodes)
        .map(|(t, nodes)| {
            let th = hub(ws, *t)[0];
            let x = nodes[tip].x;
            (*t, -x.x * th.sin() + x.y * th.cos())
        })
        .collect();
    (out, cpu)
}

/// Largest difference between two histories sampled at the same times (`b` may be
/// sampled `k` times as densely as `a`: its every `k`-th point is used).
fn largest_difference(a: &[(f64, f64)], b: &[(f64, f64)], k: usize) -> f64 {
    a.iter()
        .enumerate()
        .map(|(i, (t, v))| {
            let (tb, vb) = b[i * k];
            assert!((t - tb).abs() < 1e-9, "times {t} {tb}");
            (v - vb).abs()
        })
        .fold(0.0, f64::max)
}

/// The run at `ws` (the deck: 10 beams, h = 0.01 s, to 20 s) against the linear reference.
/// Tolerance, derived term by term:
/// * the reference's model leaves out terms of relative order `(v/L)²` (geometric
///   nonlinearity: foreshortening, the turn of the centrifugal force) and `ρA ω² L²/EA`
///   (axial stretch, Coriolis): `v_peak ((v_peak/L)² + ρA ω² L²/EA)`;
/// * the run's discretisation error, second order in space and in time: the coarse
///   run's error is about 4/3 of its change when the mesh (or the step) is halved; taken
///   as twice each change, measured here (10 → 20 beams, 0.01 → 0.005 s);
/// * the reference's truncation to 5 modes: its change with 6 modes (RK4 at 1 ms: its
///   error is below 1e-6 m, the change from 2 ms).
fn compare(ws: f64) {
    let (run, cpu) = run_deck(ws, 10, 0.01, 20.0);
    let (fine_mesh, _) = run_deck(ws, 20, 0.01, 20.0);
    let (fine_step, _) = run_deck(ws, 10, 0.005, 20.0);
    let r5 = reference(&galerkin(5), ws, true, 1e-3, 20.0, 10);
    let r6 = reference(&galerkin(6), ws, true, 1e-3, 20.0, 10);
    let peak = r5.iter().fold(0.0f64, |m, p| m.max(p.1.abs()));
    let model = peak * ((peak / L).powi(2) + RHO_A * ws * ws * L * L / 2.8e7);
    let mesh = largest_difference(&run, &fine_mesh, 1);
    let step = largest_difference(&run, &fine_step, 2);
    let modes = largest_difference(&r5, &r6, 1);
    let tol = model + 2.0 * (mesh + step) + modes;
    let err = largest_difference(&run, &r5, 1);
    println!(
        "ws {ws}: peak {peak:.4} m, |run - ref| {err:.2e} m, tol {tol:.2e} \
         (model {model:.1e}, mesh {mesh:.1e}, step {step:.1e}, modes {modes:.1e}), CPU {cpu:.2} s"
    );
    assert!(err <= tol, "ws {ws}: {err:e} > {tol:e}");
    // The comparison is not vacuous: the deflection is resolved to a few per cent.
    assert!(tol < 0.05 * peak, "ws {ws}: tol {tol:e} vs peak {peak}");
}

#[test]
fn spin_up_at_4_rad_s_matches_the_linear_reference() {
    compare(4.0);
}

#[test]
fn spin_up_at_10_rad_s_matches_the_linear_reference() {
    compare(10.0);
}

/// The known failure: without the centrifugal stiffening `G` the linear model's
/// transverse stiffness `K − θ̇² M` loses definiteness once θ̇ passes the first bending
/// frequency ω₁ = 3.7977 rad/s (its modal stiffness `ω₁² − θ̇²`), and the deflection
/// grows without bound: past the beam's length at ω_s = 10 before t = 8 s and at
/// ω_s = 4 before 15 s, where the stiffened model stays under 0.9 m.
#[test]
fn without_stiffening_the_linear_model_diverges() {
    let gal = galerkin(5);
    let w1 = (gal.k[(0, 0)] / gal.m[(0, 0)]).sqrt();
    // 1.8751² √(EI/(ρA L⁴)), the clamped-free beam's first frequency.
    assert!((w1 - 1.875104068711961f64.powi(2) * (EI / (RHO_A * L.powi(4))).sqrt()).abs() < 1e-9);
    assert!((w1 - 3.7977).abs() < 1e-4, "{w1}");
    for (ws, by) in [(10.0, 8.0), (4.0, 15.0)] {
        let soft = reference(&gal, ws, false, 1e-3, by, 100);
        let stiff = reference(&gal, ws, true, 1e-3, 20.0, 100);
        let beyond = soft.iter().find(|p| p.1.abs() > L);
        assert!(beyond.is_some(), "ws {ws}: no divergence by {by} s");
        let bounded = stiff.iter().fold(0.0f64, |m, p| m.max(p.1.abs()));
        assert!(bounded < 0.9, "ws {ws}: stiffened peak {bounded}");
        println!(
            "ws {ws}: unstiffened |v| > L at t = {:.1} s; stiffened peak {bounded:.3} m",
            beyond.map_or(0.0, |p| p.0)
        );
    }
}
