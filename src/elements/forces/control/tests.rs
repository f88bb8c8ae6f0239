use super::*;
use crate::elements::testing::*;
use crate::model::FunctionId;
use crate::model::control::{HeldValue, Pid};

const PENDULUM: &str = include_str!("../../../../decks/simple_pendulum.dat");
const ARM: &str = include_str!("../../../../decks/driven_arm.dat");

/// A smooth nonlinear law of four sensors, with its exact gradient.
struct Smooth;
impl Law for Smooth {
    fn eval(&self, t: f64, s: &[f64], grad: Option<&mut [f64]>) -> f64 {
        if let Some(g) = grad {
            g[0] = 3.0;
            g[1] = 2.0 * s[1];
            g[2] = s[2].cos();
            g[3] = -1.5 * t;
        }
        3.0 * s[0] + s[1] * s[1] + s[2].sin() - 1.5 * t * s[3]
    }
}

fn model_with(text: &str, data: ControlData) -> (Model, Control) {
    let mut m = crate::deck::parse_deck(text, "deck").expect("deck parses");
    m.add_control(ElementId(9), data).expect("control added");
    let el = m.elements[&ElementId(9)].clone();
    let ElementKind::Control(d) = &el.kind else {
        unreachable!()
    };
    let c = Control::from_model(&m, &el, d).expect("built");
    (m, c)
}

fn all_sensors() -> Vec<Sensor> {
    vec![
        Sensor::HingeAngle(ElementId(1)),
        Sensor::HingeRate(ElementId(1)),
        Sensor::Coordinate(crate::model::NodeId(2), 1),
        Sensor::Velocity(crate::model::NodeId(2), 0),
    ]
}

/// The iteration matrix of an input on every kind of sensor, a hinge torque and a nodal
/// force, against central differences of the residual (tolerance as RSPRING's: 1e-6 of
/// the largest entry), off the hinge's motions (random rotations of 0.5 rad).
#[test]
fn tangent_matches_finite_differences() {
    for actuator in [
        Actuator::HingeTorque(ElementId(1)),
        Actuator::NodeForce(crate::model::NodeId(2), 1),
    ] {
        let (m, c) = model_with(
            PENDULUM,
            ControlData {
                actuator,
                sensors: all_sensors(),
                law: ControlLaw::External(Arc::new(Smooth)),
            },
        );
        let x0: Vec<_> = m.nodes.values().map(|n| n.position).collect();
        for seed in 1..4 {
            let st = random_states(&x0, 0.1, 0.5, seed);
            let mut ctx = dyn_ctx();
            ctx.t = 0.3;
            check_tangent(&c, &ctx, &st, &[], 1e-6);
        }
    }
}

/// The PID's tangent (with its integral's `½ k_i (t − t_n)`) against central differences.
#[test]
fn pid_tangent_matches_finite_differences() {
    let (m, mut c) = model_with(
        ARM,
        ControlData {
            actuator: Actuator::HingeTorque(ElementId(1)),
            sensors: vec![
                Sensor::HingeAngle(ElementId(1)),
                Sensor::HingeRate(ElementId(1)),
            ],
            law: ControlLaw::Pid(Pid {
                kp: 40.0,
                ki: 15.0,
                kd: 6.0,
                target: FunctionId(1),
                amplitude: 0.7,
            }),
        },
    );
    let x0: Vec<_> = m.nodes.values().map(|n| n.position).collect();
    let st = random_states(&x0, 0.0, 0.4, 5);
    let mut ctx = dyn_ctx();
    ctx.t = 0.1;
    c.commit(&ctx, &st, &[]);
    ctx.t = 0.35;
    check_tangent(&c, &ctx, &st, &[], 1e-6);
}

