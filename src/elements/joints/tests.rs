use super::*;
use crate::elements::testing::*;

fn all_types() -> Vec<JointType> {
    let a = Vector3::new(0.3, -0.5, 0.8).normalize();
    let (p, q) = normals(&a);
    vec![
        JointType::Spherical,
        JointType::Hinge { p, q, a },
        JointType::UJoint {
            a1: a,
            a2: p,
            b: a.cross(&p),
        },
        JointType::Clamp,
        JointType::Prismatic { p, q, a },
        JointType::Rigid,
    ]
}

fn ctx() -> EvalContext {
    EvalContext {
        constraint_scale: 3.7,
        penalty: 11.0,
        ..dyn_ctx()
    }
}

#[test]
fn tangent_matches_finite_differences_at_large_rotations() {
    for kind in all_types() {
        // Node 2 offset from node 1 (joint point at node 1), a third node for RIGID.
        let x0 = [
            Vector3::new(0.1, 0.2, -0.1),
            Vector3::new(0.4, -0.1, 0.3),
            Vector3::new(-0.2, 0.5, 0.1),
        ];
        let n = if matches!(kind, JointType::Rigid) {
            3
        } else {
            2
        };
        let j = Joint::new(ElementId(7), kind.clone(), (0..n).collect(), &x0[..n]).unwrap();
        for seed in 1..4 {
            // Rotations up to ~2.6 rad per node, displacements of 0.3 m.
            let st = random_states(&x0[..n], 0.3, 1.5, seed);
            let mut g = Lcg(seed + 100);
            let lam: Vec<f64> = (0..j.multipliers()).map(|_| g.next() * 5.0).collect();
            check_tangent(&j, &ctx(), &st, &lam, 1e-7);
            check_tangent(&j, &static_ctx(), &st, &lam, 1e-7);
        }
    }
}

#[test]
fn reference_configuration_satisfies_the_constraints() {
    let x0 = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(0.5, 0.1, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
    ];
    for kind in all_types() {
        let n = if matches!(kind, JointType::Rigid) {
            3
        } else {
            2
        };
        let j = Joint::new(ElementId(1), kind, (0..n).collect(), &x0[..n]).unwrap();
        let st: Vec<NodeState> = x0[..n].iter().map(|x| NodeState::at_rest(*x)).collect();
        assert!(j.constraint_violation(&st) < 1e-15);
    }
}

#[test]
fn hinge_allows_rotation_about_its_axis_only_and_counts_turns() {
    let a = Vector3::new(0.0, 0.0, 1.0);
    let (p, q) = normals(&a);
    let x0 = [Vector3::zeros(), Vector3::zeros()];
    let mut j = Joint::new(ElementId(1), JointType::Hinge { p, q, a }, vec![0, 1], &x0).unwrap();
    let base = rotation::exp(&Vector3::new(0.4, -1.1, 0.7));
    let mut st = [NodeState::at_rest(x0[0]), NodeState::at_rest(x0[1])];
    st[0].r = base;
    let c = dyn_ctx();
    // Turn node 2 about the hinge axis by 3.5 turns in steps of 0.5 rad.
    let mut theta = 0.0;
    while theta < 7.0 * std::f64::consts::PI {
        theta += 0.5;
        st[1].r = base * rotation::exp(&(a * theta));
        assert!(j.constraint_violation(&st) < 1e-14);
        j.commit(&c, &st, &[0.0; 5]);
        let row = j.output_row(&c, &st, &[0.0; 5]);
        assert!((row[0] - theta).abs() < 1e-12, "{} vs {theta}", row[0]);
    }
    // A rotation about a normal violates it by sin(angle).
    st[1].r = base * rotation::exp(&(p * 0.1));
    assert!((j.constraint_violation(&st) - 0.1f64.sin()).abs() < 1e-14);
}

#[test]
fn hinge_reaction_is_the_multiplier_force_and_has_no_moment_about_the_axis() {
    let a = Vector3::new(0.0, 0.0, 1.0);
    let (p, q) = normals(&a);
    let x0 = [Vector3::zeros(), Vector3::zeros()];
    let j = Joint::new(ElementId(1), JointType::Hinge { p, q, a }, vec![0, 1], &x0).unwrap();
    let mut st = random_states(&x0, 0.0, 0.0, 1);
    st[1].r = rotation::exp(&(a * 0.8));
    st[0].r = Matrix3::identity();
    let c = EvalContext {
        constraint_scale: 2.0,
        ..static_ctx()
    };
    let lam = [1.0, -2.0, 0.5, 0.3, -0.7];
    let (f, m) = j.reactions(&c, &st, &lam)[0];
    assert!((f - Vector3::new(-2.0, 4.0, -1.0)).norm() < 1e-12, "{f}");
    assert!(m.dot(&(st[1].r * a)).abs() < 1e-12, "{m}");
    assert!(m.norm() > 0.1);
}

