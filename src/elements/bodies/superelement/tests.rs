//! The reduction and the element against independent solutions: a 3D Euler–Bernoulli
//! frame assembled here (consistent mass; Przemieniecki, *Theory of Matrix Structural
//! Analysis*, 1968, §5 and §11), its full eigenvalues, rigid-body closed forms, the
//! power balance of the inertia forces, a finite difference of the residual.

use super::fe::FeModel;
pub(super) use super::frame_model::{A, RHO, l_frame};
use super::invariants::Body;
use super::mtx::SymMatrix;
use super::reduce::{lowest_eigenvalues, reduce};
use super::*;
use crate::elements::testing::{Lcg, check_tangent, dyn_ctx, random_states, static_ctx};
use crate::rotation;
use nalgebra::{DMatrix, Matrix3, Vector3};

fn body_of(fe: &FeModel, interface: &[u32], modes: usize) -> Body {
    let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
    let red = reduce(fe, &k, &m, interface, modes).expect("reduces");
    Body::new(fe, &m, &red, interface[0], &interface[1..]).expect("positive mass")
}

fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |e, (x, y)| e.max((x - y).abs() / y.abs()))
}

/// Clamped at the frame node: the CB eigenvalues are upper bounds of the full model's,
/// their error falls as modes are added, and with every interior mode kept they are the
/// full model's to round-off.
#[test]
fn clamped_eigenvalues_converge_to_the_full_model() {
    let fe = l_frame(4);
    let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
    let free: Vec<usize> = (6..fe.dofs.len()).collect();
    let full = lowest_eigenvalues(&k, &m, &free, 5).expect("full");
    let interior = fe.dofs.len() - 12;
    let mut last = f64::INFINITY;
    for modes in [2, 6, 12, interior] {
        // Interface: the frame node and the tip.
        let b = body_of(&fe, &[1, 9], modes);
        let n = b.n;
        let mq = b.m0.view((6, 6), (n, n)).into_owned();
        let all: Vec<usize> = (0..n).collect();
        let cb = lowest_eigenvalues(&b.k, &mq, &all, 5).expect("reduced");
        for (c, f) in cb.iter().zip(&full) {
            assert!(*c >= f * (1.0 - 1e-10), "{modes} modes: {c} below {f}");
        }
        let e = rel_err(&cb, &full);
        eprintln!("clamped, {modes} modes: largest relative error of the 5 lowest ω²: {e:.3e}");
        assert!(e <= last, "{modes} modes: error {e} rose from {last}");
        // The truncation's first-order bound: λ_i's error below λ_i / λ_cut, λ_cut the
        // first fixed-interface mode left out (Géradin & Rixen §8.4; in fact second order).
        if modes < interior {
            let next = body_of(&fe, &[1, 9], modes + 1);
            let cut = next.omega2[modes];
            assert!(
                e <= full[4] / cut,
                "{modes} modes: {e} above {}",
                full[4] / cut
            );
        }
        last = e;
    }
    assert!(last < 1e-8, "every mode kept: {last}");
}

/// Free–free: `(𝕄₀, diag(0, K))` has six zero eigenvalues (the rigid motions) and the
/// full free model's elastic ones, to round-off with every mode kept.
#[test]
fn free_free_eigenvalues_converge_to_the_full_model() {
    let fe = l_frame(4);
    let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
    let all_fe: Vec<usize> = (0..fe.dofs.len()).collect();
    let full = lowest_eigenvalues(&k, &m, &all_fe, 11).expect("full");
    let interior = fe.dofs.len() - 12;
    let mut last = f64::INFINITY;
    for modes in [3, 8, interior] {
        let b = body_of(&fe, &[1, 5], modes);
        let (mm, kk) = b.free_free();
        let all: Vec<usize> = (0..mm.nrows()).collect();
        let cb = lowest_eigenvalues(&kk, &mm, &all, 11).expect("reduced");
        for z in &cb[..6] {
            assert!(z.abs() < 1e-6 * full[6], "rigid eigenvalue {z}");
        }
        let e = rel_err(&cb[6..], &full[6..]);
        eprintln!("free-free, {modes} modes: largest relative error of 5 elastic ω²: {e:.3e}");
        assert!(e <= last);
        last = e;
    }
    assert!(last < 1e-8, "every mode kept: {last}");
}

