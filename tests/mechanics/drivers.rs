//! Drivers (issue 25 §2): hinges, prismatic joints and node motions prescribed in time,
//! against closed forms computed here.
//!
//! Tolerances. The driven coordinate is enforced at every step's end to Newton's
//! tolerance (index-3 constraint `g(q_{n+1}) = a f(t_{n+1})`), so the angle (travel) must
//! equal the law to round-off times the turns counted (≤ 1e-9 rad). The driving torque is
//! the multiplier, which HHT computes with a global error O(h²) (second-order accurate
//! for index-3 multipliers started from consistent accelerations, Arnold & Brüls 2007):
//! with h = 1e-3 s and the law's time scale T = 2 s, (h/T)²·|τ|max·C with C ≲ 10 gives a
//! relative error ≲ 3e-6; the tests allow 1e-4 of the torque's largest magnitude, and
//! check that halving h reduces the error (the order, not a tuned number).

use crate::common;

use common::deck;
use mecano::deck::parse_deck;
use mecano::model::Model;
use mecano::solver::{self, Observer, Snapshot};
use std::f64::consts::PI;

/// What a driven run records at every accepted step.
#[derive(Default)]
struct Rec {
    /// Element number whose output row is recorded.
    element: usize,
    t: Vec<f64>,
    rows: Vec<Vec<f64>>,
    /// Kinetic + strain + gravity energy, J.
    energy: Vec<f64>,
    /// Work of the loads and drivers since t = 0, J.
    work: Vec<f64>,
    /// Node positions (filled by [`NodeRec`]).
    pos: Vec<Vec<nalgebra::Vector3<f64>>>,
}

impl Observer for Rec {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let i = snap.integ;
        let ctx = i.current_context();
        let e = self.element;
        let el = &i.sys.elements[e];
        let o = i.sys.mult_offset[e];
        let lam = &i.lambda[o..o + el.multipliers()];
        self.t.push(i.t);
        self.rows.push(el.output_row(&ctx, &i.nodes, lam));
        let en = i.energies();
        self.energy.push(en.kinetic + en.strain + en.gravity);
        self.work.push(i.external_work);
        Ok(())
    }
}

/// Runs `model` recording element (dense index) `element`.
fn run(model: &Model, element: usize) -> Rec {
    let mut rec = Rec {
        element,
        ..Rec::default()
    };
    let rep = solver::run(model, &mut rec).expect("runs");
    assert!(rep.failure.is_none(), "{:?}", rep.failure);
    rec
}

/// The driven arm (m = 1 kg, L = 1 m, g = 9.81 m/s²): θ = A sin²(πt/T),
/// τ = m L² θ̈ + m g L cos θ.
fn arm_closed_form(t: f64, a: f64, tt: f64) -> (f64, f64) {
    let (m, l, g) = (1.0, 1.0, 9.81);
    let s = PI * t / tt;
    let th = a * s.sin().powi(2);
    let thdd = a * 2.0 * PI * PI / (tt * tt) * (2.0 * s).cos();
    (th, m * l * l * thdd + m * g * l * th.cos())
}

/// The largest |error| of the angle (law and `angle` column) and of the torque, and the
/// torque's largest magnitude, of a driven-arm run against the closed form of amplitude
/// `amp` and duration `tt`.
fn arm_errors(rec: &Rec, amp: f64, tt: f64) -> (f64, f64, f64) {
    let (mut e_angle, mut e_tau, mut tau_max) = (0.0f64, 0.0f64, 0.0f64);
    for (t, row) in rec.t.iter().zip(&rec.rows) {
        let (th, tau) = arm_closed_form(*t, amp, tt);
        // Columns: angle, prescribed, torque, fx … mz.
        e_angle = e_angle.max((row[0] - th).abs()).max((row[1] - th).abs());
        e_tau = e_tau.max((row[2] - tau).abs());
        tau_max = tau_max.max(tau.abs());
    }
    (e_angle, e_tau, tau_max)
}