/// On the hinge's motions the sensors read the closed forms, a held value is applied as a
/// torque `u` on node 2 about the axis (`−u` on node 1), and the input's power is `u θ̇`.
#[test]
fn held_torque_and_sensors_on_hinge_motions() {
    let held = HeldValue::new(2.5);
    let (_, mut c) = model_with(
        PENDULUM,
        ControlData {
            actuator: Actuator::HingeTorque(ElementId(1)),
            sensors: all_sensors(),
            law: ControlLaw::Held(held.clone()),
        },
    );
    let ctx = dyn_ctx();
    let mut st = vec![
        NodeState::at_rest(Vector3::zeros()),
        NodeState::at_rest(Vector3::x()),
    ];
    // Three turns and a bit, committed step by step: the angle counts them.
    let n = 50;
    let total = 3.3 * std::f64::consts::TAU;
    for i in 1..=n {
        let th = total * i as f64 / n as f64;
        st[1].r = crate::rotation::exp(&(Vector3::z() * th));
        st[1].x = Vector3::new(th.cos(), th.sin(), 0.0);
        st[1].v = Vector3::new(-th.sin(), th.cos(), 0.0) * 1.5;
        st[1].w = Vector3::z() * 1.5;
        c.commit(&ctx, &st, &[]);
        let row = c.output_row(&ctx, &st, &[]);
        assert_eq!(row[0], 2.5);
        assert!((row[1] - th).abs() < 1e-12, "angle {} vs {th}", row[1]);
        assert!((row[2] - 1.5).abs() < 1e-12);
        assert!((row[3] - th.sin()).abs() < 1e-15);
        assert!((row[4] + 1.5 * th.sin()).abs() < 1e-15);
    }
    let mut out = Local::new(12);
    c.evaluate(&ctx, &st, &[], false, &mut out);
    // Material moments: node 2 receives +u about its material z (= global z here).
    assert!((out.res[rx(1) + 2] + 2.5).abs() < 1e-14);
    assert!((out.res[rx(0) + 2] - 2.5).abs() < 1e-14);
    assert!((c.input_power(&ctx, &st, &[]) - 2.5 * 1.5).abs() < 1e-13);
    held.set(-1.0);
    assert_eq!(c.output_row(&ctx, &st, &[])[0], -1.0);
    // Checkpoints: the angles' turns come back.
    let saved = c.save_state();
    let (_, mut d) = model_with(
        PENDULUM,
        ControlData {
            actuator: Actuator::HingeTorque(ElementId(1)),
            sensors: all_sensors(),
            law: ControlLaw::Held(held),
        },
    );
    d.restore_state(&saved).expect("same kind");
    assert_eq!(d.output_row(&ctx, &st, &[]), c.output_row(&ctx, &st, &[]));
}

/// References that do not exist, or are not hinges, are refused when the input is added.
#[test]
fn bad_references_are_refused() {
    let mut m = crate::deck::parse_deck(PENDULUM, "deck").unwrap();
    let data = |actuator, sensors| ControlData {
        actuator,
        sensors,
        law: ControlLaw::Held(HeldValue::new(0.0)),
    };
    use crate::model::control::ControlError as E;
    assert_eq!(
        m.add_control(
            ElementId(1),
            data(Actuator::HingeTorque(ElementId(1)), vec![])
        ),
        Err(E::Taken(1))
    );
    assert_eq!(
        m.add_control(
            ElementId(5),
            data(Actuator::HingeTorque(ElementId(2)), vec![])
        ),
        Err(E::NotAHinge(2))
    );
    assert_eq!(
        m.add_control(
            ElementId(5),
            data(Actuator::NodeForce(crate::model::NodeId(7), 0), vec![])
        ),
        Err(E::NoNode(7))
    );
    assert_eq!(
        m.add_control(
            ElementId(5),
            data(
                Actuator::NodeForce(crate::model::NodeId(2), 0),
                vec![Sensor::Velocity(crate::model::NodeId(2), 3)]
            )
        ),
        Err(E::Axis(3))
    );
}

/// The deck's law of sensors (`CONTROL … LAW`): the same smooth law as [`Smooth`] written
/// as an expression gives the same value, its jets' gradient the hand-written one (to
/// round-off), and the element's iteration matrix passes the central differences of its
/// residual on every kind of sensor.
#[test]
fn expression_law_is_exact_and_its_tangent_matches_finite_differences() {
    let (expr, refs) =
        crate::deck::expr::parse_law("3*angle(1)+rate(1)^2+sin(y(2))-1.5*t*vx(2)", &|_| None)
            .expect("parses");
    let sensors: Vec<Sensor> = refs.iter().map(|r| r.0).collect();
    assert_eq!(sensors, all_sensors());
    for (t, s) in [(0.3, [0.2, -1.1, 0.7, 2.0]), (2.0, [-3.0, 0.5, -0.2, -0.4])] {
        let (mut g, mut want) = ([0.0; 4], [0.0; 4]);
        let u = expr.law(t, &s, Some(&mut g));
        let v = Smooth.eval(t, &s, Some(&mut want));
        assert!((u - v).abs() <= 1e-14 * v.abs().max(1.0), "{u} {v}");
        for k in 0..4 {
            assert!(
                (g[k] - want[k]).abs() <= 1e-14 * want[k].abs().max(1.0),
                "{k}"
            );
        }
    }
    let law = crate::model::TimeExpr {
        text: String::new(),
        expr,
        field: Default::default(),
    };
    for actuator in [
        Actuator::HingeTorque(ElementId(1)),
        Actuator::NodeForce(crate::model::NodeId(2), 1),
    ] {
        let (m, c) = model_with(
            PENDULUM,
            ControlData {
                actuator,
                sensors: sensors.clone(),
                law: ControlLaw::Expr(law.clone()),
            },
        );
        let x0: Vec<_> = m.nodes.values().map(|n| n.position).collect();
        for seed in 1..4 {
            let st = random_states(&x0, 0.1, 0.5, seed);
            let mut ctx = dyn_ctx();
            ctx.t = 0.3;
            check_tangent(&c, &ctx, &st, &[], 1e-6);
        }
    }
}
