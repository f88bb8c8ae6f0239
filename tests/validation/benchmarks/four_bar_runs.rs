//! The spatial four-bar's tests (decks/benchmarks/four_bar_bauchau.dat; docs/benchmarks.md,
//! "Spatial four-bar"): small angles against the linear frame of `four_bar.rs`, the run
//! against statics, the driver's work against the strain energy, the resultants against
//! the hinges' reactions, and the branch past the flattened position.

use super::four_bar;
use super::{bench, run, until};
use mecano::model::{Model, NodeId};
use mecano::output::History;
use std::path::Path;

/// The route's response per radian, with the deck's data (its `PROPERTIES` sections).
fn route() -> [(nalgebra::Vector3<f64>, nalgebra::Vector3<f64>); four_bar::NODES] {
    four_bar::FourBar {
        l: 0.12,
        beta: 5f64.to_radians(),
        thick: four_bar::Section {
            ea: 52.99e6,
            kga: 16.88e6,
            gj: 733.5,
            ei: 1131.0,
        },
        thin: four_bar::Section {
            ea: 13.25e6,
            kga: 4.220e6,
            gj: 45.84,
            ei: 70.66,
        },
    }
    .per_radian()
}

/// The deck's nodes of the route's nine (`four_bar::NODES`, in its order).
const FOUR_BAR_NODES: [u32; four_bar::NODES] = [10, 11, 12, 20, 21, 22, 30, 31, 32];

/// The four-bar's nodes' displacements and rotation vectors (relative to t = 0) at every
/// recorded instant.
fn four_bar_motion(
    m: &Model,
    h: &History,
) -> Vec<[(nalgebra::Vector3<f64>, nalgebra::Vector3<f64>); 9]> {
    let idx = FOUR_BAR_NODES.map(|n| m.nodes.get_index_of(&NodeId(n)).expect("node exists"));
    h.nodes
        .iter()
        .map(|s| {
            idx.map(|i| {
                let r = nalgebra::Rotation3::from_matrix_unchecked(
                    s[i].r * h.nodes[0][i].r.transpose(),
                );
                (s[i].x - h.nodes[0][i].x, r.scaled_axis())
            })
        })
        .collect()
}

/// The deck as a static analysis of `steps` load steps (its drivers follow f(t) for
/// t = i/steps), with the deck's Newton settings.
fn as_static(mut m: Model, steps: u32) -> Model {
    if let mecano::model::Analysis::Dynamic { newton, .. } = m.analysis.clone() {
        m.analysis = mecano::model::Analysis::Static {
            steps,
            newton,
            proportional: false,
        };
    }
    m
}

/// Largest difference of two sets of nodal (u, φ) over the out-of-plane components (u_z,
/// φ_x, φ_y) and over the in-plane ones (u_x, u_y, φ_z).
fn four_bar_diff(
    a: &[(nalgebra::Vector3<f64>, nalgebra::Vector3<f64>)],
    b: &[(nalgebra::Vector3<f64>, nalgebra::Vector3<f64>)],
) -> (f64, f64) {
    let mut out = 0f64;
    let mut inp = 0f64;
    for ((ua, fa), (ub, fb)) in a.iter().zip(b) {
        out = out
            .max((ua.z - ub.z).abs())
            .max((fa.x - fb.x).abs())
            .max((fa.y - fb.y).abs());
        inp = inp
            .max((ua.x - ub.x).abs())
            .max((ua.y - ub.y).abs())
            .max((fa.z - fb.z).abs());
    }
    (out, inp)
}