/// (a) A hinge driven through a smooth law: the angle equals the law to Newton's
/// tolerance, the driving torque the closed form within HHT's O(h²), and halving h
/// divides the torque's error by about 4 (at least 3: the order is seen, not assumed).
#[test]
fn hinge_driven_by_a_smooth_law_gives_the_closed_form_torque() {
    let mut errs = Vec::new();
    for h in [2e-3, 1e-3] {
        let mut model = deck("driven_arm.dat");
        model.set_fixed_step(h, 2.0, None);
        let rec = run(&model, 0);
        let (e_angle, e_tau, tau_max) = arm_errors(&rec, PI, 2.0);
        eprintln!(
            "h = {h}: angle error {e_angle:.3e} rad, torque error {e_tau:.3e} N·m of {tau_max:.3} N·m"
        );
        assert!(e_angle < 1e-9, "angle error {e_angle:e}");
        assert!(e_tau < 1e-4 * tau_max, "torque error {e_tau:e}");
        errs.push(e_tau);
    }
    assert!(
        errs[0] > 3.0 * errs[1] || errs[1] < 1e-9 * 20.0,
        "torque errors {errs:?}: not second order"
    );
}

/// (d) The energy balance closes with the driver's work: |E − E₀ − W| against the
/// largest |W| (the trapezoidal work of τ θ̇ has an O(h²) error: (T/12) h² max|Ẅ|/… ≈
/// 1e-6 of W here; 1e-4 allowed), and W itself equals the closed form's E − E₀.
#[test]
fn energy_balance_closes_with_the_drivers_work() {
    let model = deck("driven_arm.dat");
    let rec = run(&model, 0);
    let (e0, w_max) = (
        rec.energy[0],
        rec.work.iter().fold(0.0f64, |m, w| m.max(w.abs())),
    );
    let mut worst = 0.0f64;
    for k in 0..rec.t.len() {
        worst = worst.max((rec.energy[k] - e0 - rec.work[k]).abs());
    }
    // Closed form of the work at the swing's top (t = T/2, θ = π, at rest): m g L sin π − 0
    // of gravity potential plus no kinetic energy: W(T/2) = m g L (sin θ(T/2) − sin 0) = 0;
    // at t = T/4 (θ = π/2, θ̇ = Aπ/T): W = ½ m L² θ̇² + m g L.
    let k = rec.t.iter().position(|t| (t - 0.5).abs() < 1e-9).unwrap();
    let w_quarter = 0.5 * (PI * PI / 2.0).powi(2) + 9.81;
    eprintln!(
        "max |E − E0 − W| = {worst:.3e} J of max |W| = {w_max:.3} J; W(T/4) = {:.6} J (closed form {w_quarter:.6})",
        rec.work[k]
    );
    assert!(w_max > 10.0, "the driver did work: {w_max}");
    assert!(worst < 1e-4 * w_max, "balance {worst:e} of {w_max}");
    assert!((rec.work[k] - w_quarter).abs() < 1e-4 * w_quarter);
}

/// (e) Many turns: 25 whole turns out and back at up to ω = Aπ/T ≈ 49 rad/s; the angle
/// is the law at every step (to 1e-9 rad after 157 rad: no drift, no singularity) and the
/// torque the closed form within HHT's O(h²): (ω h)² of the largest torque (2.4e-3 at
/// h = 1e-3 s).
#[test]
fn hinge_driven_through_many_turns_stays_exact() {
    let model = deck("driven_arm_turns.dat");
    let rec = run(&model, 0);
    let (e_angle, e_tau, tau_max) = arm_errors(&rec, 50.0 * PI, 10.0);
    let top = rec.rows.iter().map(|r| r[0]).fold(0.0f64, f64::max);
    eprintln!(
        "turns {:.3}: angle error {e_angle:.3e} rad, torque error {e_tau:.3e} of {tau_max:.3} N·m",
        top / (2.0 * PI)
    );
    assert!((top / (2.0 * PI) - 25.0).abs() < 1e-3, "top {top}");
    assert!(e_angle < 1e-9, "angle error {e_angle:e}");
    assert!(
        e_tau < 1e-3 * tau_max,
        "torque error {e_tau:e} of {tau_max}"
    );
}