/// The rigid invariants are the frame's: mass `ρ A L`, first moment `m x̄`.
#[test]
fn rigid_invariants() {
    let fe = l_frame(3);
    let b = body_of(&fe, &[1], 4);
    let l = 1.0 + (0.8f64 * 0.8 + 0.3 * 0.3).sqrt();
    let mass = RHO * A * l;
    assert!((b.mass - mass).abs() < 1e-12 * mass);
    for i in 0..3 {
        for j in 0..3 {
            let want = if i == j { mass } else { 0.0 };
            assert!((b.m0[(i, j)] - want).abs() < 1e-12 * mass);
        }
    }
    // Centroid: leg 1 at (0.5, 0, 0), leg 2 at (1, 0.4, 0.15).
    let l2 = l - 1.0;
    let xbar = (Vector3::new(0.5, 0.0, 0.0) + Vector3::new(1.0, 0.4, 0.15) * l2) / l;
    assert!((b.c0 - xbar * mass).norm() < 1e-12 * mass);
    // The V–Ω block of 𝕄₀ is −c̃₀ (momentum m V + Ω × c).
    let vo = b.m0.view((0, 3), (3, 3)).into_owned();
    assert!((vo + rotation::skew(&b.c0)).norm() < 1e-12 * mass);
}

/// A test element: the L-frame reduced about node 1 with the tip node 9 on the interface
/// and 4 modes (10 coordinates, 4 modal nodes); its nodes at solver indices 0–5.
fn element() -> (Superelement, Vec<Vector3<f64>>) {
    let fe = l_frame(4);
    let body = body_of(&fe, &[1, 9], 4);
    let tip = fe.nodes[&9];
    let q_ref = vec![Vector3::zeros(); 4];
    let el = Superelement::new(ElementId(7), (0..6).collect(), body, q_ref);
    let mut x = vec![Vector3::zeros(), tip];
    x.extend([Vector3::zeros(); 4]);
    (el, x)
}

#[test]
fn tangent_matches_finite_differences() {
    let (el, x) = element();
    let mut nodes = random_states(&x, 1e-3, 0.3, 5);
    // Interface node near its place on the body; small elastic coordinates.
    let mut g = Lcg(9);
    for s in nodes.iter_mut().skip(2) {
        s.x = g.vec(1e-3);
        s.r = Matrix3::identity();
        s.w = Vector3::zeros();
        s.wd = Vector3::zeros();
    }
    let lambda: Vec<f64> = (0..6).map(|_| g.next() * 100.0).collect();
    let mut ctx = dyn_ctx();
    ctx.gravity = Vector3::new(0.0, 0.0, -9.81);
    ctx.penalty = 3.0;
    check_tangent(&el, &ctx, &nodes, &lambda, 1e-6);
    check_tangent(&el, &static_ctx(), &nodes, &lambda, 1e-6);
}

/// Rigid body (no deformation): the frame node's rows are Newton–Euler's about a point
/// off the centre of mass, `m ẍ₀ + R(Ω̇ × c + Ω × (Ω × c))` and `J Ω̇ + Ω × JΩ + c × Rᵀẍ₀`.
#[test]
fn rigid_motion_is_newton_euler() {
    let (el, x) = element();
    let mut nodes = random_states(&x, 0.0, 1.0, 3);
    for s in nodes.iter_mut().skip(1) {
        *s = NodeState::at_rest(Vector3::zeros());
    }
    // The tip where the frame carries it (no constraint force needed).
    nodes[1].x = nodes[0].x + nodes[0].r * x[1];
    nodes[1].r = nodes[0].r;
    let mut out = Local::new(el.lay.size());
    el.evaluate(&dyn_ctx(), &nodes, &[0.0; 6], false, &mut out);
    let b = el.body();
    let (s, c) = (&nodes[0], b.c0);
    let jm = b.m0.fixed_view::<3, 3>(3, 3).into_owned();
    let fx = s.a * b.mass + s.r * (s.wd.cross(&c) + s.w.cross(&s.w.cross(&c)));
    let ft = jm * s.wd + s.w.cross(&(jm * s.w)) + c.cross(&(s.r.transpose() * s.a));
    let r = &out.res;
    let scale = fx.norm() + ft.norm();
    assert!((Vector3::new(r[0], r[1], r[2]) - fx).norm() < 1e-10 * scale);
    assert!((Vector3::new(r[3], r[4], r[5]) - ft).norm() < 1e-10 * scale);
}