#[test]
fn ujoint_angles_and_singularity() {
    let (a1, a2) = (Vector3::z(), Vector3::y());
    let x0 = [Vector3::zeros(), Vector3::zeros()];
    let mut j = Joint::new(
        ElementId(12),
        JointType::UJoint {
            a1,
            a2,
            b: a1.cross(&a2),
        },
        vec![0, 1],
        &x0,
    )
    .unwrap();
    let c = dyn_ctx();
    let base = rotation::exp(&Vector3::new(-0.3, 0.9, 0.2));
    let mut st = [NodeState::at_rest(x0[0]), NodeState::at_rest(x0[1])];
    st[0].r = base;
    for (t1, t2) in [(0.3, -0.2), (1.2, 0.4), (-2.5, 1.0)] {
        st[1].r = base * rotation::exp(&(a1 * t1)) * rotation::exp(&(a2 * t2));
        assert!(j.constraint_violation(&st) < 1e-14);
        let row = j.output_row(&c, &st, &[0.0; 4]);
        assert!(
            (row[0] - t1).abs() < 1e-12 && (row[1] - t2).abs() < 1e-12,
            "{row:?}"
        );
        assert!((row[2].cos() - t1.cos() * t2.cos()).abs() < 1e-12);
        assert!(j.singularity(&st).is_none());
    }
    // Bend of 90°: the shafts are perpendicular.
    st[1].r =
        base * rotation::exp(&(a1 * 0.3)) * rotation::exp(&(a2 * std::f64::consts::FRAC_PI_2));
    let msg = j.singularity(&st).expect("singular");
    assert!(msg.contains("UJOINT") && msg.contains("singular"), "{msg}");
    j.commit(&c, &st, &[0.0; 4]);
    let s = j.summary().unwrap();
    assert_eq!(s["singular_passages"], 1);
}

/// A driven HINGE and PRISMATIC (sixth equation g(q) − a f(t)): the tangent is the finite
/// difference of the residual at large rotations and far from the law.
#[test]
fn driven_joints_tangent_matches_finite_differences() {
    let a = Vector3::new(0.3, -0.5, 0.8).normalize();
    let (p, q) = normals(&a);
    let law = || {
        crate::elements::drive::TimeLaw::new(
            crate::model::Function::Haversine {
                start: 0.0,
                duration: 1.0,
            },
            40.0,
        )
    };
    let x0 = [Vector3::new(0.1, 0.2, -0.1), Vector3::new(0.4, -0.1, 0.3)];
    for kind in [
        JointType::Hinge { p, q, a },
        JointType::Prismatic { p, q, a },
    ] {
        let j = Joint::new(ElementId(7), kind, vec![0, 1], &x0)
            .unwrap()
            .with_drive(law())
            .unwrap();
        assert_eq!(j.multipliers(), 6);
        for seed in 1..4 {
            let st = random_states(&x0, 0.3, 1.5, seed);
            let mut g = Lcg(seed + 100);
            let lam: Vec<f64> = (0..6).map(|_| g.next() * 5.0).collect();
            let c = EvalContext { t: 0.3, ..ctx() };
            check_tangent(&j, &c, &st, &lam, 1e-7);
        }
    }
    // Other joints refuse a driver.
    let j = Joint::new(ElementId(8), JointType::Clamp, vec![0, 1], &x0).unwrap();
    assert!(j.with_drive(law()).is_err());
}

/// `B v` of [`Element::constraint_rates`] (one dual direction along the velocities) is the
/// constraint rows of the tangent (checked against finite differences above) applied to
/// `(v, Ω)`, divided by the scale: for every joint kind and a driven HINGE and PRISMATIC,
/// at large rotations, to round-off (1e-12 of the rows' size).
#[test]
fn constraint_rates_are_the_tangents_constraint_rows_times_the_velocities() {
    let a = Vector3::new(0.3, -0.5, 0.8).normalize();
    let (p, q) = normals(&a);
    let law = || {
        crate::elements::drive::TimeLaw::new(
            crate::model::Function::Haversine {
                start: 0.0,
                duration: 1.0,
            },
            40.0,
        )
    };
    let x0 = [
        Vector3::new(0.1, 0.2, -0.1),
        Vector3::new(0.4, -0.1, 0.3),
        Vector3::new(-0.2, 0.5, 0.1),
    ];
    let mut joints: Vec<Joint> = all_types()
        .into_iter()
        .map(|kind| {
            let n = if matches!(kind, JointType::Rigid) {
                3
            } else {
                2
            };
            Joint::new(ElementId(7), kind, (0..n).collect(), &x0[..n]).unwrap()
        })
        .collect();
    for kind in [
        JointType::Hinge { p, q, a },
        JointType::Prismatic { p, q, a },
    ] {
        joints.push(
            Joint::new(ElementId(8), kind, vec![0, 1], &x0[..2])
                .unwrap()
                .with_drive(law())
                .unwrap(),
        );
    }
    let c = EvalContext { t: 0.3, ..ctx() };
    for j in &joints {
        let n = j.nodes().len();
        let m = j.multipliers();
        for seed in 1..4 {
            let st = random_states(&x0[..n], 0.3, 1.5, seed);
            let lam = vec![0.0; m];
            let mut local = Local::new(6 * n + m);
            j.evaluate(&c, &st, &lam, true, &mut local);
            let mut rates = vec![0.0; m];
            assert!(j.constraint_rates(&st, &mut rates));
            for (k, r) in rates.iter().enumerate() {
                let mut bv = 0.0;
                let mut size = 0.0f64;
                for (i, s) in st.iter().enumerate() {
                    for d in 0..3 {
                        let (tx, tr) = (
                            local.tan_at(6 * n + k, 6 * i + d),
                            local.tan_at(6 * n + k, 6 * i + 3 + d),
                        );
                        bv += (tx * s.v[d] + tr * s.w[d]) / c.constraint_scale;
                        size = size.max((tx * s.v[d]).abs()).max((tr * s.w[d]).abs());
                    }
                }
                let size = size / c.constraint_scale;
                assert!(
                    (r - bv).abs() <= 1e-12 * size.max(1.0),
                    "{:?} row {k}: {r} vs {bv}",
                    j.kind()
                );
            }
        }
    }
}