/// A node's rotation prescribed about a fixed axis (`PRESCRIBED … ROTATION`): the arm
/// welded to the driven pivot turns as the law, and the driver's moment is the driven
/// arm's torque (same closed form and tolerance as the driven hinge).
#[test]
fn prescribed_rotation_drives_an_arm() {
    let rec = run(&deck("prescribed_rotation_arm.dat"), 0);
    // Columns: prescribed, angle, moment (arm_errors takes the first two as angles).
    let (e_angle, e_tau, tau_max) = arm_errors(&rec, PI, 2.0);
    eprintln!(
        "rotation: angle error {e_angle:.3e} rad, moment error {e_tau:.3e} N·m of {tau_max:.3} N·m"
    );
    assert!(e_angle < 1e-9, "angle error {e_angle:e}");
    assert!(e_tau < 1e-4 * tau_max, "moment error {e_tau:e}");
}

/// (b) A driven prismatic slider: the travel is the law, the force m s̈ + m g/√2.
#[test]
fn prismatic_driven_slider_force_is_m_times_acceleration() {
    let model = deck("driven_slider.dat");
    let rec = run(&model, 0);
    let (m, s_amp, tt, g) = (2.0, 0.3, 1.0, 9.81);
    let (mut e_s, mut e_f, mut f_max) = (0.0f64, 0.0f64, 0.0f64);
    for (t, row) in rec.t.iter().zip(&rec.rows) {
        let x = PI * t / tt;
        let s = s_amp * x.sin().powi(2);
        let sdd = s_amp * 2.0 * PI * PI / (tt * tt) * (2.0 * x).cos();
        let f = m * sdd + m * g / 2f64.sqrt();
        // Columns: slide, prescribed, force, fx … mz.
        e_s = e_s.max((row[0] - s).abs()).max((row[1] - s).abs());
        e_f = e_f.max((row[2] - f).abs());
        f_max = f_max.max(f.abs());
    }
    eprintln!("slide error {e_s:.3e} m, force error {e_f:.3e} N of {f_max:.3} N");
    assert!(e_s < 1e-9, "slide error {e_s:e}");
    assert!(e_f < 1e-4 * f_max, "force error {e_f:e}");
}

/// (b) with the stage schemes: they ran 0.03 s of `driven_slider.dat` and stopped (the
/// inner stages' velocity rows were a central difference, which the position-level last
/// stage took back with a force ∝ 1/h, docs/accuracy.md); with exact rows both run the
/// whole second, and the force of the rows they write — the index-1 multiplier at the
/// state, `m s̈ + m g/√2` for a point mass on a straight rail — is the closed form to
/// round-off (1e-9 of its scale allowed: the solve's ε times the condition of its
/// 12 equations).
#[test]
fn prismatic_driven_slider_with_the_stage_schemes() {
    for scheme in [
        mecano::model::Scheme::Esdirk3,
        mecano::model::Scheme::Esdirk5,
    ] {
        let mut model = deck("driven_slider.dat");
        if let mecano::model::Analysis::Dynamic { scheme: s, .. } = &mut model.analysis {
            *s = scheme;
        }
        let rec = run(&model, 0);
        assert!(
            (rec.t.last().unwrap() - 1.0).abs() < 1e-12,
            "{scheme} stopped"
        );
        let (m, s_amp, g) = (2.0, 0.3, 9.81);
        let (mut e_f, mut f_max) = (0.0f64, 0.0f64);
        for (t, row) in rec.t.iter().zip(&rec.rows) {
            let x = PI * t;
            let f = m * s_amp * 2.0 * PI * PI * (2.0 * x).cos() + m * g / 2f64.sqrt();
            e_f = e_f.max((row[2] - f).abs());
            f_max = f_max.max(f.abs());
        }
        eprintln!("{scheme}: force error {e_f:.3e} N of {f_max:.3} N");
        assert!(e_f < 1e-9 * f_max, "{scheme}: force error {e_f:e}");
    }
}

/// φ̈ of the base-excited pendulum (decks/base_excited_pendulum.dat).
fn pendulum_rhs(t: f64, y: [f64; 2]) -> [f64; 2] {
    let (g, l, xa, tt) = (9.81, 1.0, 0.1, 1.0);
    let xdd = if t <= tt {
        xa * 2.0 * PI * PI / (tt * tt) * (2.0 * PI * t / tt).cos()
    } else {
        0.0
    };
    [y[1], -(g / l) * y[0].sin() - xdd / l * y[0].cos()]
}

