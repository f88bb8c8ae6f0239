//! The generic element checks for every order `p = 1…12`, and the order-p beam against the
//! two-node beam and closed forms.

use super::super::two_node::{Beam, default_axis2, reference_triad};
use super::*;
use crate::elements::Element;
use crate::elements::testing::*;
use crate::rotation;

pub(crate) fn steel_props() -> BeamProperties {
    let (e, g, a, i, j, rho) = (2.1e11, 2.1e11 / 2.6, 9e-4, 8.3e-8, 4.15e-8, 7800.0);
    BeamProperties {
        cn: Vector3::new(e * a, 5.0 / 6.0 * g * a, 5.0 / 6.0 * g * a),
        cm: Vector3::new(g * j, e * i, e * i),
        mass: rho * a,
        inertia: Vector3::new(rho * 2.0 * i, rho * i, rho * i),
    }
}

/// A straight beam of order `p` from `x1` to `x2`, nodes at the GLL points; returns the
/// element and the nodes' reference positions.
pub(super) fn straight(p: usize, x1: Vector3<f64>, x2: Vector3<f64>) -> (BeamP, Vec<Vector3<f64>>) {
    let (xi, _) = lagrange::gll(p);
    let x0: Vec<_> = xi
        .iter()
        .map(|t| x1 + (x2 - x1) * (0.5 * (1.0 + t)))
        .collect();
    let triad = reference_triad(&x1, &x2, &default_axis2(&(x2 - x1)));
    let b = BeamP::new(
        ElementId(1),
        (0..=p).collect(),
        &xi,
        &x0,
        &vec![triad; p + 1],
        steel_props(),
    );
    (b, x0)
}

