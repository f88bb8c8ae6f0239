//! Springs and dampers (issue 25 §3): SPRING, BUSHING and RSPRING against closed forms, run
//! from the decks `decks/spring_mass.dat`, `spring_static.dat`, `bushing_mass.dat`,
//! `torsion_hinge.dat` and `flywheel.dat`; and their bad input.
//!
//! # Tolerances
//! The dynamic decks use HHT with α = 0, the trapezoidal rule (γ = ½, β = ¼): no numerical
//! damping, and for a linear oscillator of frequency ω a discrete frequency
//! `ω_h = (2/h) atan(ωh/2) = ω (1 − (ωh)²/12 + O((ωh)⁴))`: periods are lengthened by
//! `(ωh)²/12` relative, never shortened. A frequency measured from upward zero crossings
//! (linear interpolation between samples: its error is O(h³ω²) at a crossing, where the
//! signal's curvature vanishes, and it is divided by the number of periods) must therefore
//! lie in `[ω (1 − (ωh)²/12 − 1e-6), ω (1 + 1e-6)]`.
//!
//! A damped oscillator's discrete eigenvalue is the Cayley transform
//! `z = (1 + hλ/2)/(1 − hλ/2)` of `λ = −ζω ± iω√(1−ζ²)`, so the trapezoidal rule's
//! logarithmic decrement per (discrete) period is `δ_h = −2π ln|z| / arg z`, O((ωh)²)
//! from the closed form `δ = 2πζ/√(1−ζ²)`; a measured decrement is held to `|δ_h − δ|`
//! plus its measurement error (peaks by a parabola through three samples: 1e-5 relative).

use crate::common;

use mecano::deck::{parse_deck, parse_deck_with};
use mecano::model::Model;
use mecano::output::History;
use mecano::rotation;
use mecano::solver;
use nalgebra::Matrix3;
use std::f64::consts::PI;

/// `decks/<name>` with parameter overrides.
fn deck_with(name: &str, set: &[(&str, f64)]) -> Model {
    let p = common::deck_path(name);
    let text = std::fs::read_to_string(&p).expect("deck readable");
    let set: Vec<(String, f64)> = set.iter().map(|(k, v)| (k.to_string(), *v)).collect();
    parse_deck_with(&text, name, &set).unwrap_or_else(|e| panic!("{name}: {e:?}"))
}

/// Runs a model to its end, every state recorded; the run must complete.
fn run(m: &Model) -> History {
    let mut h = History::new(1);
    let report = solver::run(m, &mut h).expect("the run starts");
    assert!(report.failure.is_none(), "run failed: {:?}", report.failure);
    h
}

/// The frequency (rad/s) of a signal from its upward zero crossings (at least 3).
fn crossing_frequency(t: &[f64], s: &[f64]) -> f64 {
    let mut c = Vec::new();
    for i in 0..s.len() - 1 {
        if s[i] < 0.0 && s[i + 1] >= 0.0 {
            c.push(t[i] + (t[i + 1] - t[i]) * (-s[i]) / (s[i + 1] - s[i]));
        }
    }
    assert!(c.len() >= 3, "only {} crossings", c.len());
    2.0 * PI * (c.len() - 1) as f64 / (c[c.len() - 1] - c[0])
}

/// Asserts `measured` is the frequency `omega` as the trapezoidal rule lengthens it (module
/// docs).
fn assert_frequency(what: &str, measured: f64, omega: f64, h: f64) {
    let lo = omega * (1.0 - (omega * h).powi(2) / 12.0 - 1e-6);
    let hi = omega * (1.0 + 1e-6);
    eprintln!(
        "{what}: measured {measured} rad/s, closed form {omega}, relative {:.3e}, bound (ωh)²/12 = {:.3e}",
        measured / omega - 1.0,
        (omega * h).powi(2) / 12.0
    );
    assert!(
        (lo..=hi).contains(&measured),
        "{what}: measured {measured} rad/s, closed form {omega} (allowed [{lo}, {hi}])"
    );
}

fn step_of(m: &Model) -> f64 {
    match m.analysis {
        mecano::model::Analysis::Dynamic { step, .. } => step,
        _ => panic!("dynamic deck expected"),
    }
}

