use super::*;
use crate::elements::testing::*;
use crate::elements::{Element, Local, NodeState};
use crate::rotation;

fn data(law: ContactLaw, mu: f64) -> ClearanceData {
    ClearanceData {
        axis: Vector3::new(0.2, -0.3, 1.0),
        // Large enough that the finite differences of `check_tangent` (ε = 1e-6 m) see
        // the penetrations (3e-3 m) as smooth: truncation (ε/δ)² ≈ 1e-7.
        radius: 1.0,
        clearance: 0.05,
        law,
        friction: mu,
        // Large enough that the finite difference (velocity steps c_v ε ≈ 2e-3 m/s) stays
        // in the quadratic range of the regularisation.
        friction_speed: 2.0,
        min_approach: 1e-4,
        impact_steps: 10,
    }
}

const KV: ContactLaw = ContactLaw::KelvinVoigt { k: 1e7, c: 300.0 };
const LN: ContactLaw = ContactLaw::LankaraniNikravesh {
    k: 1e10,
    exponent: 1.5,
    restitution: 0.7,
};

/// A random state with the journal penetrating the bearing's wall by `depth`.
fn state_in_contact(el: &Clearance, seed: u64, depth: f64) -> Vec<NodeState> {
    let mut st = random_states(&[Vector3::zeros(), Vector3::zeros()], 0.1, 0.4, seed);
    let s = el.kernel_at(&st, false, true);
    let n = s.normal;
    st[1].x += n * (el.c + depth - s.ecc.norm());
    st
}

fn element(law: ContactLaw, mu: f64, touching: bool) -> Clearance {
    let mut el = Clearance::new(ElementId(1), [0, 1], &data(law, mu)).unwrap();
    el.touching = touching;
    el.approach = 0.8;
    el
}

#[test]
fn penetration_is_the_eccentricity_beyond_the_clearance() {
    let el = element(KV, 0.0, false);
    for seed in 1..6 {
        let st = state_in_contact(&el, seed, 2e-3);
        let s = el.state(&st);
        assert!((s.pen - 2e-3).abs() < 1e-12, "δ {}", s.pen);
        // Eccentricity normal to the (turned) axis, and the rate = d|e|/dt by a
        // difference along the motion.
        let a = st[0].r * el.a0;
        assert!(s.ecc.dot(&a).abs() < 1e-15);
        // Central difference: error (dt²/6) d³|e|/dt³ ≈ 1e-12 here.
        let dt = 1e-6;
        let moved = |sign: f64| {
            let mut m = st.clone();
            for k in 0..2 {
                m[k].x += st[k].v * (sign * dt);
                m[k].r *= rotation::exp(&(st[k].w * (sign * dt)));
            }
            el.state(&m).pen
        };
        let rate = (moved(1.0) - moved(-1.0)) / (2.0 * dt);
        assert!(
            (rate - s.pen_rate).abs() < 1e-5 * (1.0 + rate.abs()),
            "{rate} vs {}",
            s.pen_rate
        );
    }
}

#[test]
fn tangent_matches_finite_differences() {
    for law in [KV, LN] {
        for mu in [0.0, 0.3] {
            for touching in [false, true] {
                let el = element(law, mu, touching);
                for seed in 1..5 {
                    let st = state_in_contact(&el, seed, 3e-3);
                    if el.state(&st).force <= 0.0 {
                        continue;
                    }
                    check_tangent(&el, &dyn_ctx(), &st, &[], 1e-6);
                }
            }
        }
    }
}

#[test]
fn forces_are_objective_and_balanced() {
    for law in [KV, LN] {
        let el = element(law, 0.3, true);
        let st = state_in_contact(&el, 7, 3e-3);
        let mut out = Local::new(12);
        el.evaluate(&dyn_ctx(), &st, &[], false, &mut out);
        let f = |o: &Local, i: usize| Vector3::new(o.res[i], o.res[i + 1], o.res[i + 2]);
        // Balance: forces sum to zero, and so do the moments about the origin.
        assert!((f(&out, 0) + f(&out, 6)).norm() < 1e-9 * f(&out, 0).norm());
        let mom = st[0].x.cross(&f(&out, 0))
            + st[0].r * f(&out, 3)
            + st[1].x.cross(&f(&out, 6))
            + st[1].r * f(&out, 9);
        assert!(mom.norm() < 1e-9 * f(&out, 0).norm(), "moment {mom}");
        // Objectivity: a rigid motion rotates the forces and leaves the material moments.
        let q = rotation::exp(&Vector3::new(0.4, -1.1, 0.7));
        let moved = rigidly_moved(&st, &q, &Vector3::new(1.0, 2.0, -3.0));
        let mut out2 = Local::new(12);
        el.evaluate(&dyn_ctx(), &moved, &[], false, &mut out2);
        for blk in [0, 6] {
            assert!((q * f(&out, blk) - f(&out2, blk)).norm() < 1e-9 * f(&out, 0).norm());
            assert!((f(&out, blk + 3) - f(&out2, blk + 3)).norm() < 1e-9 * f(&out, 0).norm());
        }
    }
}

#[test]
fn apart_gives_nothing() {
    let el = element(LN, 0.3, false);
    let mut st = state_in_contact(&el, 3, 0.0);
    st[1].x = st[0].x + (st[1].x - st[0].x) * 0.5;
    let mut out = Local::new(12);
    el.evaluate(&dyn_ctx(), &st, &[], true, &mut out);
    assert!(out.res.iter().chain(&out.tan).all(|v| *v == 0.0));
    assert_eq!(el.energies(&st, &Vector3::zeros()).strain, 0.0);
}

#[test]
fn dissipation_is_never_negative_and_the_energy_is_the_force_potential() {
    for law in [KV, LN] {
        let el = element(law, 0.2, true);
        for seed in 1..6 {
            let st = state_in_contact(&el, seed, 4e-3);
            let s = el.state(&st);
            assert!(el.power(&s) >= 0.0, "power {}", el.power(&s));
            // dU/dδ = F_el.
            let h = 1e-9;
            let du = (el.contact_energy(s.pen + h) - el.contact_energy(s.pen - h)) / (2.0 * h);
            assert!(
                (du - s.elastic).abs() < 1e-6 * s.elastic,
                "{du} vs {}",
                s.elastic
            );
        }
    }
}

#[test]
fn a_bad_clearance_is_refused() {
    let mut d = data(KV, 0.0);
    d.clearance = 2.0;
    assert!(Clearance::new(ElementId(1), [0, 1], &d).is_err());
    d.clearance = 0.0;
    assert!(Clearance::new(ElementId(1), [0, 1], &d).is_err());
    d.clearance = 1e-3;
    d.axis = Vector3::zeros();
    assert!(Clearance::new(ElementId(1), [0, 1], &d).is_err());
}