fn forces(b: &BeamP, st: &[NodeState]) -> Vec<f64> {
    let mut out = Local::new(6 * st.len());
    b.evaluate(&static_ctx(), st, &[], false, &mut out);
    out.res
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

#[test]
fn order_one_is_the_two_node_beam() {
    let (x1, x2) = (Vector3::new(0.1, 0.2, -0.1), Vector3::new(0.3, 0.25, 0.0));
    let (bp, x0) = straight(1, x1, x2);
    let b = Beam::new(ElementId(1), [0, 1], &x1, &x2, None, steel_props());
    for seed in 1..4 {
        let st = random_states(&x0, 0.01, 0.9, seed);
        for ctx in [static_ctx(), dyn_ctx()] {
            let (mut o1, mut o2) = (Local::new(12), Local::new(12));
            b.evaluate(&ctx, &st, &[], true, &mut o1);
            bp.evaluate(&ctx, &st, &[], true, &mut o2);
            let (sr, st_) = (max_abs(&o1.res), max_abs(&o1.tan));
            // Same formulas evaluated differently: agreement to round-off of the largest terms.
            for (a, b) in o1.res.iter().zip(&o2.res) {
                assert!((a - b).abs() < 1e-10 * sr, "residual {a} vs {b}");
            }
            for (a, b) in o1.tan.iter().zip(&o2.tan) {
                assert!((a - b).abs() < 1e-9 * st_, "tangent {a} vs {b}");
            }
        }
    }
}

#[test]
fn tangent_matches_finite_differences_for_every_order() {
    let (x1, x2) = (Vector3::new(0.1, 0.2, -0.1), Vector3::new(0.4, 0.25, 0.05));
    for p in 1..=12 {
        let (b, x0) = straight(p, x1, x2);
        // Rotations of 0.4 rad at every node (independent: large strains), stretch ~1 %.
        let st = random_states(&x0, 0.003, 0.4, p as u64);
        // Central difference, ε = 1e-6: truncation O(ε²) relative, round-off 1e-16/ε = 1e-10
        // times the residual over the tangent scale; 2e-7 of the largest entry covers both
        // (as for the two-node beam).
        check_tangent(&b, &static_ctx(), &st, &[], 2e-7);
        check_tangent(&b, &dyn_ctx(), &st, &[], 2e-7);
    }
}

#[test]
fn internal_forces_are_the_gradient_of_the_strain_energy() {
    for p in [2, 5, 9] {
        let (b, x0) = straight(p, Vector3::zeros(), Vector3::new(0.2, 0.1, 0.1));
        let st = random_states(&x0, 0.002, 0.3, 11);
        let f = forces(&b, &st);
        let energy = |s: &[NodeState]| b.energies(s, &Vector3::zeros()).strain;
        let eps = 1e-7;
        let fmax = max_abs(&f);
        for dir in 0..6 * (p + 1) {
            let mut e = Vector3::zeros();
            e[dir % 3] = eps;
            let (mut pl, mut mi) = (st.clone(), st.clone());
            let k = dir / 6;
            if dir % 6 < 3 {
                pl[k].x += e;
                mi[k].x -= e;
            } else {
                pl[k].r *= rotation::exp(&e);
                mi[k].r *= rotation::exp(&-e);
            }
            let fd = (energy(&pl) - energy(&mi)) / (2.0 * eps);
            // Truncation O(ε²) ≈ 1e-14 relative; round-off 1e-16 U/ε relative to the forces.
            assert!(
                (fd - f[dir]).abs() < 1e-6 * fmax,
                "p {p} dof {dir}: {} vs {fd}",
                f[dir]
            );
        }
    }
}

#[test]
fn rigid_motion_gives_zero_strain_and_zero_force_for_every_order() {
    for p in 1..=12 {
        let (b, x0) = straight(p, Vector3::zeros(), Vector3::new(0.1, 0.05, 0.02));
        let rest: Vec<_> = x0.iter().map(|x| NodeState::at_rest(*x)).collect();
        let q = rotation::exp(&Vector3::new(2.0, -1.0, 2.5)); // |Φ| ≈ 3.35 rad > π
        let moved = rigidly_moved(&rest, &q, &Vector3::new(1.0, -2.0, 3.0));
        let (g, k) = b.strains(&moved);
        assert!(g.norm() < 1e-13 && k.norm() < 1e-11, "p {p}: {g} {k}");
        // Relative to the force of a unit axial strain EA.
        assert!(
            max_abs(&forces(&b, &moved)) < 1e-10 * steel_props().cn.x,
            "p {p}"
        );
    }
}

#[test]
fn rigid_rotation_rotates_internal_forces_for_every_order() {
    for p in 1..=12 {
        let (b, x0) = straight(p, Vector3::zeros(), Vector3::new(0.3, 0.0, 0.0));
        let st = random_states(&x0, 0.001, 0.3, 7 + p as u64);
        let q = rotation::exp(&Vector3::new(-0.4, 1.3, 2.8));
        let moved = rigidly_moved(&st, &q, &Vector3::new(0.3, 0.2, 0.1));
        let (f0, f1) = (forces(&b, &st), forces(&b, &moved));
        let scale = max_abs(&f0);
        for k in 0..=p {
            let v = |f: &[f64], o: usize| {
                Vector3::new(f[6 * k + o], f[6 * k + o + 1], f[6 * k + o + 2])
            };
            // Forces are global (turn with Q), moments material (unchanged).
            assert!((v(&f1, 0) - q * v(&f0, 0)).norm() < 1e-9 * scale, "p {p}");
            assert!((v(&f1, 3) - v(&f0, 3)).norm() < 1e-9 * scale, "p {p}");
        }
    }
}

#[test]
fn stiffness_has_exactly_the_six_rigid_modes_for_every_order() {
    // Reduced quadrature (p points) neither locks nor loses rank: at the reference state the
    // stiffness has exactly 6 zero eigenvalues (rigid motions) and 6p positive ones.
    for p in 1..=12 {
        let l = 0.5;
        let (b, x0) = straight(p, Vector3::zeros(), Vector3::new(l, 0.0, 0.0));
        let rest: Vec<_> = x0.iter().map(|x| NodeState::at_rest(*x)).collect();
        let n = 6 * (p + 1);
        let mut out = Local::new(n);
        b.evaluate(&static_ctx(), &rest, &[], true, &mut out);
        // Scale rotations by L so that all entries have the unit of a force per length.
        let k = nalgebra::DMatrix::from_fn(n, n, |r, c| {
            let s = |i: usize| if i % 6 < 3 { 1.0 } else { 1.0 / l };
            out.tan_at(r, c) * s(r) * s(c)
        });
        let sym = (&k + k.transpose()) * 0.5;
        assert!(
            (&k - &sym).norm() < 1e-10 * k.norm(),
            "p {p}: not symmetric at rest"
        );
        let mut ev: Vec<f64> = sym.symmetric_eigenvalues().iter().copied().collect();
        ev.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let top = ev[n - 1];
        // Rigid modes at round-off (1e-12 of the largest); the smallest deformation mode is the
        // torsion of the longest wavelength, ≥ GJ/L³·(element scale) ≫ 1e-9 of the top.
        assert!(
            ev[5].abs() < 1e-11 * top,
            "p {p}: sixth eigenvalue {}",
            ev[5]
        );
        assert!(
            ev[6] > 1e-9 * top,
            "p {p}: spurious mode {} (top {top})",
            ev[6]
        );
    }
}

#[test]
fn a_node_may_be_any_number_of_turns_from_another() {
    // A circle of 1 and 1.25 turns as ONE element: relative rotations beyond π and 2π
    // between nodes. The interpolated relative rotation is θ(s) e₃ (linear in s, reproduced
    // exactly by Lagrange interpolation), so K₃ = 2π·turns / L exactly at every point.
    let l = 1.0;
    for p in [4, 8, 12] {
        let (b, x0) = straight(p, Vector3::zeros(), Vector3::new(l, 0.0, 0.0));
        for turns in [1.0, 1.25] {
            let kappa = 2.0 * std::f64::consts::PI * turns / l;
            let st: Vec<NodeState> = x0
                .iter()
                .map(|x| {
                    let th = kappa * x.x;
                    let mut s =
                        NodeState::at_rest(Vector3::new(th.sin(), 1.0 - th.cos(), 0.0) / kappa);
                    s.r = rotation::exp(&Vector3::new(0.0, 0.0, th));
                    s
                })
                .collect();
            let (_, k) = b.strains(&st);
            assert!(
                (k - Vector3::new(0.0, 0.0, kappa)).norm() < 1e-12 * kappa,
                "p {p}: {k}"
            );
            // A further whole turn of one node (R ← R exp(2π e₃) in 64 increments) changes
            // nothing: the element sees configurations, not rotation histories.
            let f0 = forces(&b, &st);
            let mut st2 = st.clone();
            for _ in 0..64 {
                st2[p].r *=
                    rotation::exp(&Vector3::new(0.0, 0.0, 2.0 * std::f64::consts::PI / 64.0));
            }
            let f2 = forces(&b, &st2);
            let s = max_abs(&f0).max(1.0);
            assert!(
                f0.iter().zip(&f2).all(|(a, b)| (a - b).abs() < 1e-7 * s),
                "p {p}"
            );
        }
    }
}

#[test]
fn consistent_mass_integrates_the_kinetic_energy_of_a_rigid_translation() {
    for p in 1..=12 {
        let l = 0.7;
        let (b, x0) = straight(p, Vector3::zeros(), Vector3::new(0.0, l, 0.0));
        let v = Vector3::new(1.0, -2.0, 0.5);
        let st: Vec<_> = x0
            .iter()
            .map(|x| NodeState {
                v,
                ..NodeState::at_rest(*x)
            })
            .collect();
        let e = b.energies(&st, &Vector3::new(0.0, -9.81, 0.0));
        let m = steel_props().mass * l;
        assert!(
            (e.kinetic - 0.5 * m * v.norm_squared()).abs() < 1e-12 * m,
            "p {p}"
        );
        // Gravity potential of the centre of mass at y = L/2.
        assert!((e.gravity - m * 9.81 * l / 2.0).abs() < 1e-12 * m, "p {p}");
    }
}

#[test]
fn f64_energy_density_equals_the_generic_one() {
    // The energy guard's strain energy (`density_f64`: cross products, one sin/cos per
    // point) against the generic `density` (matrices from `rotation`): the same formula,
    // so equal to round-off of the largest term (1e-12 of it, as the residual paths below),
    // with small rotations in the series branch and rotations past π from the reference node.
    for p in [1, 3, 5, 8] {
        let (x1, x2) = (Vector3::new(0.1, 0.2, -0.1), Vector3::new(0.4, 0.25, 0.05));
        let (b, x0) = straight(p, x1, x2);
        for (seed, du, dr) in [(3, 1e-3, 0.01), (5, 0.01, 0.5), (9, 0.05, 3.0)] {
            let st = random_states(&x0, du, dr, seed + p as u64);
            b.with_locals(&st, |sc, n| {
                for q in &b.stiff {
                    let v = BeamP::point_vars(q, &sc.z[..n]);
                    let (fast, full) = (b.density_f64(q, &v), b.density(q, &v));
                    let at = |k: usize| Vector3::new(v[k], v[k + 1], v[k + 2]);
                    let (g, k) = point_strains(&at(0), &at(3), &at(6));
                    let big = 0.5
                        * ((g - q.gamma0)
                            .abs()
                            .component_mul(&(g.abs() + q.gamma0.abs()))
                            .dot(&b.props.cn)
                            + (k - q.kappa0)
                                .abs()
                                .component_mul(&(k.abs() + q.kappa0.abs()))
                                .dot(&b.props.cm));
                    assert!(
                        (fast - full).abs() <= 1e-12 * big.max(f64::MIN_POSITIVE),
                        "p {p}, seed {seed}: {fast} vs {full}"
                    );
                }
            });
        }
    }
}

#[test]
fn residual_path_equals_the_tangent_path_for_every_order() {
    // The residual path (`internal_forces`: f64 cross-product formulas, one sin/cos per
    // point, `exp(ψ̃ᵢ)` taken from the relative rotations) and the tangent path (generic
    // `density_grad` under dual numbers, matrices from `rotation`) are the same equations:
    // they agree to round-off of the largest force (1e-12 of it covers the ~1e2 operations
    // of a force at ε = 2.2e-16 each, with margin). Small rotations exercise the series
    // branch (ψ² < 1e-2), large ones rotations past π from the reference node.
    for p in 1..=12 {
        let (x1, x2) = (Vector3::new(0.1, 0.2, -0.1), Vector3::new(0.4, 0.25, 0.05));
        let (b, x0) = straight(p, x1, x2);
        for (seed, du, dr) in [(3, 1e-3, 0.01), (5, 0.01, 0.5), (9, 0.05, 3.0)] {
            let st = random_states(&x0, du, dr, seed + p as u64);
            for ctx in [static_ctx(), dyn_ctx()] {
                let (mut fast, mut full) = (Local::new(6 * (p + 1)), Local::new(6 * (p + 1)));
                b.evaluate(&ctx, &st, &[], false, &mut fast);
                b.evaluate(&ctx, &st, &[], true, &mut full);
                let scale = max_abs(&full.res);
                for (a, c) in fast.res.iter().zip(&full.res) {
                    assert!(
                        (a - c).abs() < 1e-12 * scale,
                        "p {p}, seed {seed}: {a} vs {c}"
                    );
                }
            }
        }
    }
}