/// A mass on a SPRING: ω = √(k/m) = 20 rad/s.
#[test]
fn spring_mass_frequency_is_sqrt_k_over_m() {
    let m = deck_with("spring_mass.dat", &[]);
    let h = run(&m);
    let x: Vec<f64> = h.nodes.iter().map(|n| n[1].x.x - 1.0).collect();
    let w = crossing_frequency(&h.t, &x);
    assert_frequency("spring-mass", w, (800.0f64 / 2.0).sqrt(), step_of(&m));
}

/// The damped decay (c = 4 N·s/m, ζ = 0.05): the logarithmic decrement of successive peaks
/// against `2πζ/√(1−ζ²)`, within the trapezoidal rule's own O((ωh)²) error (module docs);
/// and the energy balance closes: `E(t) + D(t) = E(0)`, D the dampers' dissipation, to the
/// trapezoidal rule's quadrature of the damper's power `Σ (h/4) c (Δv)²` ≈ `(ωh)²/4 · D`
/// (Δv ≈ h a and ⟨a²⟩ = ω²⟨v²⟩ for a lightly damped oscillation), taken with a factor 1.5.
#[test]
fn damped_decay_has_the_closed_form_decrement_and_the_balance_closes() {
    let (k, mass, c) = (800.0f64, 2.0f64, 4.0f64);
    let m = deck_with("spring_mass.dat", &[("c", c)]);
    let hstep = step_of(&m);
    let h = run(&m);
    let x: Vec<f64> = h.nodes.iter().map(|n| n[1].x.x - 1.0).collect();
    let mut peaks = Vec::new();
    for i in 1..x.len() - 1 {
        if x[i] > x[i - 1] && x[i] >= x[i + 1] && x[i] > 0.0 {
            let (a, b, cc) = (x[i - 1], x[i], x[i + 1]);
            peaks.push(b - (a - cc).powi(2) / (8.0 * (a - 2.0 * b + cc)));
        }
    }
    assert!(peaks.len() >= 8, "{} peaks", peaks.len());
    let n = peaks.len() - 1;
    let measured = (peaks[0] / peaks[n]).ln() / n as f64;
    let omega = (k / mass).sqrt();
    let zeta = c / (2.0 * (k * mass).sqrt());
    let closed = 2.0 * PI * zeta / (1.0 - zeta * zeta).sqrt();
    // The trapezoidal rule's decrement (Cayley transform of the eigenvalue).
    let (re, im) = (
        -zeta * omega * hstep / 2.0,
        omega * (1.0 - zeta * zeta).sqrt() * hstep / 2.0,
    );
    let num = nalgebra::Complex::new(1.0 + re, im);
    let den = nalgebra::Complex::new(1.0 - re, -im);
    let z = num / den;
    let discrete = -2.0 * PI * z.norm().ln() / z.arg();
    let tol = (discrete - closed).abs() + 1e-5 * closed;
    eprintln!("decrement: measured {measured}, closed form {closed}, scheme {discrete}");
    assert!(
        (measured - closed).abs() <= tol,
        "decrement {measured}, closed form {closed}, scheme's {discrete} (tolerance {tol})"
    );
    // The energy balance.
    let last = h.energy.len() - 1;
    let d = h.damping_work[last];
    assert!(
        d > 0.9 * h.energy[0],
        "most of the energy dissipated: {d} of {}",
        h.energy[0]
    );
    let gap = (h.energy[last] + d - h.energy[0]).abs();
    let tol = 1.5 * (omega * hstep).powi(2) / 4.0 * d;
    eprintln!("balance: gap {gap:e} J of D = {d} J (tolerance {tol:e})");
    assert!(
        gap <= tol,
        "balance off by {gap} J (tolerance {tol} J, D = {d} J)"
    );
}

