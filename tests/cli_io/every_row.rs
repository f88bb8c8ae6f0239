//! Every row written (issue 34 §7): with fixed steps, each planned output instant
//! `k·EVERY·STEP` appears exactly once in every history a run writes (`node_N.csv`,
//! `element_N.csv`, `energy.csv`), in increasing time, with no gap — whatever the steps and
//! the events: CAME and CLEARANCE impacts cut the steps, land on touches and releases and
//! come back to the grid. Run over a ladder of steps on real decks, and on steps chosen so
//! that a touch lands just before a grid instant (the case that lost that instant's row).
//! With `OUTPUT … SUBSTEPS` the rows are a superset of the grid's, bit for bit, and a contact
//! force's peak read from them matches the closed form where the grid rows miss it.

use crate::common::{self, TempDir, deck};
use mecano::model::Model;
use std::path::Path;

/// How close to a grid instant a state counts as that instant's row: the stepper never takes
/// a step shorter than 1e-3 STEP to reach a grid instant, so a state that close before it
/// (an event landed there) stands for it (grammar.md, `OUTPUT` `EVERY`).
const REACH: f64 = 1e-3;

/// A CSV history: its header and its rows.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("a header")
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|x| x.parse().unwrap_or_else(|e| panic!("{x}: {e}")))
                .collect()
        })
        .collect();
    (header, rows)
}

/// Runs `model` into a fresh directory; the run must complete.
fn run(model: &Model, name: &str) -> TempDir {
    let dir = TempDir::new(name);
    let report = mecano::app::run_model(model, name, &dir, true)
        .unwrap_or_else(|(c, m)| panic!("{name}: run refused ({c}): {m}"));
    assert!(report.failure.is_none(), "{name}: {:?}", report.failure);
    dir
}

/// Every history file of a run's directory (node, element and energy CSVs).
fn histories(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    files.sort();
    assert!(
        files.iter().any(|p| p
            .file_name()
            .unwrap()
            .to_string_lossy()
            .starts_with("node_")),
        "no node history in {}",
        dir.display()
    );
    files
}

/// The invariant on one history's times `ts` of a fixed-step run of step `h0`, `EVERY n`, to
/// `end`: strictly increasing; each instant `k n h0` (k = 0 … ⌊(end + REACH h0)/(n h0)⌋)
/// matched by exactly one row within `REACH·h0`; the last row at `end`. Without sub-steps, no other row (but the
/// end's, when `end` is off the grid). Returns the number of planned instants.
fn assert_every_row(ts: &[f64], h0: f64, n: u32, end: f64, substeps: bool, what: &str) -> usize {
    let p = h0 * f64::from(n);
    for w in ts.windows(2) {
        assert!(
            w[1] > w[0],
            "{what}: rows not increasing: {} then {}",
            w[0],
            w[1]
        );
    }
    let tol = REACH * h0;
    // The end's row stands for an instant within reach after it.
    let planned = ((end + tol) / p).floor() as usize + 1;
    let mut on_grid = 0;
    for k in 0..planned {
        let tk = k as f64 * p;
        let hits = ts.iter().filter(|t| (**t - tk).abs() <= tol).count();
        assert_eq!(
            hits,
            1,
            "{what}: instant {k} (t = {tk:e}) has {hits} rows; rows around it: {:?}",
            ts.iter()
                .filter(|t| (**t - tk).abs() <= 2.0 * p)
                .collect::<Vec<_>>()
        );
        on_grid += 1;
    }
    let last = *ts.last().expect("rows");
    assert!(
        (last - end).abs() <= 1e-9 * h0,
        "{what}: last row at {last}, end {end}"
    );
    let end_on_grid = ((planned - 1) as f64 * p - end).abs() <= tol;
    if !substeps {
        let expected = on_grid + usize::from(!end_on_grid);
        assert_eq!(
            ts.len(),
            expected,
            "{what}: {} rows, {expected} planned: {ts:?}",
            ts.len()
        );
    }
    planned
}