/// The four-bar's response to a small crank angle against the linear frame of
/// `benchmarks/four_bar.rs` (the published solution is a plot only, not read): the deck
/// as a static analysis without gravity at θ = −1e-3 and −2e-3 rad, its nodes' (u, φ) per
/// radian against the route's, over all nine nodes (the bars' ends and middles). Out of
/// the plane, what the misalignment causes (u_z of the middles 1e-3 m/rad); in the plane,
/// the rigid mechanism's motion. Tolerance, each part derived:
/// - the terms of higher order in θ: the response per radian is s₁ + s₂θ + …, so
///   |s(θ) − s₁| ≈ |s(2θ) − s(θ)|; twice that covers the cubic terms while |s₃θ| < |s₂|/3;
/// - the beams' discretisation: the run with beams of order 8 against order 4 (the
///   route's solution, cubic in the deflection and quadratic in the rotation, lies in both
///   spaces: both should be exact to Newton's tolerance);
/// - Newton's tolerance (1e-10 of the model's length, 0.24 m): 2.4e-11 m over θ = 1e-3,
///   2.4e-8 per radian; 1e-7 allowed.
#[test]
fn four_bar_small_angles_follow_the_linear_frame() {
    let route = route();
    let per_radian = |theta: f64, p: f64| {
        let m = as_static(
            bench(
                "four_bar_bauchau.dat",
                &[("w", theta), ("g", 0.0), ("p", p)],
            ),
            1,
        );
        let (h, _) = run(&m);
        let last = *four_bar_motion(&m, &h).last().expect("a step");
        last.map(|(u, f)| (u / theta, f / theta))
    };
    let theta = -1e-3;
    let (s1, s2, s8) = (
        per_radian(theta, 4.0),
        per_radian(2.0 * theta, 4.0),
        per_radian(theta, 8.0),
    );
    let (nl_out, nl_in) = four_bar_diff(&s1, &s2);
    let (fe_out, fe_in) = four_bar_diff(&s1, &s8);
    let (d_out, d_in) = four_bar_diff(&s1, &route);
    let mid = route[4].0.z;
    let tol_out = 2.0 * nl_out + fe_out + 1e-7;
    let tol_in = 2.0 * nl_in + fe_in + 1e-7;
    eprintln!(
        "four-bar, per radian of crank angle at θ = {theta}: out of the plane |Δ| {d_out:.3e} \
         (tolerance {tol_out:.3e}: higher order {nl_out:.2e}, order 8 vs 4 {fe_out:.2e}); \
         in the plane {d_in:.3e} (tolerance {tol_in:.3e}: {nl_in:.2e}, {fe_in:.2e}); \
         coupler's middle u_z/θ: run {:.6e}, route {mid:.6e} m/rad",
        s1[4].0.z
    );
    for (k, ((u, f), (ur, fr))) in s1.iter().zip(&route).enumerate() {
        eprintln!(
            "  node {}: u/θ {:+.5e} {:+.5e} {:+.5e} φ/θ {:+.5e} {:+.5e} {:+.5e} | route {:+.5e} {:+.5e} {:+.5e} {:+.5e} {:+.5e} {:+.5e}",
            FOUR_BAR_NODES[k], u.x, u.y, u.z, f.x, f.y, f.z, ur.x, ur.y, ur.z, fr.x, fr.y, fr.z
        );
    }
    assert!(d_out <= tol_out, "out of the plane {d_out} > {tol_out}");
    assert!(d_in <= tol_in, "in the plane {d_in} > {tol_in}");
    // Not empty: the misalignment bends the loop out of its plane.
    assert!(mid.abs() > 1e-4, "{mid}");
}