/// Static equilibrium of `decks/spring_static.dat`: a free length, a preload and a
/// force–deflection TABLE, each against the length where its tension equals m g. The table's
/// root is found here by bisection on the table's points (an independent route: the element
/// interpolates them itself). Tolerance: Newton stops at a residual of 1e-8 of the
/// reference force (≥ m g) and an increment of 1e-10 of the reference length (1 m); with
/// stiffnesses ≥ 857 N/m that is ≤ 6e-10 m: 1e-9 m.
#[test]
fn static_equilibrium_of_free_length_preload_and_curve() {
    let m = common::deck("spring_static.dat");
    let h = run(&m);
    let last = h.nodes.last().expect("states");
    let mg = 5.0 * 9.81;
    let length = |i: usize, j: usize| (last[j].x - last[i].x).norm();
    let idx = |n: u32| m.nodes.get_index_of(&mecano::model::NodeId(n)).unwrap();
    let l_free = length(idx(1), idx(2));
    assert!(
        (l_free - (0.8 + mg / 1000.0)).abs() < 1e-9,
        "free length: {l_free}"
    );
    let l_pre = length(idx(3), idx(4));
    assert!(
        (l_pre - (1.0 + (mg - 30.0) / 2000.0)).abs() < 1e-9,
        "preload: {l_pre}"
    );
    let table = [
        (-0.01, -10.0),
        (0.0, 0.0),
        (0.01, 10.0),
        (0.03, 40.0),
        (0.1, 100.0),
    ];
    let f = |d: f64| {
        let k = table
            .windows(2)
            .position(|w| d <= w[1].0)
            .unwrap_or(table.len() - 2);
        let ((a, fa), (b, fb)) = (table[k], table[k + 1]);
        fa + (fb - fa) * (d - a) / (b - a)
    };
    let (mut lo, mut hi) = (0.0, 0.1);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < mg { lo = mid } else { hi = mid }
    }
    let l_curve = length(idx(5), idx(6));
    eprintln!(
        "static: free {:e}, preload {:e}, curve {:e} m off",
        l_free - (0.8 + mg / 1000.0),
        l_pre - (1.0 + (mg - 30.0) / 2000.0),
        l_curve - 1.0 - lo
    );
    assert!(
        (l_curve - (1.0 + lo)).abs() < 1e-9,
        "curve: {l_curve} vs {}",
        1.0 + lo
    );
}

/// A body on a BUSHING whose axes are turned 45° about Z: six uncoupled oscillations at
/// `√(k_i/m)` and `√(k_ri/J_i)`, each read in the bushing axes.
#[test]
fn bushing_six_uncoupled_frequencies() {
    let m = common::deck("bushing_mass.dat");
    let hs = step_of(&m);
    let h = run(&m);
    let s = 0.5f64.sqrt();
    let e = Matrix3::new(s, -s, 0.0, s, s, 0.0, 0.0, 0.0, 1.0);
    let x0 = h.nodes[0][1].x;
    let k: [f64; 6] = [1000.0, 2000.0, 3000.0, 4.0, 10.0, 27.0];
    let inertia = [1.0, 1.0, 1.0, 0.01, 0.02, 0.03];
    for c in 0..6 {
        let sig: Vec<f64> = h
            .nodes
            .iter()
            .map(|n| {
                let v = if c < 3 {
                    n[1].x - x0
                } else {
                    rotation::log(&n[1].r)
                };
                (e.transpose() * v)[c % 3]
            })
            .collect();
        let w = crossing_frequency(&h.t, &sig);
        assert_frequency(
            &format!("bushing component {c}"),
            w,
            (k[c] / inertia[c]).sqrt(),
            hs,
        );
    }
}

/// A disc on a HINGE with an RSPRING: ω = √(k/J) = 10 rad/s.
#[test]
fn torsional_oscillator_frequency_is_sqrt_k_over_j() {
    let m = deck_with("torsion_hinge.dat", &[]);
    let h = run(&m);
    let th: Vec<f64> = h.nodes.iter().map(|n| rotation::log(&n[1].r).z).collect();
    let w = crossing_frequency(&h.t, &th);
    assert_frequency("torsion", w, (5.0f64 / 0.05).sqrt(), step_of(&m));
}

/// A flywheel spinning down under the RSPRING's friction: `ω(t) = ω₀ − T t/J` while
/// `ω ≫ ω_reg` (the trapezoidal rule integrates a constant torque exactly; the tanh is
/// within `2e^{−40}` of 1 for ω ≥ 1 rad/s; Newton's tolerance leaves ~1e-8 of the torque
/// per step: 1e-6 ω₀ covers 2000 steps of it), at rest after 2 s, and the energy the
/// friction dissipated is `½Jω₀²` (trapezoidal power exact while the power is linear in t;
/// in the stop, over a few steps, ≤ h T ω_reg = 2.5e-5 J: 1e-5 of it).
#[test]
fn flywheel_spins_down_linearly_and_dissipates_its_energy() {
    let m = common::deck("flywheel.dat");
    let h = run(&m);
    let (w0, tf, j) = (20.0, 0.5, 0.05);
    let mut checked = 0;
    for (t, n) in h.t.iter().zip(&h.nodes) {
        let w = n[1].w.z;
        if *t <= 1.9 {
            let want = w0 - tf * t / j;
            assert!(
                (w - want).abs() <= 1e-6 * w0,
                "t = {t}: omega {w}, want {want}"
            );
            checked += 1;
        }
    }
    assert!(checked > 1800);
    let last = h.nodes.len() - 1;
    assert!(
        h.nodes[last][1].w.z.abs() < 1e-3 * w0,
        "still turning: {}",
        h.nodes[last][1].w.z
    );
    let e0 = 0.5 * j * w0 * w0;
    assert!((h.energy[0] - e0).abs() < 1e-12 * e0);
    let d = h.damping_work[last];
    eprintln!(
        "flywheel: dissipated {d} J of {e0} J, final omega {}",
        h.nodes[last][1].w.z
    );
    assert!((d - e0).abs() <= 1e-5 * e0, "dissipated {d} J, want {e0} J");
    assert!((h.energy[last] + d - h.energy[0]).abs() <= 1e-5 * e0);
}

