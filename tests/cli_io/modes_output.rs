//! The outputs of a modal analysis beyond its tables (issue 24 §4): the ParaView series of
//! each mode, `mecano-rs plot modes`, and the sweep quantity of a mode's frequency and
//! damping — each read back and checked against `modes.csv` / `modes_shapes.csv`.

use crate::common;

use common::TempDir;
use std::path::Path;

fn mecano(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .args(args)
        .current_dir(common::root())
        .output()
        .expect("run mecano-rs")
}

fn ok(o: &std::process::Output) {
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Column `name` of a CSV text, as strings per row.
fn column(text: &str, name: &str) -> Vec<String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let i = header.iter().position(|c| *c == name).expect(name);
    lines
        .map(|l| l.split(',').nth(i).unwrap().to_string())
        .collect()
}

/// The 3-vectors of the `DataArray` after `marker` in a `.vtu` text.
fn vtu_vectors(text: &str, marker: &str) -> Vec<[f64; 3]> {
    let start = text.find(marker).expect(marker);
    let body = &text[start..];
    // The end of the array's opening tag (every array here is written `format="ascii">`).
    let body = &body[body.find("format=\"ascii\">").unwrap()..];
    let body = &body[body.find('\n').unwrap() + 1..body.find("</DataArray>").unwrap()];
    body.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn paraview_series_and_plot_of_the_cantilever_modes_match_the_tables() {
    let dir = TempDir::new("modes_output");
    let d = dir.path().to_str().unwrap();
    ok(&mecano(&[
        "modes",
        "decks/cantilever_modes.dat",
        "--count",
        "4",
        "-o",
        d,
        "-q",
    ]));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let csv = std::fs::read_to_string(dir.join("modes.csv")).unwrap();
    let shapes = std::fs::read_to_string(dir.join("modes_shapes.csv")).unwrap();
    let periods: Vec<f64> = column(&csv, "period_s")
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
    let frames = mecano::modes::vtk::FRAMES;
    for k in 1..=4 {
        // The collection: FRAMES frames over one period of the mode (modes.csv's).
        let pvd = std::fs::read_to_string(dir.join(format!("vtk/mode_{k:03}.pvd"))).unwrap();
        assert_eq!(pvd.matches("<DataSet").count(), frames);
        let last = format!(
            "timestep=\"{:e}\"",
            periods[k - 1] * (frames - 1) as f64 / frames as f64
        );
        assert!(pvd.contains(&last), "{last} in {pvd}");
        // Frame FRAMES/4 (sin = 1) less frame 0 at the tip node (x = 1, 0, 0) is the
        // amplitude times the tip's row of modes_shapes.csv.
        let read = |j: usize| {
            std::fs::read_to_string(dir.join(format!("vtk/mode_{k:03}_{j:02}.vtu"))).unwrap()
        };
        let (f0, f4) = (read(0), read(frames / 4));
        let points = vtu_vectors(&f0, "<Points>");
        let tip = points
            .iter()
            .position(|p| (p[0] - 1.0).abs() < 1e-12 && p[1] == 0.0 && p[2] == 0.0)
            .expect("the tip node");
        let (d0, d4) = (
            vtu_vectors(&f0, "Name=\"displacement\""),
            vtu_vectors(&f4, "Name=\"displacement\""),
        );
        let amp = summary["vtk"]["modes"][k - 1]["amplitude"]
            .as_f64()
            .unwrap();
        assert_eq!(summary["vtk"]["modes"][k - 1]["unit"], "m");
        let row: Vec<String> = shapes
            .lines()
            .filter(|l| l.starts_with(&format!("{k},2,")))
            .map(String::from)
            .collect();
        let u: Vec<f64> = row[0]
            .split(',')
            .skip(2)
            .take(3)
            .map(|x| x.parse().unwrap())
            .collect();
        for c in 0..3 {
            // The frames carry 6 significant digits ({:e} of the shortest repr: all of
            // them) on a position of 1 m: round-off 1e-15 m on an amplitude of 5 cm.
            let got = (d4[tip][c] - d0[tip][c]) / amp;
            assert!(
                (got - u[c]).abs() < 1e-9,
                "mode {k}, component {c}: {got} vs {}",
                u[c]
            );
        }
    }

    // plot modes: the figure exists and its legend gives modes.csv's frequencies.
    let fig = dir.join("modes.svg");
    ok(&mecano(&[
        "plot",
        "modes",
        d,
        "-o",
        fig.to_str().unwrap(),
        "--modes",
        "1,3",
    ]));
    let svg = std::fs::read_to_string(&fig).unwrap();
    let f = column(&csv, "natural_hz");
    for k in [1usize, 3] {
        let label = mecano::plot::modes_label(k, f[k - 1].parse().unwrap());
        assert!(svg.contains(&label), "{label}");
    }
    // A mode that is not in modes.csv is bad input.
    let o = mecano(&[
        "plot",
        "modes",
        d,
        "-o",
        fig.to_str().unwrap(),
        "--modes",
        "9",
    ]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn a_sweep_reads_each_case_modes_frequency_and_damping() {
    let out = TempDir::new("modes_sweep");
    let o = out.path().to_str().unwrap();
    ok(&mecano(&[
        "sweep",
        "sweeps/cantilever_modes.toml",
        "-o",
        o,
        "--jobs",
        "1",
    ]));
    let sweep = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let (f1, f3, z1) = (
        column(&sweep, "f1"),
        column(&sweep, "f3"),
        column(&sweep, "zeta1"),
    );
    assert_eq!(f1.len(), 3);
    for case in 0..3 {
        let csv = std::fs::read_to_string(Path::new(o).join(format!("cases/{case:04}/modes.csv")))
            .unwrap();
        let nat = column(&csv, "natural_hz");
        let zeta = column(&csv, "damping_ratio");
        // The same doubles (both files write the shortest representation).
        let v = |s: &str| s.parse::<f64>().unwrap();
        assert_eq!(v(&f1[case]), v(&nat[0]));
        assert_eq!(v(&f3[case]), v(&nat[2]));
        assert_eq!(v(&z1[case]), v(&zeta[0]));
    }
    // A heavier tip mass lowers the first frequency (0.25, 1, 4 kg).
    let v = |s: &String| s.parse::<f64>().unwrap();
    assert!(v(&f1[0]) > v(&f1[1]) && v(&f1[1]) > v(&f1[2]));
}

/// The seed pendulum linearised about its state just before the first impact (issue 24:
/// `modes decks/pendulum.dat --at 0.533`, the run at the deck's h = 1e-4 s, HHT α = −0.1, to
/// t = 0.533 s, where node 23 is 0.95 mm above the floor), against the table of
/// docs/pendulum.md ("Just before the first impact"): no rigid mode (the motion's centrifugal
/// tension gives the three pendulum motions a frequency), the pendulum motions at 0.464,
/// 0.728, 1.036 Hz, the ten elastic ones 16.85–453.6 Hz, the mesh's highest 48,715 Hz, and
/// damping ratios below 7e-6 in size (a frozen linearisation of a moving state, no physical
/// damping).
///
/// Tolerances: each frequency within half a unit of the last digit the document prints
/// (5e-4 Hz for the pendulum motions, 5e-3 Hz for 16.85, 0.05 Hz for the others, 0.5 Hz for
/// the highest) — the document's claim to its printed precision. What may move a frequency
/// between machines is the run's state at 0.533 s: Newton's tolerance (1e-8 on the scaled
/// residual) perturbs it by ~1e-8 relative, and the frequencies as much, far below those
/// half-units. The damping bound is the document's (its largest |ζ| is 6.9e-6, its most
/// negative −4.1e-7: "ζ ≥ −4.2e-7" for the modes marked unstable). 2.2 s in the test profile.
#[test]
fn pendulum_modes_just_before_the_first_impact_match_the_document() {
    let dir = TempDir::new("modes_impact");
    let d = dir.path().to_str().unwrap();
    ok(&mecano(&[
        "modes",
        "decks/pendulum.dat",
        "--at",
        "0.533",
        "--count",
        "13",
        "-o",
        d,
    ]));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["rigid_modes"], 0, "no rigid mode in motion");
    let highest = summary["highest_frequency_hz"].as_f64().unwrap();
    assert!((highest - 48_715.0).abs() <= 0.5, "highest {highest} Hz");
    let csv = std::fs::read_to_string(dir.join("modes.csv")).unwrap();
    let f: Vec<f64> = column(&csv, "frequency_hz")
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
    let zeta: Vec<f64> = column(&csv, "damping_ratio")
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
    let kind = column(&csv, "kind");
    println!("frequencies {f:?}\ndamping {zeta:?}\nkinds {kind:?}");
    // (document's value, half a unit of its last printed digit)
    let doc = [
        (0.464, 5e-4),
        (0.728, 5e-4),
        (1.036, 5e-4),
        (16.85, 5e-3),
        (86.4, 0.05),
        (111.0, 0.05),
        (114.3, 0.05),
        (150.9, 0.05),
        (222.8, 0.05),
        (335.7, 0.05),
        (368.9, 0.05),
        (378.6, 0.05),
        (453.6, 0.05),
    ];
    assert_eq!(f.len(), doc.len());
    for (i, ((fi, zi), (want, tol))) in f.iter().zip(&zeta).zip(doc).enumerate() {
        assert!(
            (fi - want).abs() <= tol,
            "mode {}: {fi} Hz, document {want}",
            i + 1
        );
        assert!(zi.abs() < 7e-6, "mode {}: damping ratio {zi}", i + 1);
        assert!(
            kind[i] == "elastic" || kind[i] == "unstable",
            "mode {}: {}",
            i + 1,
            kind[i]
        );
        if kind[i] == "unstable" {
            assert!(*zi >= -4.2e-7, "mode {}: damping ratio {zi}", i + 1);
        }
    }
}
