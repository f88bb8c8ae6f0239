use super::*;
use crate::elements::testing::*;
use crate::elements::{Element, Local, NodeState};
use crate::model::PlacedProfile;
use crate::rotation;
use nalgebra::Vector2;

fn data(cam: Profile, fol: Profile, mu: f64, clip: bool) -> CameData {
    CameData {
        stiffness: 1e6,
        damping: 300.0,
        friction: mu,
        // Large enough that the finite difference (velocity steps c_v ε ≈ 2e-3 m/s) stays
        // in the quadratic range of the regularisation.
        friction_speed: 2.0,
        clip_tension: clip,
        impact_steps: 10,
        cam: PlacedProfile {
            profile: cam,
            offset: Vector3::new(0.1, -0.05, 0.02),
            frame: rotation::exp(&Vector3::new(0.1, -0.2, 0.3)),
        },
        follower: PlacedProfile {
            profile: fol,
            offset: Vector3::new(0.03, 0.02, -0.01),
            frame: Matrix3::identity(),
        },
    }
}

/// A state with the roller penetrating the surface by about `depth`.
fn state_in_contact(el: &Came, seed: u64, depth: f64) -> Vec<NodeState> {
    let mut st = random_states(
        &[Vector3::zeros(), Vector3::new(0.0, 0.5, 0.0)],
        0.05,
        0.4,
        seed,
    );
    // Move the roller node so that the gap is −depth.
    for _ in 0..3 {
        let s = el.state(&st).or_else(|| {
            let l = el.local_point(&st);
            let eta0 = el.curve.closest_parameter(&Vector2::new(l.x, l.y));
            Some(el.kernel_at(&st, eta0, false, true))
        });
        let s = s.unwrap();
        let pi = 1 - el.s;
        st[pi].x -= s.normal * (s.gap + depth);
    }
    st
}

fn check(cam: Profile, fol: Profile, mu: f64, clip: bool) {
    // Both laws: from a state apart (spring alone) and in contact (spring and dashpot).
    for touching in [false, true] {
        let mut el = Came::new(
            ElementId(1),
            [0, 1],
            &data(cam.clone(), fol.clone(), mu, clip),
        )
        .unwrap();
        el.touching = touching;
        check_law(&el, clip);
    }
}

fn check_law(el: &Came, clip: bool) {
    for seed in 1..6 {
        let st = state_in_contact(el, seed, 1e-3);
        let s = el.state(&st).unwrap();
        assert!((s.gap + 1e-3).abs() < 1e-9, "gap {}", s.gap);
        if clip && s.force <= 0.0 {
            continue;
        }
        check_tangent(el, &dyn_ctx(), &st, &[], 1e-6);
    }
}

#[test]
fn tangent_point_on_line_rotated_cam() {
    check(Profile::Line, Profile::Point, 0.0, false);
}

#[test]
fn tangent_point_on_circle() {
    check(Profile::Circle { radius: 0.3 }, Profile::Point, 0.0, false);
}

#[test]
fn tangent_roller_on_circle_with_friction() {
    check(
        Profile::Circle { radius: 0.3 },
        Profile::Circle { radius: 0.05 },
        0.3,
        true,
    );
}

#[test]
fn tangent_roller_on_line_with_friction() {
    check(Profile::Line, Profile::Circle { radius: 0.05 }, 0.4, false);
}

#[test]
fn tangent_point_on_spline() {
    let pts = vec![
        [-0.5, 0.1],
        [-0.2, -0.05],
        [0.1, 0.05],
        [0.4, 0.0],
        [0.8, 0.2],
    ];
    check(
        Profile::Spline {
            points: pts,
            closed: false,
        },
        Profile::Point,
        0.2,
        false,
    );
}

#[test]
fn tangent_flat_follower_on_disc_cam() {
    check(Profile::Circle { radius: 0.2 }, Profile::Line, 0.0, false);
}

#[test]
fn forces_balance_and_push_apart() {
    let el = Came::new(
        ElementId(1),
        [0, 1],
        &data(Profile::Line, Profile::Point, 0.3, true),
    )
    .unwrap();
    let mut st = state_in_contact(&el, 7, 1e-3);
    for s in &mut st {
        s.v = Vector3::zeros();
        s.w = Vector3::zeros();
    }
    let mut out = Local::new(12);
    el.evaluate(&dyn_ctx(), &st, &[], false, &mut out);
    let f_a = Vector3::new(out.res[0], out.res[1], out.res[2]);
    let f_b = Vector3::new(out.res[6], out.res[7], out.res[8]);
    assert!((f_a + f_b).norm() < 1e-9 * f_a.norm());
    let s = el.state(&st).unwrap();
    // Residual = −force; the follower is pushed along +n with k·depth.
    assert!((f_b + s.normal * 1e3).norm() < 1e-6, "{f_b:?}");
}

#[test]
fn far_apart_costs_nothing() {
    let el = Came::new(
        ElementId(1),
        [0, 1],
        &data(Profile::Circle { radius: 0.1 }, Profile::Point, 0.0, true),
    )
    .unwrap();
    let st = vec![
        NodeState::at_rest(Vector3::zeros()),
        NodeState::at_rest(Vector3::new(5.0, 0.0, 0.0)),
    ];
    assert!(el.state(&st).is_none());
    let mut out = Local::new(12);
    el.evaluate(&dyn_ctx(), &st, &[], true, &mut out);
    assert!(out.res.iter().chain(&out.tan).all(|v| *v == 0.0));
}