/// The dynamic run is quasi-static: over 0.1–1.5 s (crank angle to −0.9 rad) the deck's
/// run (h = 0.01 s) and the deck as a static analysis at the same crank angles (150 load
/// steps) give the same out-of-plane displacements of the bars' middles (nodes 11, 21,
/// 31). What may part them, each bounded:
/// - the free vibration the start leaves: the quasi-static deflection grows at
///   ṡ = |ω| s₁ (s₁ the linear route's largest u_z per radian) from t = 0, where the run
///   starts undeformed at rest relative to the rigid motion, so the exact solution carries
///   a vibration of amplitude at most ṡ/Ω₁, Ω₁ the lowest mode's circular frequency
///   (`mecano::app::modes`); generalized-α with ρ∞ = 0 annihilates it in a few steps
///   (unresolved: Ω₁h = 13), hence the window starts at 0.1 s, and the bound is kept;
/// - the inertial loads of the rigid motion, ρA ω² l at most against gravity's ρA g: the
///   static sag under gravity g = 9.81 m/s² (a static run at θ = 0) times ω² (2l)/g;
/// - the run's own time error: its difference to the run at h/2 (second order: 4/3 of it).
#[test]
fn four_bar_dynamic_run_is_quasi_static() {
    let end = 1.5;
    let w = -0.6;
    let base = until(bench("four_bar_bauchau.dat", &[]), end);
    let mids = [1, 4, 7];
    let uz = |m: &Model| {
        let (h, cpu) = run(m);
        let t = h.t.clone();
        let z: Vec<[f64; 3]> = four_bar_motion(m, &h)
            .iter()
            .map(|s| mids.map(|k| s[k].0.z))
            .collect();
        (t, z, cpu)
    };
    let (t, dynamic, cpu) = uz(&base);
    let mut half = base.clone();
    assert!(half.set_fixed_step(0.005, end, None));
    let (t_half, dyn_half, _) = uz(&half);
    let steps = (end / 0.01).round() as u32;
    let (t_static, stat, _) = uz(&as_static(
        bench("four_bar_bauchau.dat", &[("w", w * end)]),
        steps,
    ));
    let (_, sag, _) = uz(&as_static(
        bench("four_bar_bauchau.dat", &[("w", 0.0), ("g", 9.81)]),
        1,
    ));
    let sag = sag
        .last()
        .expect("a step")
        .iter()
        .fold(0f64, |a, z| a.max(z.abs()));

    // Samples at the same instants (static: t = i/steps of the end).
    let at = |ts: &[f64], scale: f64, t0: f64| {
        ts.iter()
            .position(|x| (x * scale - t0).abs() < 1e-9)
            .expect("instant recorded")
    };
    let (mut d_qs, mut d_time, mut peak) = (0f64, 0f64, 0f64);
    for (k, tk) in t.iter().enumerate().filter(|(_, tk)| **tk >= 0.1 - 1e-9) {
        let s = &stat[at(&t_static, end, *tk)];
        let hh = &dyn_half[at(&t_half, 1.0, *tk)];
        for j in 0..3 {
            d_qs = d_qs.max((dynamic[k][j] - s[j]).abs());
            d_time = d_time.max((dynamic[k][j] - hh[j]).abs());
            peak = peak.max(dynamic[k][j].abs());
        }
    }
    let route = route();
    let s1 = route.iter().fold(0f64, |a, (u, _)| a.max(u.z.abs()));
    let modes = mecano::app::modes::analyse_model(&base, mecano::app::modes::About::Initial, 1)
        .map_err(|f| f.message)
        .expect("modal analysis")
        .1;
    let omega1 = 2.0 * std::f64::consts::PI * modes.modes[0].natural_hz;
    let start = w.abs() * s1 / omega1;
    let inertia = sag * w * w * 0.24 / 9.81;
    let tol = start + inertia + 4.0 / 3.0 * d_time;
    eprintln!(
        "four-bar to {end} s: largest |u_z| of the middles {peak:.4e} m; dynamic − quasi-static {d_qs:.3e} m \
         (tolerance {tol:.3e}: start {start:.2e} [s₁ {s1:.3e} m/rad, Ω₁ {omega1:.1} rad/s], \
         inertia {inertia:.2e} [sag {sag:.2e} m], time {d_time:.2e}); CPU {cpu:.2} s"
    );
    assert!(d_qs <= tol, "{d_qs} > {tol}");
    assert!(peak > 1e-3, "{peak}");
}

/// The columns of a CSV history file, by name.
fn csv_columns(path: &Path) -> std::collections::HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    let mut lines = text.lines();
    let names: Vec<String> = lines
        .next()
        .expect("a header")
        .split(',')
        .map(str::to_string)
        .collect();
    let mut cols = vec![Vec::new(); names.len()];
    for l in lines {
        for (c, v) in cols.iter_mut().zip(l.split(',')) {
            c.push(v.parse::<f64>().expect("a number"));
        }
    }
    names.into_iter().zip(cols).collect()
}

/// Runs the four-bar deck with the binary to `end` at step `h`, beams of order `p`, into a
/// fresh directory.
fn four_bar_files(end: f64, h: f64, p: u32) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "mecano_four_bar_{}_{}_{p}",
        std::process::id(),
        (h * 1e6).round()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let deck = Path::new(env!("CARGO_MANIFEST_DIR")).join("decks/benchmarks/four_bar_bauchau.dat");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck)
        .args([
            "-q",
            "--set",
            &format!("tend={end}"),
            "--set",
            &format!("h={h}"),
        ])
        .args(["--set", &format!("p={p}"), "-o"])
        .arg(&dir)
        .output()
        .expect("runs");
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    dir
}

