//! Superelements (issue 38): the project's own beams exported (`mecano-rs export`), reduced
//! by Craig–Bampton and run as a `SUPERELEMENT`, against the beam decks they came from
//! (docs/superelements.md gives the figures these tests print). Runs in motion:
//! tests/superelement_motion.rs.

mod common;

use mecano::elements::superelement::{fe, invariants::Body, reduce};
use std::path::Path;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
}

/// The exported bar (decks/superelement/beam/).
fn beam() -> fe::FeModel {
    fe::read(&common::root().join("decks/superelement/beam")).expect("the exported bar reads")
}

/// `mecano-rs export` writes, for decks/superelement/beam_free.dat, the very files kept in
/// decks/superelement/beam/ (so the decks that read them are the export of today's code).
#[test]
fn export_writes_the_kept_files() {
    let dir = common::TempDir::new("se_export");
    let out = dir.join("beam");
    let o = bin()
        .current_dir(common::root())
        .args(["export", "decks/superelement/beam_free.dat", "-q", "-o"])
        .arg(&out)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for name in fe::FILES {
        let kept =
            std::fs::read_to_string(common::root().join("decks/superelement/beam").join(name))
                .expect("kept");
        let written = std::fs::read_to_string(out.join(name)).expect("written");
        assert_eq!(kept, written, "{name} differs from the export");
    }
}

/// Eigenvalues of the exported bar, clamped at node 1 and free–free, against its
/// Craig–Bampton reductions: errors fall as modes are added, 1e-8 with all kept.
#[test]
fn reduced_eigenvalues_converge() {
    let fe = beam();
    let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
    let n = fe.dofs.len();
    let node1: Vec<usize> = (0..6).map(|c| fe.dof_of(1, c).expect("node 1")).collect();
    let clamped: Vec<usize> = (0..n).filter(|r| !node1.contains(r)).collect();
    let full_c = reduce::lowest_eigenvalues(&k, &m, &clamped, 6).expect("clamped");
    let all: Vec<usize> = (0..n).collect();
    let full_f = reduce::lowest_eigenvalues(&k, &m, &all, 12).expect("free");
    let rel = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .fold(0.0f64, |e, (x, y)| e.max((x - y).abs() / y.abs()))
    };
    let (mut last_c, mut last_f) = (f64::INFINITY, f64::INFINITY);
    for modes in [2, 4, 8, 16, 42] {
        let red = reduce::reduce(&fe, &k, &m, &[1, 2], modes).expect("reduces");
        let body = Body::new(&fe, &m, &red, 1, &[2]).expect("mass");
        let nq = body.n;
        let mq = body.m0.view((6, 6), (nq, nq)).into_owned();
        let idx: Vec<usize> = (0..nq).collect();
        let c = reduce::lowest_eigenvalues(&body.k, &mq, &idx, 6).expect("reduced");
        let (mm, kk) = body.free_free();
        let idx: Vec<usize> = (0..6 + nq).collect();
        let f = reduce::lowest_eigenvalues(&kk, &mm, &idx, 12).expect("reduced");
        let (ec, ef) = (rel(&c, &full_c), rel(&f[6..], &full_f[6..]));
        eprintln!(
            "exported bar, interface nodes 1, 2, {modes:2} modes: clamped 6 lowest ω² {ec:.2e}, free-free 6 lowest elastic ω² {ef:.2e}"
        );
        assert!(ec <= last_c * (1.0 + 1e-9) && ef <= last_f * (1.0 + 1e-9));
        (last_c, last_f) = (ec, ef);
    }
    assert!(last_c < 1e-8 && last_f < 1e-8, "{last_c} {last_f}");
}

/// The `modes` command on the clamped bar as beams and as its superelement (every mode
/// kept): the same frequencies (the element's linearisation is the reduction's).
#[test]
fn modes_of_the_superelement_are_the_beams() {
    let dir = common::TempDir::new("se_modes");
    let read = |deck: &str, out: &str, set: &[&str]| -> Vec<f64> {
        let o = bin()
            .arg("modes")
            .arg(common::deck_path(deck))
            .args(["-q", "--count", "8", "-o"])
            .arg(dir.join(out))
            .args(set)
            .output()
            .expect("runs");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(dir.join(out).join("modes.csv")).expect("modes.csv");
        text.lines()
            .skip(1)
            .map(|l| {
                l.split(',')
                    .nth(2)
                    .expect("frequency")
                    .parse()
                    .expect("number")
            })
            .collect()
    };
    let beams = read("superelement/cantilever_beams.dat", "b", &[]);
    let all = read("superelement/cantilever_se.dat", "s", &[]);
    let few = read(
        "superelement/cantilever_se.dat",
        "s9",
        &["--set", "modes=9"],
    );
    for i in 0..8 {
        let e = (all[i] - beams[i]).abs() / beams[i];
        assert!(e < 1e-8, "mode {}: {} Hz vs {} Hz", i + 1, all[i], beams[i]);
        // 9 fixed-interface modes of a cantilever clamped at its frame (the 8th and 9th
        // are a pair of equal frequency, kept whole): its own lowest modes.
        let e9 = (few[i] - beams[i]).abs() / beams[i];
        assert!(e9 < 1e-8, "9 modes, mode {}: {e9}", i + 1);
    }
}