/// Runs `model` at fixed step `h` to `end` and checks the invariant on each of its histories;
/// returns the rows of node histories checked and the solver's steps.
fn check_ladder_run(model: &Model, name: &str, h: f64, end: f64) -> (usize, u64) {
    let mut m = model.clone();
    assert!(m.set_fixed_step(h, end, None));
    let n = m.output.every.max(1);
    let dir = run(&m, name);
    let mut rows = 0;
    for f in histories(&dir) {
        let (_, data) = read_csv(&f);
        let ts: Vec<f64> = data.iter().map(|r| r[0]).collect();
        let what = format!(
            "{name} h = {h:e}: {}",
            f.file_name().unwrap().to_string_lossy()
        );
        assert_every_row(&ts, h, n, end, false, &what);
        rows = ts.len();
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let steps = summary["stats"]["steps"].as_u64().expect("stats.steps");
    println!("{name}: h = {h:e}, EVERY {n}: {rows} rows, {steps} steps");
    (rows, steps)
}

/// `decks/contact_bounce.dat` with its mass launched at 1 m/s toward the floor `y0` away,
/// with `analysis` as its ANALYSIS card.
fn launched_bounce(y0: &str, analysis: &str) -> Model {
    let path = common::deck_path("contact_bounce.dat");
    let text = std::fs::read_to_string(&path).unwrap();
    let card = "ANALYSIS DYNAMIC ALPHA 0 STEP 1e-4 END 0.008";
    let node = "  2  0 0.001 0  FIX ROT";
    assert!(text.contains(card) && text.contains(node));
    let text = text
        .replace(card, &format!("INITIAL\n  2 V 0 -1 0\n\n{analysis}"))
        .replace(node, &format!("  2  0 {y0} 0  FIX ROT"));
    mecano::deck::parse_deck(&text, "contact_bounce_launched.dat").expect("deck parses")
}

/// CAME: the seed's pendulum (`decks/pendulum.dat`, `EVERY 10`) to 0.7 s, past its first
/// impact on the floor (about 0.5 s), at three steps — one of which does not divide END
/// (the last row is then the end's) —, and the bouncing mass of `decks/contact_bounce.dat`
/// launched at 1 m/s from 1 mm: its touch at exactly 1 ms lands 1e-4 STEP before the 10th
/// grid instant when STEP = 1e-3/(10 − 1e-4) s, inside the stepper's reach (steps shorter
/// than 1e-3 STEP are never taken): that instant's row is the touch's state.
#[test]
fn came_impacts_keep_every_planned_row() {
    let pendulum = deck("pendulum.dat");
    for h in [2e-4, 1e-4, 6e-5] {
        let (_, steps) = check_ladder_run(&pendulum, "rows_pendulum", h, 0.7);
        // The impact cut steps: events happened in the window checked.
        assert!(
            steps as f64 > 0.7 / h + 0.5,
            "no extra steps: no impact before 0.7 s?"
        );
    }
    let bounce = launched_bounce("0.001", "ANALYSIS DYNAMIC ALPHA 0 STEP 1e-4 END 0.004");
    for h in [1e-3 / (10.0 - 1e-4), 1e-4, 3e-5] {
        check_ladder_run(&bounce, "rows_bounce", h, 4e-3);
    }
    // The row that was lost: MINSTEP 3e-4 STEP (not a power-of-two fraction of it), the
    // touch 1e-4 STEP before the 10th instant. The step's bisection stops 1/1024 STEP before
    // the instant, the touch's root lands 1.0e-4 STEP before it, and the next step
    // (MINSTEP) ends 2e-4 STEP after it: no state within 1e-6 of the instant, whose row was
    // missing (0.0009 s, then 0.0011 s). Its row is now the first state within reach.
    let minstep = launched_bounce(
        "0.00099999",
        "ANALYSIS DYNAMIC ALPHA 0 STEP 1e-4 MINSTEP 3e-8 END 0.004",
    );
    let dir = run(&minstep, "rows_minstep");
    let (_, data) = read_csv(&dir.join("node_2.csv"));
    let ts: Vec<f64> = data.iter().map(|r| r[0]).collect();
    assert_every_row(
        &ts,
        1e-4,
        1,
        4e-3,
        false,
        "MINSTEP 3e-8, touch at 1e-3 - 1e-8 s",
    );
    let row = ts
        .iter()
        .find(|t| (**t - 1e-3).abs() <= REACH * 1e-4)
        .unwrap();
    println!(
        "MINSTEP: the 10th instant's row at t = {row:e} (1e-3 - {:.3e} s)",
        1e-3 - row
    );
}

/// CLEARANCE: the steel journal rattling in its bearing (`decks/stab_clearance_impact.dat`,
/// an impact every ~0.2 ms, each 31 µs long) to 5.5 ms at 1e-4 … 1e-7 s (the case:
/// 55,000 steps at 1e-7 s, whose history lost the rows from 2.5 ms on), and the journal of
/// `decks/clearance_impact.dat` whose touch at c/v = 0.5 ms lands 1e-4 STEP before the
/// 50th grid instant when STEP = 5e-4/(50 − 1e-4) s.
#[test]
fn clearance_impacts_keep_every_planned_row() {
    let rattle = deck("stab_clearance_impact.dat");
    for h in [1e-4, 1e-5, 1e-6, 1e-7] {
        let (_, steps) = check_ladder_run(&rattle, "rows_rattle", h, 5.5e-3);
        assert!(steps as f64 > 5.5e-3 / h + 0.5, "no impact cut a step");
    }
    let single = deck("clearance_impact.dat");
    for h in [5e-4 / (50.0 - 1e-4), 1e-5, 3e-6] {
        check_ladder_run(&single, "rows_journal", h, 1.2e-3);
    }
}

/// `OUTPUT … SUBSTEPS` on the launched bouncing mass (CAME, Kelvin–Voigt k = 1e6 N/m,
/// c = 200 N·s/m, CLIP OFF, m = 1 kg, v₀ = 1 m/s, IMPACT_STEPS 100) at STEP = 1 ms, about a
/// third of the 3.16 ms impact: the rows are the grid run's rows, bit for bit, and more, in
/// strictly increasing time, and every planned instant is still there once. The contact
/// force's peak read from the sub-step rows matches the closed form's — the force
/// `k δ + c δ̇` of `δ = (v₀/ω_d) e^{−σt} sin ω_d t`, its maximum over the impact found on a
/// fine sampling — within the sampling's `max|F̈| Δ²/8` at the largest row spacing Δ during
/// the contact, plus the trapezoidal rule's (ωΔ)²/4 of the peak (`tests/mechanics/contact.rs`),
/// plus the touch's landing (1e-4 of a step at v₀: `k v₀ 1e-4 Δ`); the grid rows' peak is
/// further off than that (the test would tell a run that wrote no sub-step).
#[test]
fn substeps_are_a_superset_and_hold_the_contact_peak() {
    let card = "ANALYSIS DYNAMIC ALPHA 0 STEP 1e-3 END 0.005";
    let grid = launched_bounce("0.0005", card);
    let mut sub = grid.clone();
    sub.output.substeps = true;
    let (dg, ds) = (run(&grid, "rows_grid"), run(&sub, "rows_sub"));
    for f in histories(&dg) {
        let name = f.file_name().unwrap().to_owned();
        let (hg, rg) = read_csv(&f);
        let (hs, rs) = read_csv(&ds.join(&name));
        assert_eq!(hg, hs);
        let what = format!("SUBSTEPS {}", name.to_string_lossy());
        let ts: Vec<f64> = rs.iter().map(|r| r[0]).collect();
        assert_every_row(&ts, 1e-3, 1, 5e-3, true, &what);
        assert!(rs.len() > rg.len() + 50, "{what}: {} rows only", rs.len());
        let mut j = 0;
        for row in &rg {
            while j < rs.len() && rs[j][0] < row[0] {
                j += 1;
            }
            assert!(
                j < rs.len() && rs[j] == *row,
                "{what}: the grid row at t = {} is not among the sub-step rows",
                row[0]
            );
        }
    }
    // The closed form.
    let (k, c, m, v0): (f64, f64, f64, f64) = (1e6, 200.0, 1.0, 1.0);
    let w = (k / m).sqrt();
    let sigma = c / (2.0 * m);
    let wd = (w * w - sigma * sigma).sqrt();
    let force = |t: f64| {
        let (s, co, e) = ((wd * t).sin(), (wd * t).cos(), (-sigma * t).exp());
        k * v0 / wd * e * s + c * v0 * e * (co - sigma / wd * s)
    };
    let dur = std::f64::consts::PI / wd;
    let n = 100_000;
    let dt = dur / n as f64;
    let f: Vec<f64> = (0..=n).map(|i| force(i as f64 * dt)).collect();
    let peak = f.iter().cloned().fold(f64::MIN, f64::max);
    let f2 = f
        .windows(3)
        .map(|w| ((w[2] - 2.0 * w[1] + w[0]) / (dt * dt)).abs())
        .fold(0.0, f64::max);
    let column = |dir: &Path| {
        let (h, rows) = read_csv(&dir.join("element_1.csv"));
        let i = h
            .iter()
            .position(|c| c == "normal_force")
            .expect("normal_force");
        let a = h.iter().position(|c| c == "active").expect("active");
        let contact: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r[a] > 0.5)
            .map(|r| (r[0], r[i]))
            .collect();
        contact
    };
    let (cg, cs) = (column(&dg), column(&ds));
    let max = |c: &[(f64, f64)]| c.iter().map(|x| x.1).fold(f64::MIN, f64::max);
    let spacing = cs.windows(2).map(|w| w[1].0 - w[0].0).fold(0.0, f64::max);
    let tol =
        f2 * spacing * spacing / 8.0 + peak * (w * spacing).powi(2) / 4.0 + k * v0 * 1e-4 * spacing;
    let (pg, ps) = (max(&cg), max(&cs));
    println!(
        "peak force: closed form {peak:.3} N, sub-step rows {ps:.3} N ({} rows in contact, \
         spacing ≤ {spacing:.2e} s, |err| {:.2e}, tol {tol:.2e}), grid rows {pg:.3} N ({} rows)",
        cs.len(),
        (ps - peak).abs(),
        cg.len()
    );
    assert!(ps >= pg, "the sub-step rows' peak is below the grid rows'");
    assert!(
        (ps - peak).abs() <= tol,
        "sub-step peak {ps} vs {peak} (tol {tol})"
    );
    assert!(
        (pg - peak).abs() > tol,
        "the grid rows alone already hold the peak"
    );
}