/// The driver's work and the bars' sectional forces over 0–1.5 s (crank to −0.9 rad),
/// from the files a run writes (the driver's `torque` and each beam's resultants are in
/// the element histories).
///
/// **Work.** Without damping the work of the driving torque, W = ∫ τ dθ (trapezoidal rule
/// over the recorded steps, computed here from `element_1.csv`), equals the change of
/// strain and kinetic energy (`energy.csv`): the driver's multiplier against the beams'
/// strain energy. The defect D = W − ΔU − ΔK has two sources, each estimated: the
/// quadrature (Richardson: the trapezoid on every second sample differs by 3 times the
/// error; |W_h − W_2h| allowed) and the integrator (second order: D at h against D at h/2,
/// 4/3 of the difference).
///
/// **Sectional forces.** Each bar's first half (elements 10, 20, 30) is loaded at its joint
/// end (hinges 1, 2, 3: the force F and moment M on the bar, global) and at the section
/// by the rest of the bar; without gravity, and with inertia negligible (below), the
/// resultants at the element's midpoint s are |n| = |F| and |m| = |M + (x_J − x_s) × F|:
/// equilibrium alone, whatever the beam's stiffness. Allowed, each part estimated:
/// - the resultants' discretisation error: they come from the strains, one derivative
///   below the displacements, and converge more slowly (order 4: 2e-4 of the 400 N out-of-
///   plane shear of the coupler); bounded by their difference to the run with beams of
///   order 8 (|n| and |m| compared sample by sample);
/// - x_s taken as the middle of the element's end nodes: the element's bow from that chord
///   is below κℓ²/8 = 2.3e-5 m (curvature M/EI < 0.05/m over ℓ ≤ 0.12 m), a moment error
///   below 1e-4·|F|;
/// - the distributed inertia of the rigid motion between joint and section, ρA·0.06 m·
///   ω²(2l) ≤ 1.997·0.06·0.36·0.24 = 1.0e-2 N, and its moment over 0.06 m, 6e-4 N m:
///   1e-2 N and 1e-3 N m allowed; the start's elastic transient, not bounded here, is left
///   out by starting the comparison at 0.1 s (the quasi-static test's window);
/// - 1e-6 of the values for the printed digits.
#[test]
fn four_bar_driver_work_and_sectional_forces() {
    let end = 1.5;
    let defect = |dir: &Path| {
        let (e1, en) = (
            csv_columns(&dir.join("element_1.csv")),
            csv_columns(&dir.join("energy.csv")),
        );
        let (tau, th) = (&e1["torque"], &e1["prescribed"]);
        let work = |stride: usize| {
            (stride..tau.len())
                .step_by(stride)
                .map(|k| 0.5 * (tau[k] + tau[k - stride]) * (th[k] - th[k - stride]))
                .sum::<f64>()
        };
        let n = tau.len() - 1;
        assert_eq!(n % 2, 0, "an even number of steps");
        let (w1, w2) = (work(1), work(2));
        let du = en["strain"][n] - en["strain"][0];
        let dk = en["kinetic"][n] - en["kinetic"][0];
        (w1, (w1 - w2).abs(), w1 - du - dk)
    };
    let (dir, dir_half, dir_p8) = (
        four_bar_files(end, 0.01, 4),
        four_bar_files(end, 0.005, 4),
        four_bar_files(end, 0.01, 8),
    );
    let (w, quad, d) = defect(&dir);
    let (_, _, d_half) = defect(&dir_half);
    let tol = quad + 4.0 / 3.0 * (d - d_half).abs();
    eprintln!(
        "four-bar to {end} s: driver's work {w:.6e} J, W − ΔU − ΔK = {d:.3e} J (h/2: {d_half:.3e}); \
         tolerance {tol:.3e} (quadrature {quad:.2e})"
    );
    assert!(d.abs() <= tol, "{d} > {tol}");
    assert!(w > 1.0, "{w}");

    let node = |n: u32| {
        let c = csv_columns(&dir.join(format!("node_{n}.csv")));
        (0..c["x"].len())
            .map(|k| nalgebra::Vector3::new(c["x"][k], c["y"][k], c["z"][k]))
            .collect::<Vec<_>>()
    };
    for (beam, joint, (a, b)) in [(10, 1, (10, 11)), (20, 2, (20, 21)), (30, 3, (30, 31))] {
        let (e, j, e8) = (
            csv_columns(&dir.join(format!("element_{beam}.csv"))),
            csv_columns(&dir.join(format!("element_{joint}.csv"))),
            csv_columns(&dir_p8.join(format!("element_{beam}.csv"))),
        );
        let (xa, xb) = (node(a), node(b));
        let (mut dn, mut dm, mut peak_n, mut peak_m) = (0f64, 0f64, 0f64, 0f64);
        for k in (0..xa.len()).filter(|&k| e["t"][k] >= 0.1 - 1e-9) {
            let v = |c: &[&str; 3], m: &std::collections::HashMap<String, Vec<f64>>| {
                nalgebra::Vector3::new(m[c[0]][k], m[c[1]][k], m[c[2]][k])
            };
            let (f, mj) = (v(&["fx", "fy", "fz"], &j), v(&["mx", "my", "mz"], &j));
            let (n, m) = (v(&["n1", "n2", "n3"], &e), v(&["m1", "m2", "m3"], &e));
            let (n8, m8) = (v(&["n1", "n2", "n3"], &e8), v(&["m1", "m2", "m3"], &e8));
            let xs = 0.5 * (xa[k] + xb[k]);
            let m_eq = mj + (xa[k] - xs).cross(&f);
            let tol_n = 1e-2 + (n.norm() - n8.norm()).abs() + 1e-6 * f.norm();
            let tol_m = 1e-3 + (m.norm() - m8.norm()).abs() + 1e-4 * f.norm() + 1e-6 * m_eq.norm();
            dn = dn.max((n.norm() - f.norm()).abs() / tol_n);
            dm = dm.max((m.norm() - m_eq.norm()).abs() / tol_m);
            peak_n = peak_n.max(f.norm());
            peak_m = peak_m.max(m_eq.norm());
        }
        eprintln!(
            "  element {beam} against hinge {joint}: largest ||n| − |F|| / tolerance {dn:.3}, \
             ||m| − |M + r × F|| / tolerance {dm:.3} (|F| up to {peak_n:.3e} N, |m| up to {peak_m:.3e} N m)"
        );
        assert!(dn <= 1.0 && dm <= 1.0, "element {beam}: {dn} {dm}");
        assert!(peak_m > 1.0, "{peak_m}");
    }
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&dir_half);
    let _ = std::fs::remove_dir_all(&dir_p8);
}