/// (c) A node's displacement prescribed: the pendulum whose pivot is moved along X
/// against RK4 of its equation (step 1e-4 s, error ~1e-14: an independent route). HHT's
/// phase error at h = 1e-3 s is O((ωh)²) per radian of motion, ω = 3.13 rad/s: ~1e-5
/// of the amplitude over 3 s; 1e-3 rad (of φmax ≈ 0.1 rad) allowed for the angle, 1e-3
/// of the force's scale for the force.
#[test]
fn prescribed_pivot_displacement_moves_the_pendulum_as_its_equation() {
    let model = deck("base_excited_pendulum.dat");
    let rec = run(&model, 2); // element 3, the PRESCRIBED, is dense index 2
    let mut states = Rec {
        element: 0,
        ..Rec::default()
    };
    let rep = solver::run(&model, &mut NodeRec(&mut states)).unwrap();
    assert!(rep.failure.is_none());
    // RK4 reference at 1e-4 s, sampled at the run's times (multiples of 1e-3 s).
    let hr = 1e-4;
    let mut y = [0.0, 0.0];
    let mut t = 0.0;
    let (mut e_phi, mut phi_max, mut e_f, mut f_max, mut e_x) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (k, tk) in rec.t.iter().enumerate() {
        while t < tk - 1e-12 {
            let f = |t: f64, y: [f64; 2]| pendulum_rhs(t, y);
            let k1 = f(t, y);
            let k2 = f(
                t + hr / 2.0,
                [y[0] + hr / 2.0 * k1[0], y[1] + hr / 2.0 * k1[1]],
            );
            let k3 = f(
                t + hr / 2.0,
                [y[0] + hr / 2.0 * k2[0], y[1] + hr / 2.0 * k2[1]],
            );
            let k4 = f(t + hr, [y[0] + hr * k3[0], y[1] + hr * k3[1]]);
            for i in 0..2 {
                y[i] += hr / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            t += hr;
        }
        let x = PI * tk;
        let xs = if *tk <= 1.0 {
            0.1 * x.sin().powi(2)
        } else {
            0.0
        };
        let xdd = pendulum_rhs(*tk, y);
        let xsdd = if *tk <= 1.0 {
            0.1 * 2.0 * PI * PI * (2.0 * x).cos()
        } else {
            0.0
        };
        let force = xsdd + (xdd[1] * y[0].cos() - y[1] * y[1] * y[0].sin());
        let row = &rec.rows[k];
        // Columns: prescribed, displacement, force.
        e_x = e_x.max((row[0] - xs).abs()).max((row[1] - xs).abs());
        e_f = e_f.max((row[2] - force).abs());
        f_max = f_max.max(force.abs());
        let (p1, p2) = (states.pos[k][0], states.pos[k][1]);
        let phi = (p2.x - p1.x).atan2(p1.y - p2.y);
        e_phi = e_phi.max((phi - y[0]).abs());
        phi_max = phi_max.max(y[0].abs());
    }
    eprintln!(
        "pivot error {e_x:.3e} m, angle error {e_phi:.3e} rad of {phi_max:.3}, force error {e_f:.3e} N of {f_max:.3} N"
    );
    // Energy: the driver's work W pays for E − E₀ but for HHT's numerical damping of the
    // free swing (damping ratio ≈ |α| ωh/2 ≈ 8e-5: a loss of 2ξωt ≈ 1.5e-3 of the
    // swing's energy over 3 s); 5e-3 of max(E − E₀, |W|) allowed.
    let e0 = rec.energy[0];
    let scale = rec
        .energy
        .iter()
        .zip(&rec.work)
        .fold(0.0f64, |m, (e, w)| m.max((e - e0).abs()).max(w.abs()));
    let balance = rec
        .energy
        .iter()
        .zip(&rec.work)
        .fold(0.0f64, |m, (e, w)| m.max((e - e0 - w).abs()));
    eprintln!("base excitation: |E − E0 − W| ≤ {balance:.3e} J of {scale:.3e} J");
    assert!(balance < 5e-3 * scale, "balance {balance:e} of {scale:e}");
    assert!(e_x < 1e-9, "pivot displacement error {e_x:e}");
    assert!(e_phi < 1e-2 * phi_max, "angle error {e_phi:e}");
    assert!(e_f < 1e-2 * f_max, "force error {e_f:e}");
}

/// Node positions of every accepted state.
struct NodeRec<'a>(&'a mut Rec);