/// The binary: `--check` lists the springs among the scene's effects (and friction for an
/// RSPRING with FRICTION), a run writes the element's history with its force columns and
/// the spring's energy in energy.csv.
#[test]
fn check_lists_springs_and_a_run_writes_their_histories() {
    let bin = env!("CARGO_BIN_EXE_mecano-rs");
    for (deck, extra) in [("bushing_mass.dat", ""), ("flywheel.dat", "friction")] {
        let o = std::process::Command::new(bin)
            .arg(common::deck_path(deck))
            .arg("--check")
            .output()
            .expect("runs");
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{out}");
        let eff = out
            .lines()
            .find(|l| l.starts_with("effects:"))
            .expect("effects line");
        assert!(
            eff.contains("springs and dampers") && eff.contains(extra),
            "{eff}"
        );
    }
    let dir = common::TempDir::new("springs_run");
    let o = std::process::Command::new(bin)
        .arg(common::deck_path("spring_mass.dat"))
        .args(["-q", "--set", "c=4", "-o"])
        .arg(dir.path())
        .output()
        .expect("runs");
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let el = std::fs::read_to_string(dir.join("element_1.csv")).expect("element history");
    assert!(
        el.starts_with("t,length,deflection,rate,tension,fx,fy,fz\n"),
        "{el:.80}"
    );
    // Row 2 (t = h): tension = k δ + c ℓ̇, fx = −tension (the spring pulls node 2 back).
    let row: Vec<f64> = el
        .lines()
        .nth(2)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!((row[4] - (800.0 * row[2] + 4.0 * row[3])).abs() < 1e-9 * row[4].abs().max(1.0));
    assert!((row[5] + row[4]).abs() < 1e-12 * row[4].abs().max(1.0));
    let en = std::fs::read_to_string(dir.join("energy.csv")).expect("energy");
    let strain_max = en
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap().parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    // The first peak of x = (v0/ω_d) e^(−ζωt) sin(ω_d t), at tan(ω_d t) = ω_d/(ζω): ½ k x².
    // Sampling misses it by ≤ h/2 (relative (ω h/2)²/2 = 5e-5 in x) and the trapezoidal
    // rule's amplitude and phase err by O((ωh)²) = 4e-4: 2e-3 of the energy.
    let (k, m, c, v0) = (800.0f64, 2.0f64, 4.0f64, 0.1f64);
    let (omega, zeta) = ((k / m).sqrt(), c / (2.0 * (k * m).sqrt()));
    let wd = omega * (1.0 - zeta * zeta).sqrt();
    let tp = (wd / (zeta * omega)).atan() / wd;
    let xp = v0 / wd * (-zeta * omega * tp).exp() * (wd * tp).sin();
    let want = 0.5 * k * xp * xp;
    assert!(
        (strain_max - want).abs() < 2e-3 * want,
        "largest strain energy {strain_max}, closed form {want}"
    );
}

