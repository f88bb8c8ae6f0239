//! No silent wrong answer (issue 28 §1): a load beyond f64 or far beyond what the model
//! carries ends in a diagnosis, never in a "converged" run; a step whose energy jumps
//! without the work to pay for it is refused (the energy guard); every failure writes the
//! same complete record.

use crate::common;

use mecano::deck::parse_deck;
use mecano::output::History;
use mecano::solver::{self, energy_guard};
use std::path::Path;
use std::process::Command;

const PENDULUM: &str = include_str!("../../decks/pendulum.dat");

/// The pendulum with `from` replaced by `to` in its text and cut to `end` seconds.
fn pendulum(from: &str, to: &str, end: &str) -> String {
    assert!(PENDULUM.contains(from), "{from}");
    PENDULUM
        .replace(from, to)
        .replace("STEP 1e-4 END 2.0", &format!("STEP 1e-4 END {end}"))
}

/// Huge loads used to pass the Newton test with zero iterations: the reference force was
/// `|load|`, whose norm overflowed to infinity (1e200² > f64::MAX), so every relative
/// residual was 0 (exit 0, "complete", the node never felt the load, energy balance
/// error 1.0). A load beyond 1e100 is now refused as input (issue 35 §1: its squared norm
/// would overflow); one within it but far beyond what the model carries must stop with a
/// diagnosis (the run cannot be resolved at any step: its state becomes non-finite, or
/// Newton fails).
#[test]
fn huge_loads_end_in_a_diagnosis_not_a_zero_iteration_success() {
    for to in ["MOMENT 2  0 0 -1e200", "MOMENT 2  0 0 -1e308"] {
        let e = parse_deck(&pendulum("MOMENT 2  0 0 -1000", to, "0.01"), "huge.dat")
            .expect_err(to)
            .to_string();
        assert!(e.contains("out of range"), "`{to}`: {e}");
    }
    for (from, to) in [
        ("MOMENT 2  0 0 -1000", "MOMENT 2  0 0 -1e60"),
        ("MOMENT 2  0 0 -1000", "MOMENT 2  0 0 -1e100"),
        (
            "MOMENT 2  0 0 -1000  FUNCTION 1",
            "MOMENT 2  0 0 -1000  FUNCTION 1\n  FORCE 12 0 -1e100 0",
        ),
    ] {
        let model = parse_deck(&pendulum(from, to, "0.01"), "huge.dat").expect("the deck parses");
        let mut hist = History::new(1);
        let report = solver::run(&model, &mut hist).expect("the run starts");
        let f = report.failure.unwrap_or_else(|| {
            panic!(
                "`{to}`: the run 'completed' ({} steps, {} Newton iterations)",
                report.stats.steps, report.stats.newton_iterations
            )
        });
        assert!(report.time < 0.01, "`{to}`: stopped at {}", report.time);
        eprintln!("`{to}`: {f}");
    }
}

/// The reference force is the load acting now, not the largest of the run: a force of
/// 1e12 N that acts only after the run's end (a TABLE zero until 5 s) used to make the
/// pendulum's residuals relative to 1e12 N, so Newton accepted 1e4 N of imbalance on its
/// 1 kg mass (the mass then went 9.7e-8 m off the run without it in 0.3 s). The dormant
/// load adds 0 to every residual, so the run must be the run without it: the bound
/// 1e-12 m is round-off of |x| = 1 m accumulated over 300 steps (300 · 2.2e-16 m ≈ 7e-14 m,
/// with a margin).
#[test]
fn a_load_that_does_not_act_yet_does_not_loosen_newton() {
    let deck = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/decks/simple_pendulum.dat"
    ))
    .unwrap()
    .replace("END 10.0", "END 0.3");
    let dormant = deck
        .replace(
            "LOADS\n",
            "FUNCTIONS\n  1 TABLE 0 0  5 0  5.0001 1  5.0002 0\nLOADS\n  FORCE 2 0 -1e12 0 FUNCTION 1\n",
        );
    assert_ne!(deck, dormant);
    let run = |text: &str| {
        let model = parse_deck(text, "p.dat").unwrap();
        let mut hist = History::new(1);
        let report = solver::run(&model, &mut hist).unwrap();
        assert!(report.failure.is_none(), "{:?}", report.failure);
        hist
    };
    let (a, b) = (run(&deck), run(&dormant));
    assert_eq!(a.t.len(), b.t.len());
    let worst = a
        .positions(1)
        .iter()
        .zip(b.positions(1))
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-12,
        "the dormant load moved the mass by {worst:e} m"
    );
}