impl Observer for NodeRec<'_> {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let x = snap.integ.nodes.iter().map(|s| s.x).collect();
        self.0.pos.push(x);
        Ok(())
    }
}

/// (g) Bad input: located deck errors (line, column, what), and the binary exits with 2
/// and writes nothing.
#[test]
fn bad_drivers_are_located_deck_errors() {
    let head = "NODES\n 1 0 0 0 FIX ALL\n 2 1 0 0\n 3 0 1 0 FIX X\nFUNCTIONS\n 1 HAVERSINE 0 1\n 2 TABLE 0 0 1 1\n 3 CONSTANT 0.5\nELEMENTS\n";
    let tail = "\nANALYSIS DYNAMIC STEP 1e-3 END 1\n";
    let cases: [(&str, usize, usize, &str); 11] = [
        (
            " 1 UJOINT 1 2 AXIS1 0 0 1 AXIS2 0 1 0 DRIVE 1",
            10,
            39,
            "only a HINGE",
        ),
        (" 1 SPHERICAL 1 2 DRIVE 1", 10, 18, "only a HINGE"),
        (" 1 CLAMP 1 2 DRIVE 1", 10, 14, "only a HINGE"),
        (" 1 RIGID 1 2 DRIVE 1", 10, 14, "only a HINGE"),
        (
            " 1 HINGE 1 2 AXIS 0 0 1 DRIVE 2",
            10,
            31,
            "function 2 has no derivatives",
        ),
        (
            " 1 HINGE 1 2 AXIS 0 0 1 DRIVE 7",
            10,
            31,
            "undefined function 7",
        ),
        (
            " 1 HINGE 1 2 AXIS 0 0 1 DRIVE 1 DRIVE 1",
            10,
            33,
            "a second DRIVE",
        ),
        (" 1 PRESCRIBED 3 X FUNCTION 1", 10, 15, "fixed in X"),
        (
            " 1 PRESCRIBED 2 Y FUNCTION 1\n 2 PRESCRIBED 2 Y FUNCTION 1 AMPLITUDE 2",
            11,
            15,
            "already prescribes",
        ),
        // A driven joint and a PRESCRIBED node motion that set one motion twice (node 1
        // is fixed): located at the PRESCRIBED card, whichever comes first.
        (
            " 1 PRESCRIBED 2 ROTATION AXIS 0 0 1 FUNCTION 1\n 2 HINGE 1 2 AXIS 0 0 1 DRIVE 1",
            10,
            2,
            "two drivers would fight",
        ),
        (
            " 1 PRISMATIC 1 2 AXIS 1 0 0 DRIVE 1\n 2 PRESCRIBED 2 Y FUNCTION 1",
            11,
            2,
            "two drivers would fight",
        ),
    ];
    for (card, line, col, gist) in cases {
        let text = format!("{head}{card}{tail}");
        let errs = match parse_deck(&text, "bad.dat") {
            Ok(_) => panic!("accepted:\n{text}"),
            Err(e) => e,
        };
        let msg = errs.errors()[0].to_string();
        assert_eq!(errs.line_col(0), Some((line, col)), "{card}: {msg}");
        assert!(msg.contains(gist), "{card}: {msg}");
    }
    // The binary: exit 2, no output directory.
    let tmp = common::TempDir::new("drivers_bad");
    let bad = tmp.join("bad.dat");
    std::fs::write(&bad, format!("{head} 1 CLAMP 1 2 DRIVE 1{tail}")).unwrap();
    let out_dir = tmp.join("out");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&bad)
        .arg("-o")
        .arg(&out_dir)
        .output()
        .expect("binary runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("only a HINGE"), "{err}");
    assert!(!out_dir.exists());
}