/// Past the first flattened position (t = 2.618 s) the loop runs crossed: at 3.0 s the
/// coupler's middle (node 21) is where the rigid anti-parallelogram puts it, not the
/// parallelogram (docs/benchmarks.md, "Branch"). The rigid positions are computed here
/// (circle intersection: C at 0.24 m from B and 0.12 m from D, B = 0.12 (sin θ, cos θ),
/// θ = 0.6 t); the run's middle may differ from its rigid assembly by the bars'
/// deformation, which in the plane is smaller than the largest out-of-plane displacement
/// of the run so far (the loop is a mechanism in its plane; it deforms there only through
/// the tilted hinge's moment, tan 5° of the out-of-plane one, and through the axial
/// strains, below 1.2e-4): that displacement is the tolerance. The two assemblies are 0.05
/// m apart.
#[test]
fn four_bar_runs_crossed_past_the_flattened_position() {
    let end = 3.0;
    let m = until(bench("four_bar_bauchau.dat", &[]), end);
    let (h, _) = run(&m);
    let i = m.nodes.get_index_of(&NodeId(21)).expect("node exists");
    let x = h.nodes.last().expect("a step")[i].x;
    let lz = h.nodes.iter().fold(0f64, |a, s| a.max(s[i].x.z.abs()));
    let th = 0.6 * end;
    let b = nalgebra::Vector2::new(0.12 * th.sin(), 0.12 * th.cos());
    let d = nalgebra::Vector2::new(0.24, 0.0);
    let bd = d - b;
    let l = bd.norm();
    let a = (0.24f64.powi(2) - 0.12f64.powi(2) + l * l) / (2.0 * l);
    let hh = (0.24f64.powi(2) - a * a).sqrt();
    let p = b + a * bd / l;
    let perp = nalgebra::Vector2::new(-bd.y, bd.x) / l;
    let mids = [p + hh * perp, p - hh * perp].map(|c| 0.5 * (b + c));
    // The parallelogram's C is B + (0.24, 0): its middle is B + (0.12, 0).
    let para = b + nalgebra::Vector2::new(0.12, 0.0);
    let (crossed, other) = if (mids[0] - para).norm() < (mids[1] - para).norm() {
        (mids[1], mids[0])
    } else {
        (mids[0], mids[1])
    };
    let xy = nalgebra::Vector2::new(x.x, x.y);
    let (dc, dp) = ((xy - crossed).norm(), (xy - other).norm());
    eprintln!(
        "four-bar at {end} s: coupler's middle ({:.5}, {:.5}); rigid crossed ({:.5}, {:.5}) at {dc:.2e} m, \
         parallelogram ({:.5}, {:.5}) at {dp:.2e} m; tolerance {lz:.2e} m",
        xy.x, xy.y, crossed.x, crossed.y, other.x, other.y
    );
    assert!(dc <= lz, "{dc} > {lz}");
    assert!(dp > 10.0 * lz, "{dp}");
}
