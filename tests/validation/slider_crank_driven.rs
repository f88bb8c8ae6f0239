//! Reactions and driving torques at the integrator's order (issue 34 §6):
//! `decks/slider_crank_driven.dat`, a rigid slider-crank whose crank a HINGE's driver turns
//! at constant speed `θ = ωt`, under gravity, against its closed-form inverse dynamics.
//!
//! The mechanism has no degree of freedom: its positions are the kinematics of `θ(t)` (every
//! run holds them to round-off), its velocities are the scheme's quadrature of the stage
//! accelerations (third order with ESDIRK3, fifth with ESDIRK5 here), and the driving torque
//! and the crank pin's force follow from the accelerations. With the multipliers of a stiffly
//! accurate ESDIRK's last stage those converged at the stage order, 2 (docs/accuracy.md,
//! "Reactions at the integrator's order"); the rows a run writes now carry the index-1
//! equations' multipliers at the row's `(q, v)`, which converge as the velocities do.

use crate::common;

use common::{TempDir, deck, deck_path};
use mecano::model::{Model, Scheme};
use mecano::solver::{self, Observer, Snapshot};
use std::f64::consts::PI;

// The deck's data (decks/slider_crank_driven.dat).
const R: f64 = 0.1;
const L: f64 = 0.3;
const OMEGA: f64 = 2.0 * PI;
const G: f64 = 9.81;
const M_CRANK: f64 = 1.0;
const M_ROD: f64 = 2.0;
const J_ROD: f64 = 1.5e-2;
const M_SLIDER: f64 = 1.0;

type V2 = [f64; 2];

fn add(a: V2, b: V2) -> V2 {
    [a[0] + b[0], a[1] + b[1]]
}

fn half(a: V2) -> V2 {
    [a[0] / 2.0, a[1] / 2.0]
}