/// `--check` lists the drivers among the scene's effects; a driven joint counts one more
/// constraint.
#[test]
fn drivers_are_effects_of_the_scene() {
    let m = deck("driven_arm.dat");
    assert!(m.effects().names().contains(&"drivers"));
    assert_eq!(m.summary().constraints, 6);
    let m = deck("base_excited_pendulum.dat");
    assert!(m.effects().drivers);
    assert_eq!(m.summary().constraints, 6);
    assert!(!deck("simple_pendulum.dat").effects().drivers);
}

/// INITIAL velocities that contradict a driver are overridden (grammar.md, "Drivers"):
/// the driven arm given a spin of 5 rad/s at t = 0, where its law's rate ḟ(0) is 0,
/// starts at rest all the same, and its torque is the closed form from the first step
/// (without the projection the first steps would carry a velocity jump, an impulsive
/// torque of J·5 rad/s over one step: 5000 N·m at h = 1e-3 s).
#[test]
fn initial_velocities_contradicting_a_drive_are_overridden() {
    let mut model = deck("driven_arm.dat");
    model.initial.push(mecano::model::InitialVelocity {
        node: mecano::model::NodeId(2),
        velocity: nalgebra::Vector3::new(0.0, 5.0, 0.0),
        angular: nalgebra::Vector3::new(0.0, 0.0, 5.0),
        span: Default::default(),
    });
    let rec = run(&model, 0);
    let (e_angle, e_tau, tau_max) = arm_errors(&rec, PI, 2.0);
    eprintln!(
        "with a contradicting INITIAL spin: angle error {e_angle:.3e}, torque error {e_tau:.3e} of {tau_max:.3}"
    );
    assert!(e_angle < 1e-9);
    assert!(e_tau < 1e-4 * tau_max, "torque error {e_tau:e}");
    // The kinetic energy at t = 0 is the law's: zero.
    assert!(rec.energy[0].abs() < 1e-12, "E(0) = {}", rec.energy[0]);
}

/// Every node's position, velocity and angular velocity at the first recorded state
/// (t = 0, after the start's projection), and the driven joint's rows over the run.
#[derive(Default)]
struct StartRec {
    inner: Rec,
    start: Vec<[nalgebra::Vector3<f64>; 3]>,
}

impl Observer for StartRec {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        if self.start.is_empty() {
            self.start = snap.integ.nodes.iter().map(|s| [s.x, s.v, s.w]).collect();
        }
        self.inner.state(snap)
    }
}

/// A deck of an arm turning at constant speed ω about Z from t = 0, its hinge driven by
/// θ = ω t (`FUNCTIONS … EXPR`: ḟ(0) = ω ≠ 0, the start must project the velocities).
/// `body` the arm's cards after the hinge (element 1), `more` further sections.
fn constant_speed_deck(w: f64, h: f64, nodes: &str, body: &str, more: &str) -> Model {
    let text = format!(
        "PARAMETERS\n  w {w}\nFUNCTIONS\n  1 EXPR $w*t\nNODES\n  1 0 0 0 FIX ALL\n{nodes}\nELEMENTS\n  1 HINGE 1 2 AXIS 0 0 1 DRIVE 1\n{body}\n{more}\nANALYSIS DYNAMIC ALPHA -0.05 STEP {h} END 1.0\n"
    );
    parse_deck(&text, "constant_speed.dat").unwrap_or_else(|e| panic!("{e:?}"))
}