/// Along any motion the inertia, elastic and gravity forces' power is the rate of
/// `T + U`: `Σ r·(ẋ, Ω, q̇) = d(T + U)/dt` (a central difference of the energies along
/// the second-order Taylor path of the state), which only a Lagrangian derivation gives.
#[test]
fn forces_are_the_energy_rate() {
    let (el, x) = element();
    let mut nodes = random_states(&x, 0.0, 1.0, 11);
    let mut g = Lcg(4);
    for s in nodes.iter_mut().skip(2) {
        *s = NodeState::at_rest(g.vec(1e-2));
        s.v = g.vec(1.0);
        s.a = g.vec(1.0);
    }
    let grav = Vector3::new(1.0, -2.0, -9.81);
    let mut ctx = dyn_ctx();
    ctx.gravity = grav;
    let mut out = Local::new(el.lay.size());
    el.evaluate(&ctx, &nodes, &[0.0; 6], false, &mut out);
    let mut power = 0.0;
    for k in [0, 2, 3, 4, 5] {
        let s = &nodes[k];
        power += out.res[6 * k..6 * k + 3]
            .iter()
            .zip(s.v.iter())
            .map(|(a, b)| a * b)
            .sum::<f64>();
        power += out.res[6 * k + 3..6 * k + 6]
            .iter()
            .zip(s.w.iter())
            .map(|(a, b)| a * b)
            .sum::<f64>();
    }
    let at = |h: f64| -> f64 {
        let moved: Vec<NodeState> = nodes
            .iter()
            .map(|s| NodeState {
                x: s.x + s.v * h + s.a * (0.5 * h * h),
                r: s.r * rotation::exp(&(s.w * h + s.wd * (0.5 * h * h))),
                v: s.v + s.a * h,
                w: s.w + s.wd * h,
                ..*s
            })
            .collect();
        let e = el.energies(&moved, &grav);
        e.kinetic + e.strain + e.gravity
    };
    let h = 1e-5;
    let rate = (at(h) - at(-h)) / (2.0 * h);
    assert!(
        (power - rate).abs() < 1e-6 * power.abs().max(1.0),
        "power {power} vs energy rate {rate}"
    );
}

/// A rigid motion of the frame and interface nodes (the elastic coordinates unchanged):
/// their forces rotate, their material moments and the modal and constraint rows do not.
#[test]
fn rigid_rotation_objectivity() {
    let (el, x) = element();
    let mut nodes = random_states(&x, 1e-3, 0.5, 21);
    let mut g = Lcg(2);
    for s in nodes.iter_mut().skip(2) {
        *s = NodeState::at_rest(g.vec(1e-3));
        s.v = g.vec(1.0);
        s.a = g.vec(1.0);
    }
    let lambda: Vec<f64> = (0..6).map(|_| g.next()).collect();
    let q = rotation::exp(&Vector3::new(0.7, -1.1, 2.4));
    let b = Vector3::new(1.0, -2.0, 0.5);
    let mut moved = nodes.clone();
    for s in moved.iter_mut().take(2) {
        s.x = q * s.x + b;
        s.r = q * s.r;
        s.v = q * s.v;
        s.a = q * s.a;
    }
    let ctx = dyn_ctx();
    let eval = |n: &[NodeState]| {
        let mut out = Local::new(el.lay.size());
        el.evaluate(&ctx, n, &lambda, false, &mut out);
        out.res
    };
    let (r0, r1) = (eval(&nodes), eval(&moved));
    let scale = r0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for k in 0..2 {
        let t0 = Vector3::from_column_slice(&r0[6 * k..6 * k + 3]);
        let t1 = Vector3::from_column_slice(&r1[6 * k..6 * k + 3]);
        assert!((q * t0 - t1).norm() < 1e-12 * scale);
    }
    for i in (3..6).chain(9..r0.len()) {
        assert!((r0[i] - r1[i]).abs() < 1e-12 * scale, "row {i}");
    }
}

#[test]
fn bad_reductions_are_refused() {
    let fe = l_frame(2);
    let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
    let e = reduce(&fe, &k, &m, &[1, 99], 2).expect_err("no node 99");
    assert!(matches!(
        e,
        reduce::ReduceError::InterfaceDof { node: 99, .. }
    ));
    let e = reduce(&fe, &k, &m, &[1], 1000).expect_err("too many");
    assert!(matches!(
        e,
        reduce::ReduceError::TooManyModes {
            asked: 1000,
            interior: 24
        }
    ));
    // Two frames not connected: with node 1 held, the other one is free.
    let mut two = fe.clone();
    let n = fe.dofs.len();
    let mut kk = DMatrix::zeros(2 * n, 2 * n);
    let mut mm = DMatrix::zeros(2 * n, 2 * n);
    kk.view_mut((0, 0), (n, n)).copy_from(&k);
    kk.view_mut((n, n), (n, n)).copy_from(&k);
    mm.view_mut((0, 0), (n, n)).copy_from(&m);
    mm.view_mut((n, n), (n, n)).copy_from(&m);
    two.k = SymMatrix::from_dense(&kk, 0.0);
    two.m = SymMatrix::from_dense(&mm, 0.0);
    let offset = fe.nodes.len() as u32;
    for (p, x) in fe.nodes.iter() {
        two.nodes
            .insert(p + offset, x + Vector3::new(0.0, 0.0, 5.0));
    }
    two.dofs
        .extend(fe.dofs.iter().map(|&(p, c)| (p + offset, c)));
    let e = reduce(&two, &kk, &mm, &[1], 2).expect_err("free part");
    assert_eq!(e, reduce::ReduceError::NotHeld);
}