/// The guard on a real system (the simple pendulum: a 1 kg mass on a 1 m hinge arm,
/// gravity): a step from rest that the integrator resolves passes; the same end state
/// with 1e5 m/s added (5e9 J out of nothing, in a step whose work is 0) is a jump; a
/// non-finite end state is one too.
#[test]
fn the_energy_guard_refuses_energy_no_work_paid_for_and_passes_a_resolved_step() {
    let deck = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/decks/simple_pendulum.dat"
    ))
    .unwrap();
    let model = parse_deck(&deck, "simple_pendulum.dat").unwrap();
    let mut integ = solver::prepare(&model).unwrap();
    integ.initialize().unwrap();
    let old = integ.nodes.clone();
    let h = 1e-3;
    integ.try_step(h).expect("a resolved step from rest");
    let new = integ.nodes.clone();
    let floor = integ.residual_floor * integ.sys.ref_length;
    let n = integ.sys.elements.len();
    let g = integ.guard_g;
    let m_old = energy_guard::measure(&integ.sys, &old, 0.0);
    let check = |nodes: &[mecano::elements::NodeState]| {
        let m_new = energy_guard::measure(&integ.sys, nodes, h);
        let step = energy_guard::Step {
            old: m_old,
            new: m_new,
            drive: (0.0, 0.0),
            h,
            t_new: h,
            newton: 0.0,
            // At the smallest step: a jump is refused even where no shorter step is left.
            at_floor: true,
        };
        energy_guard::check(&energy_guard::Balance::default(), &step, g, floor, n)
    };
    assert!(check(&new).is_ok());
    let mut fast = new.clone();
    fast[1].v.y -= 1e5;
    let j = check(&fast).expect_err("a jump");
    // ½ m v² with v ≈ 1e5 m/s, m = 1 kg.
    assert!((j.created / 5e9 - 1.0).abs() < 1e-3, "{j:?}");
    let mut nan = new.clone();
    nan[1].v.x = f64::NAN;
    assert!(check(&nan).is_err());
}

/// A run over many steps from rest, through impacts (the pendulum's first 0.3 s: the
/// torque pulse, the swing, the floor), is never refused by the guard: steps, rejected
/// steps and the motion are those of a run without it.
#[test]
fn the_energy_guard_does_not_refuse_a_resolved_run() {
    let text = pendulum("OUTPUT NODES", "OUTPUT NODES", "0.03");
    let model = parse_deck(&text, "p.dat").unwrap();
    let mut hist = History::new(1);
    let report = solver::run(&model, &mut hist).unwrap();
    assert!(report.failure.is_none(), "{:?}", report.failure);
    assert_eq!(report.stats.rejected_steps, 0, "{:?}", report.stats);
}

/// A scratch directory removed when the test ends, also when it fails.
fn tmp(name: &str) -> common::TempDir {
    common::TempDir::new(&format!("silent_{name}"))
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// Every failure writes the same record: `I2 1e60` fails before the first step (its
/// matrix cannot be factored: the bars' stiffness swamps their mass) and a huge moment
/// fails in the first step; both exit 1 with a summary holding the failure, the stop and
/// the counters, and CSVs with their header. (1e308 in either is refused as input now.)
#[test]
fn every_failure_writes_the_complete_record() {
    let d = tmp("record");
    for (name, from, to) in [
        ("section", "I2 8.3e-8", "I2 1e60"),
        ("force", "MOMENT 2  0 0 -1000", "MOMENT 2  0 0 -1e100"),
    ] {
        let deck = d.join(format!("{name}.dat"));
        std::fs::write(&deck, pendulum(from, to, "0.01")).unwrap();
        let out = d.join(name);
        let o = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
            .arg(&deck)
            .args(["-q", "-o"])
            .arg(&out)
            .env_remove("MECANO_FAILPOINT")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{name}: {err}");
        let s = summary(&out);
        assert_eq!(s["complete"], false, "{name}");
        assert!(s["failure"]["message"].is_string(), "{name}: {s}");
        assert_eq!(s["stop"]["reason"], "failed", "{name}: {s}");
        assert!(s["stats"]["steps"].is_u64(), "{name}: {s}");
        assert!(s["time_reached"].is_number(), "{name}: {s}");
        for (file, head) in [
            ("node_12.csv", "t,x,y,z,"),
            ("energy.csv", "t,kinetic,"),
            ("element_12.csv", "t,angle1,"),
        ] {
            let text = std::fs::read_to_string(out.join(file)).unwrap();
            assert!(text.starts_with(head), "{name}: {file}: `{text}`");
            assert!(
                !text.contains("NaN") && !text.contains("inf"),
                "{name}: {file}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}