/// Bad input: located deck errors, never a model.
#[test]
fn bad_springs_are_located_deck_errors() {
    let pre = "NODES\n 1 0 0 0 FIX ALL\n 2 1 0 0\n 3 1 0 0\nELEMENTS\n 1 HINGE 1 2 AXIS 0 0 1\n 2 MASS 2 M 1\n";
    let post = "ANALYSIS DYNAMIC STEP 1e-3 END 1\n";
    // (card on line 8, column of the error, words of the message)
    let cases: [(&str, usize, &str); 9] = [
        (
            " 9 SPRING 2 3 K 10",
            11,
            "a spring of zero length with no free length given",
        ),
        (" 9 SPRING 2 3 K 10 PRELOAD 4", 11, "no free length given"),
        (" 9 SPRING 2 3 K 10 L0 1", 11, "line of action is undefined"),
        (
            " 9 SPRING 1 2 K -10",
            17,
            "K (stiffness) = -10 is out of range",
        ),
        (" 9 SPRING 1 2 C -1", 17, "C (damping) = -1 is out of range"),
        (
            " 9 BUSHING 1 2 K 1 1 1 1 -1 1",
            26,
            "Kry (stiffness) = -1 is out of range",
        ),
        (
            " 9 RSPRING 2 K 5",
            12,
            "names element 2, a MASS: an RSPRING acts on a HINGE",
        ),
        (" 9 RSPRING 7 K 5", 12, "undefined element 7"),
        (" 9 RSPRING 1 C -2", 16, "C (damping) = -2 is out of range"),
    ];
    for (card, col, gist) in cases {
        let text = format!("{pre}{card}\n{post}");
        let errs = match parse_deck(&text, "bad.dat") {
            Ok(_) => panic!("accepted: {card}"),
            Err(e) => e,
        };
        let msg = errs.errors()[0].to_string();
        assert!(msg.contains(gist), "{card}: {msg}");
        assert_eq!(errs.line_col(0), Some((8, col)), "{card}: {msg}");
    }
    // The binary: exit 2, nothing written.
    let dir = common::TempDir::new("springs_bad");
    let deck = dir.join("bad.dat");
    std::fs::write(&deck, format!("{pre} 9 SPRING 2 3 K 10\n{post}")).unwrap();
    let out = dir.join("out");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck)
        .args(["-q", "-o"])
        .arg(&out)
        .output()
        .expect("runs");
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("SPRING element 9 joins nodes 2 and 3") && err.contains("bad.dat:8:11"),
        "{err}"
    );
    assert!(!out.exists(), "nothing is written");
}

/// A run that drives a spring through zero length fails cleanly: exit 1 with the
/// spring's diagnosis, no NaN in any history. A mass launched at 10 m/s straight at the
/// spring's fixed end, 1 m away (the soft spring cannot stop it: ½ m v² = 50 J ≫ ½ k L0²).
#[test]
fn a_spring_through_zero_length_fails_cleanly() {
    let text = "NODES\n 1 0 0 0 FIX ALL\n 2 1 0 0 FIX Y Z ROT\nELEMENTS\n 1 SPRING 1 2 K 1\n 2 MASS 2 M 1\n\
INITIAL\n 2 V -10 0 0\nANALYSIS DYNAMIC STEP 1e-2 END 0.5\nOUTPUT NODES 2 ELEMENTS 1\n";
    let dir = common::TempDir::new("springs_zero");
    let deck = dir.join("through.dat");
    std::fs::write(&deck, text).unwrap();
    let out = dir.join("out");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck)
        .args(["-q", "-o"])
        .arg(&out)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("(SPRING)") && err.contains("zero length"),
        "{err}"
    );
    for f in ["node_2.csv", "element_1.csv", "energy.csv"] {
        let s = std::fs::read_to_string(out.join(f)).expect(f);
        assert!(
            !s.to_lowercase().contains("nan") && !s.contains("inf"),
            "{f}"
        );
        assert!(
            s.lines().count() > 5,
            "{f} keeps the history before the failure"
        );
    }
}

/// The canonical writer: the spring decks written and read back give the same elements
/// (kinds with their data, nodes; an RSPRING written by its hinge's number), and the text
/// is a fixed point.
#[test]
fn spring_cards_round_trip() {
    for name in [
        "spring_static.dat",
        "bushing_mass.dat",
        "torsion_hinge.dat",
        "flywheel.dat",
    ] {
        let m = common::deck(name);
        let text = mecano::deck::write_deck(&m);
        let back = parse_deck(&text, "written").unwrap_or_else(|e| panic!("{name}: {e:?}\n{text}"));
        let parts = |m: &Model| -> Vec<_> {
            m.elements
                .values()
                .map(|e| (e.kind.clone(), e.nodes.clone()))
                .collect()
        };
        assert_eq!(parts(&m), parts(&back), "{name}");
        assert_eq!(mecano::deck::write_deck(&back), text, "{name}");
    }
}