fn dot(a: V2, b: V2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn cross(a: V2, b: V2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// The closed-form inverse dynamics at crank angle `θ` (`θ̇ = ω`, `θ̈ = 0`): the driving
/// torque and the force the crank pin (the SPHERICAL) exerts on the rod.
///
/// Kinematics, with `P = r(cos θ, sin θ)` the crank pin, `D = √(l² − r² sin²θ)`, the slider
/// `S = (r cos θ + D, 0)`, the rod's angle `φ` (`sin φ = −r sin θ / l`, so `φ' = −r cos θ/D`),
/// the crank's centre `P/2` and the rod's `G = (P + S)/2`; derivatives in `θ` (′), so that
/// velocities are `ω (·)′` and accelerations `ω² (·)″`:
/// `D′ = −r² sin θ cos θ / D`, `D″ = −r² cos 2θ / D − (r² sin θ cos θ)² / D³`,
/// `φ″ = r sin θ / D + r cos θ D′ / D²`.
///
/// Torque by virtual work (the driver's power `τω` is the rate of kinetic and potential
/// energy): `τ = Σ mᵢ aᵢ·xᵢ′ + J_rod ω² φ″ φ′ + g Σ mᵢ yᵢ′` (the crank turns at constant
/// speed: its own inertia takes no torque).
///
/// Pin force by Newton–Euler: the slider `m_s a_S = −F_U + N ŷ − m_s g ŷ` (`F_U` the rod's
/// force on the slider's pin, `N` the guide's), the rod `m_r a_G = F_P + F_U − m_r g ŷ`,
/// `J φ̈ = (P − G) × F_P + (S − G) × F_U`: `F_Ux = −m_s a_Sx`, then `F_Px` from the rod's x
/// equation and `(F_Py, F_Uy)` from its y and moment equations.
fn inverse_dynamics(th: f64) -> (f64, V2) {
    let (s, c) = th.sin_cos();
    let d = (L * L - R * R * s * s).sqrt();
    let d1 = -R * R * s * c / d;
    let d2 = -R * R * (2.0 * th).cos() / d - (R * R * s * c).powi(2) / d.powi(3);
    let w2 = OMEGA * OMEGA;
    let p = [R * c, R * s];
    let (p1, p2) = ([-R * s, R * c], [-R * c, -R * s]);
    let sl = [R * c + d, 0.0];
    let (s1, s2) = ([-R * s + d1, 0.0], [-R * c + d2, 0.0]);
    let (phi1, phi2) = (-R * c / d, R * s / d + R * c * d1 / (d * d));
    let (c1, c2) = (half(p1), half(p2));
    let (g, g1, g2) = (half(add(p, sl)), half(add(p1, s1)), half(add(p2, s2)));
    let tau = w2
        * (M_CRANK * dot(c2, c1)
            + M_ROD * dot(g2, g1)
            + J_ROD * phi2 * phi1
            + M_SLIDER * dot(s2, s1))
        + G * (M_CRANK * c1[1] + M_ROD * g1[1] + M_SLIDER * s1[1]);
    // Newton–Euler for the pin force.
    let (a_g, a_s, phidd) = ([w2 * g2[0], w2 * g2[1]], w2 * s2[0], w2 * phi2);
    let fux = -M_SLIDER * a_s;
    let fpx = M_ROD * a_g[0] - fux;
    // Unknowns (fpy, fuy): fpy + fuy = m_r (a_Gy + g);
    // (P−G)x fpy − (P−G)y fpx + (S−G)x fuy − (S−G)y fux = J φ̈.
    let (pg, sg) = ([p[0] - g[0], p[1] - g[1]], [sl[0] - g[0], sl[1] - g[1]]);
    let sum = M_ROD * (a_g[1] + G);
    let rhs = J_ROD * phidd + pg[1] * fpx + sg[1] * fux;
    // pg[0] fpy + sg[0] (sum − fpy) = rhs.
    let fpy = (rhs - sg[0] * sum) / (pg[0] - sg[0]);
    debug_assert!(
        (cross(pg, [fpx, fpy]) + cross(sg, [fux, sum - fpy]) - J_ROD * phidd).abs() < 1e-9
    );
    (tau, [fpx, fpy])
}

/// The driving torque and the pin force of every accepted state, read as a writer reads
/// them (an observer that reads reactions: the default).
#[derive(Default)]
struct Rows {
    t: Vec<f64>,
    tau: Vec<f64>,
    pin: Vec<V2>,
}

impl Observer for Rows {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let i = snap.integ;
        let ctx = i.current_context();
        let row = |e: usize| {
            i.sys.elements[e].output_row(&ctx, &i.nodes, i.sys.element_lambda(e, &i.lambda))
        };
        // Element 3 (the driven HINGE, dense 2): angle, prescribed, torque, …; element 4 (the
        // SPHERICAL, dense 3): fx, fy, fz, mx, my, mz on the rod's node.
        let (hinge, pin) = (row(2), row(3));
        self.t.push(i.t);
        self.tau.push(hinge[2]);
        self.pin.push([pin[0], pin[1]]);
        Ok(())
    }
}

/// The largest errors of the torque and of the pin force over the rows of a run at step
/// `h` to `end`, and the torque's error at the last row.
fn errors(scheme: Scheme, h: f64, end: f64) -> (f64, f64, f64) {
    let mut model: Model = deck("slider_crank_driven.dat");
    assert!(model.set_fixed_step(h, end, Some(scheme)));
    let mut rows = Rows::default();
    let rep = solver::run(&model, &mut rows).expect("run starts");
    assert!(rep.failure.is_none(), "{:?}", rep.failure);
    assert!((rows.t.last().copied().unwrap() - end).abs() < 1e-12);
    let (mut et, mut ef, mut last) = (0.0f64, 0.0f64, 0.0);
    for k in 0..rows.t.len() {
        let (tau, pin) = inverse_dynamics(OMEGA * rows.t[k]);
        last = (rows.tau[k] - tau).abs();
        et = et.max(last);
        ef = ef.max((rows.pin[k][0] - pin[0]).hypot(rows.pin[k][1] - pin[1]));
    }
    (et, ef, last)
}

/// The floor of the reactions' error, N·m (and N per 0.1 m of arm): the index-1 solve's
/// `Ḃv` is a central difference of the exact `B v` with `εω = 1e-5` (truncation
/// `(εω)²/6 ≈ 2e-11`, round-off `ε_mach/(εω) ≈ 2e-11` of the centripetal terms,
/// `m r ω² ≈ 4 N` on a 0.1 m arm: ~1e-11 N·m), and Newton leaves the last stage's velocity
/// within `TOLINC L / (γh) ≈ 1e-13·0.4 m / 2e-4 s = 2e-10 m/s`, which moves the centripetal
/// terms by `2 m v δv / l ≈ 1e-9 N`, `1e-10 N·m`. Measured 2.4–3e-11 N·m.
const FLOOR: f64 = 2e-10;

/// ESDIRK3 and ESDIRK5: the driving torque and the crank pin's force converge at (at
/// least) third order against the closed form, down to the floor. Measured (h = 4e-2,
/// 2e-2, 1e-2, 5e-3 s over one turn): ESDIRK3 1.38e-5, 1.56e-6, 1.86e-7, 2.28e-8 N·m
/// (orders 3.14, 3.07, 3.03), ESDIRK5 9.3e-8, 2.7e-9, 9.0e-11 N·m (5.1, 4.9, then the
/// floor). The last stage's multipliers, which these rows carried until issue 34, were
/// second order: ESDIRK3 6.3e-3 … 9.7e-5 N·m, ESDIRK5 2.8e-2 … 4.0e-4 N·m on the same ladder.
#[test]
fn driving_torque_and_pin_force_converge_at_third_order_or_better() {
    let steps = [4e-2, 2e-2, 1e-2, 5e-3];
    for scheme in [Scheme::Esdirk3, Scheme::Esdirk5] {
        let errs: Vec<(f64, f64)> = steps
            .iter()
            .map(|&h| {
                let (et, ef, _) = errors(scheme, h, 1.0);
                println!("{scheme}, h = {h:e}: torque {et:.3e} N·m, pin force {ef:.3e} N");
                (et, ef)
            })
            .collect();
        for k in 0..steps.len() - 1 {
            for (what, e0, e1, floor) in [
                ("torque", errs[k].0, errs[k + 1].0, FLOOR),
                ("pin force", errs[k].1, errs[k + 1].1, FLOOR / 0.1),
            ] {
                let order = (e0 / e1).log2();
                println!(
                    "  {what}: order {order:.2} between h = {:e} and {:e}",
                    steps[k],
                    steps[k + 1]
                );
                assert!(
                    order >= 2.8 || e1 <= floor,
                    "{scheme}: {what} order {order} ({e0:e} -> {e1:e})"
                );
            }
        }
        assert!(errs[steps.len() - 1].0 <= 1e-7, "{scheme}: {:?}", errs);
    }
}

/// A shortened last step (END not a multiple of STEP) ends on a row as accurate as the
/// others: its reaction depends on the row's state, not on the step that led there. With the
/// last stage's multipliers a last step of 0.01 h was 9.6e-5 N·m off with ESDIRK5 at
/// h = 1e-3 s (the rows of full steps 1.6e-5) and 2.4e-5 N·m with ESDIRK3 at 2.5e-4 s (full
/// rows 9.1e-7): the position-level last stage takes the incoming velocity's error back over
/// a step of 0.01 h, a force ∝ 1/(0.01 h). Now within the rows' own error plus the floor.
#[test]
fn a_shortened_last_step_is_as_accurate_as_the_others() {
    for scheme in [Scheme::Esdirk3, Scheme::Esdirk5] {
        let h = 1e-3;
        let (full, _, _) = errors(scheme, h, 0.25);
        for frac in [0.37, 0.01] {
            let (_, _, last) = errors(scheme, h, 0.25 + frac * h);
            println!(
                "{scheme}: last step {frac} h: torque error {last:.3e} (rows of full steps {full:.3e})"
            );
            assert!(
                last <= full + FLOOR,
                "{scheme}, {frac} h: {last:e} vs {full:e}"
            );
        }
    }
}

/// The files a run writes carry the same reactions: `OUTPUT … EVERY 10` with END off the
/// grid (the last row written by the writer's finish, not by a sampled step), ESDIRK5 at
/// h = 1e-3 s: every row of element_3.csv's torque within the floor of the closed form.
#[test]
fn written_rows_carry_the_index1_reactions() {
    let dir = TempDir::new("sc_driven");
    let text = std::fs::read_to_string(deck_path("slider_crank_driven.dat")).unwrap();
    let text = text
        .replace("STEP 1e-3 END 1.0", "STEP 1e-3 END 0.2504")
        .replace("ELEMENTS 3 4 5", "ELEMENTS 3 4 5 EVERY 10");
    let deck_file = dir.join("sc.dat");
    std::fs::write(&deck_file, text).unwrap();
    let out = dir.join("out");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck_file)
        .arg("-o")
        .arg(&out)
        .arg("--quiet")
        .status()
        .unwrap();
    assert!(status.success());
    let csv = std::fs::read_to_string(out.join("element_3.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("t,angle,prescribed,torque,fx,fy,fz,mx,my,mz")
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 27, "t = 0, 0.01, …, 0.25 and 0.2504");
    assert_eq!(rows.last().unwrap()[0], 0.2504);
    for r in &rows {
        let (tau, _) = inverse_dynamics(OMEGA * r[0]);
        assert!(
            (r[3] - tau).abs() <= FLOOR,
            "t = {}: {} vs {tau}",
            r[0],
            r[3]
        );
    }
}