/// A hinge driven at constant speed from t = 0, the first law whose rate ḟ(0) is not 0
/// (the slider-cranks of decks/benchmarks/ are driven so).
///
/// (1) A point mass m = 1 kg on a massless arm L = 1 m (the driven arm's geometry), under
/// gravity, at ω = 10 rad/s, no INITIAL velocity: the start's projection onto B v = ω must
/// give the rigid field v₂ = ω ẑ × x₂ exactly (the only velocity the hinge and the driver
/// allow: to round-off, 1e-12 ωL), hence E(0) = ½ m ω² L². The angle is the law ω t to
/// Newton's tolerance at every step (1e-9 rad, as the other drivers).
///
/// The torque's closed form (θ̈ = 0) is τ = m g L cos ω t. What HHT makes of it:
/// - **A start transient.** The motion's jerk J = ω³L is not 0 at t = 0 (the centripetal
///   acceleration turns), and HHT started from the exact acceleration with index-3
///   constraints errs in its first step's acceleration by O(hJ) (Arnold & Brüls 2007: the
///   acceleration-like variable would have to start at v̇(t₀ + αh)): the position update
///   `x₁ = x₀ + h v₀ + h²((½ − β)a₀ + βa₁)` with x₁ exact gives `a₁ − v̇(h) ≈ hJ(1/(6β) − 1)`,
///   plus the |α| hJ of the start. The error then follows the scheme's spurious roots
///   (computed below from β, γ: a complex pair of modulus ρ = 0.905 for α = −0.05, HHT's
///   ρ∞ = (1 + α)/(1 − α)), growing at most like n ρⁿ, whose peak is 1/(e |ln ρ|) = 3.7.
///   Allowed: m L (|1/(6β) − 1| + |α|) hJ /(e |ln ρ|)/(1 + α) (1.7 N·m at h = 1e-3 s, of a
///   torque of 9.81 N·m; measured 1.37), and halving h must halve the transient (first
///   order: ratio between 1.5 and 2.5; measured 1.99).
/// - **After it** (t ≥ 0.3 s: ≥ 300 steps, ρ³⁰⁰·300 < 1e-8), HHT's O(h²): (ωh)² m ω² L. For
///   a uniform rotation the discrete solution is itself a uniform rotation, so its
///   tangential error vanishes and what is left is Newton's tolerance (measured ~1e-6 N·m).
///
/// The energy balance closes with the driver's work to the work of the torque's error:
/// |E − E₀ − W| ≤ ω h Σ|τ − τ_exact| (trapezoidal, over the steps) + (ωh)² |W|max.
///
/// (2) A flexible arm (three beams, 1 m, steel-like) given its rigid field by INITIAL
/// (`W 0 0 ω ABOUT 0 0 0`, the way the slider-crank decks start): that field already meets
/// B v = ω, so the projection (the smallest change in the kinetic-energy norm) leaves every
/// node's velocity as it was, to round-off. (Without INITIAL it would give the hub its
/// spin and leave the beam's nodes at rest: the smallest correction is not the rigid one.)
#[test]
fn hinge_driven_at_constant_speed_from_t0() {
    let (w, m, l, g): (f64, f64, f64, f64) = (10.0, 1.0, 1.0, 9.81);
    // HHT's parameters for the deck's α = −0.05, and the spurious roots of its
    // acceleration recursion with exact positions: [ε; u]ₙ₊₁ = A [ε; u]ₙ (ε the
    // acceleration's error, u = η/h the velocity's over h).
    let alpha: f64 = -0.05;
    let (beta, gamma) = ((1.0 - alpha).powi(2) / 4.0, 0.5 - alpha);
    let a11 = -(0.5 - beta) / beta;
    let a12 = -1.0 / beta;
    let a21 = (1.0 - gamma) + gamma * a11;
    let a22 = 1.0 + gamma * a12;
    let (tr, det) = (a11 + a22, a11 * a22 - a12 * a21);
    let disc = tr * tr - 4.0 * det;
    let rho = if disc >= 0.0 {
        0.5 * (tr.abs() + disc.sqrt())
    } else {
        det.sqrt()
    };
    let peak_factor = 1.0 / (std::f64::consts::E * rho.ln().abs());
    let jerk = w.powi(3) * l;
    let mut transients = Vec::new();
    for h in [1e-3, 5e-4] {
        let model = constant_speed_deck(
            w,
            h,
            "  2 1 0 0",
            "  2 MASS 2 M 1",
            "LOADS\n  GRAVITY 0 -9.81 0",
        );
        let mut rec = StartRec::default();
        let rep = solver::run(&model, &mut rec).expect("runs");
        assert!(rep.failure.is_none(), "{:?}", rep.failure);
        let [x2, v2, w2] = rec.start[1];
        let rigid = nalgebra::Vector3::new(0.0, 0.0, w).cross(&x2);
        let e_v0 = (v2 - rigid).norm().max((w2.z - w).abs() * l);
        let (mut e_angle, mut tau_max, mut transient, mut after) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let (mut e_bal, mut w_max, mut err_work) = (0.0f64, 0.0f64, 0.0f64);
        let r = &rec.inner;
        let mut last_err = 0.0;
        for k in 0..r.t.len() {
            let th = w * r.t[k];
            let tau = m * g * l * th.cos();
            // Columns: angle, prescribed, torque, fx … mz.
            e_angle = e_angle
                .max((r.rows[k][0] - th).abs())
                .max((r.rows[k][1] - th).abs());
            let err = r.rows[k][2] - tau;
            if r.t[k] < 0.3 {
                transient = transient.max(err.abs());
            } else {
                after = after.max(err.abs());
            }
            if k > 0 {
                err_work += 0.5 * (err.abs() + last_err) * w * (r.t[k] - r.t[k - 1]);
            }
            last_err = err.abs();
            tau_max = tau_max.max(tau.abs());
            w_max = w_max.max((m * g * l * th.sin()).abs());
            e_bal = e_bal.max((r.energy[k] - r.energy[0] - r.work[k]).abs());
        }
        let e0 = 0.5 * m * (w * l).powi(2);
        let allowed_transient =
            m * l * ((1.0 / (6.0 * beta) - 1.0).abs() + alpha.abs()) * h * jerk * peak_factor
                / (1.0 + alpha);
        let allowed_after = (w * h).powi(2) * m * w * w * l;
        let allowed_balance = err_work + (w * h).powi(2) * w_max;
        eprintln!(
            "constant speed, h = {h}: |v(0) − ω×x| {e_v0:.2e} m/s, E(0) {:.12} J (½mω²L² {e0}), \
             angle error {e_angle:.2e} rad; torque error (of {tau_max:.3} N·m): start transient \
             {transient:.3e} (allowed {allowed_transient:.2e}; ρ = {rho:.4}), after 0.3 s \
             {after:.2e} (allowed {allowed_after:.1e}); |E − E0 − W| {e_bal:.2e} J (allowed \
             {allowed_balance:.2e})",
            r.energy[0],
        );
        assert!(e_v0 <= 1e-12 * w * l, "start velocity {e_v0:e}");
        assert!(
            (r.energy[0] - e0).abs() <= 1e-12 * e0,
            "E(0) {}",
            r.energy[0]
        );
        assert!(e_angle < 1e-9, "angle error {e_angle:e}");
        assert!(transient <= allowed_transient, "transient {transient:e}");
        assert!(after <= allowed_after, "torque error {after:e}");
        assert!(e_bal <= allowed_balance, "balance {e_bal:e}");
        transients.push(transient);
    }
    let ratio = transients[0] / transients[1];
    assert!(
        (1.5..=2.5).contains(&ratio),
        "start transients {transients:?}: not first order in h"
    );

    // (2) The flexible arm started with its rigid field.
    let model = constant_speed_deck(
        w,
        1e-3,
        "  2 0 0 0\n  3 TO 5 LINE 1/3 0 0 1 0 0",
        "  2 TO 4 BEAM 2 3 MAT 1 SEC 1",
        "MATERIALS\n  1 E 2e11 NU 0.3 RHO 7800\nSECTIONS\n  1 A 1e-4 I2 1e-9 I3 1e-9 J 2e-9\nINITIAL\n  2 TO 5 W 0 0 $w ABOUT 0 0 0",
    );
    let mut rec = StartRec::default();
    let rep = solver::run(&model, &mut rec).expect("runs");
    assert!(rep.failure.is_none(), "{:?}", rep.failure);
    let spin = nalgebra::Vector3::new(0.0, 0.0, w);
    let e_field = rec
        .start
        .iter()
        .skip(1)
        .map(|[x, v, om]| (v - spin.cross(x)).norm().max((om - spin).norm() * l))
        .fold(0.0, f64::max);
    eprintln!("flexible arm: largest |v(0) − ω×x|, |ω(0) − ω| L over its nodes {e_field:.2e} m/s");
    assert!(e_field <= 1e-12 * w * l, "start field {e_field:e}");
}