/// `modes` and `--check` list a superelement's own (fixed-interface) modes: for the bar
/// clamped at its frame node with 9 modes kept, they are the clamped bar's 8 lowest modes
/// computed on the beams (an independent route: the assembled beams' eigen-solve against
/// the reduction's interior one) to the listing's 7 printed digits (1e-6), and `--check` states each one's samples per
/// period at the deck's step, `1/(f h)`, to its 4 printed digits.
#[test]
fn a_superelements_own_modes_are_listed_with_the_steps_resolution() {
    let dir = common::TempDir::new("se_own_modes");
    let beams_dir = dir.join("b");
    let o = bin()
        .arg("modes")
        .arg(common::deck_path("superelement/cantilever_beams.dat"))
        .args(["-q", "--count", "8", "-o"])
        .arg(&beams_dir)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let beams: Vec<f64> = std::fs::read_to_string(beams_dir.join("modes.csv"))
        .expect("modes.csv")
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .nth(2)
                .expect("column")
                .parse()
                .expect("number")
        })
        .collect();
    // The listing: "element 1: 9 fixed-interface modes …", then one row per mode.
    let listed = |stdout: &str| -> Vec<Vec<f64>> {
        let mut lines = stdout
            .lines()
            .skip_while(|l| !l.contains("fixed-interface modes of its own"));
        assert!(lines.next().is_some(), "no listing in:\n{stdout}");
        lines
            .map_while(|l| {
                let cells: Vec<f64> = l
                    .split_whitespace()
                    .filter_map(|c| c.parse().ok())
                    .collect();
                (l.starts_with("  ") && cells.len() >= 2).then_some(cells)
            })
            .collect()
    };
    let o = bin()
        .arg("modes")
        .arg(common::deck_path("superelement/cantilever_se.dat"))
        .args(["--count", "8", "--set", "modes=9", "-o"])
        .arg(dir.join("s"))
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = listed(&String::from_utf8_lossy(&o.stdout));
    assert_eq!(rows.len(), 9);
    for (i, b) in beams.iter().enumerate() {
        let e = (rows[i][1] - b).abs() / b;
        assert!(
            e < 1e-6,
            "own mode {}: {} Hz vs the beams' {b} Hz",
            i + 1,
            rows[i][1]
        );
    }
    // --check on the pendulum (h = 1e-3 s, 4 modes): samples per period 1/(f h).
    let o = bin()
        .arg("--check")
        .arg(common::deck_path("superelement/pendulum_se.dat"))
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = listed(&String::from_utf8_lossy(&o.stdout));
    assert_eq!(rows.len(), 4);
    for r in &rows {
        let (f, samples) = (r[1], r[2]);
        assert!(
            (samples * f * 1e-3 - 1.0).abs() < 1e-3,
            "{f} Hz: {samples} samples per period at h = 1e-3 s"
        );
    }
}

/// A change made to a copy of the files or the deck.
type Edit = Box<dyn Fn(&Path)>;

/// Bad input: located errors, exit 2, nothing written.
#[test]
fn bad_files_are_refused_located() {
    let dir = common::TempDir::new("se_bad");
    let src = common::root().join("decks/superelement");
    let setup = |name: &str, edit: &dyn Fn(&Path)| -> std::path::PathBuf {
        let case = dir.join(name);
        std::fs::create_dir_all(case.join("beam")).expect("dir");
        for f in fe::FILES {
            std::fs::copy(src.join("beam").join(f), case.join("beam").join(f)).expect("copy");
        }
        std::fs::copy(src.join("pendulum_se.dat"), case.join("d.dat")).expect("copy");
        edit(&case);
        case
    };
    let replace = |p: std::path::PathBuf, from: &str, to: &str| {
        let t = std::fs::read_to_string(&p).expect("read");
        assert!(t.contains(from), "{from}");
        std::fs::write(&p, t.replacen(from, to, 1)).expect("write");
    };
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "truncated",
            Box::new(|c: &Path| {
                let p = c.join("beam/M.mtx");
                let t = std::fs::read_to_string(&p).expect("read");
                let cut: Vec<&str> = t.lines().take(10).collect();
                std::fs::write(&p, cut.join("\n")).expect("write");
            }),
            "M.mtx:10:1: truncated",
        ),
        (
            "malformed",
            Box::new(move |c: &Path| replace(c.join("beam/K.mtx"), "\n13 1 ", "\n13 x ")),
            "K.mtx:5:4: expected a column index, found `x`",
        ),
        (
            "asymmetric",
            Box::new(move |c: &Path| {
                replace(
                    c.join("beam/K.mtx"),
                    "coordinate real symmetric",
                    "coordinate real general",
                )
            }),
            "K.mtx",
        ),
        (
            "wrong_size",
            Box::new(move |c: &Path| replace(c.join("beam/M.mtx"), "54 54 ", "60 60 ")),
            "the matrix has 60 rows but the map of degrees of freedom lists 54",
        ),
        (
            "no_node",
            Box::new(move |c: &Path| {
                replace(c.join("d.dat"), "INTERFACE 1 1 2 2", "INTERFACE 1 1 77 2")
            }),
            "interface node 77",
        ),
        (
            "too_many_modes",
            Box::new(move |c: &Path| replace(c.join("d.dat"), "modes 4", "modes 43")),
            "MODES 43: the FE model has 42 interior",
        ),
        (
            "no_files",
            Box::new(move |c: &Path| replace(c.join("d.dat"), "FILES beam", "FILES nowhere")),
            "nodes.csv:0:0: cannot read",
        ),
        (
            "misplaced",
            Box::new(move |c: &Path| replace(c.join("d.dat"), "  2 1 0 0\n", "  2 1.1 0 0\n")),
            "FE interface node 2 (node 2) is at",
        ),
    ];
    for (name, edit, expect) in cases {
        let case = setup(name, &*edit);
        let err = common::refused(&case, name, expect);
        // Placed at the SUPERELEMENT card (line 15, column 3 of pendulum_se.dat).
        assert!(
            err.contains("d.dat: line 15:3: element 2: SUPERELEMENT"),
            "{name}: {err}"
        );
    }
}
