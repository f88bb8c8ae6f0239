//! `mecano-rs study`, through the binary, on a deck whose convergence is known in closed
//! form: the torque-free rigid body (`decks/free_body.dat`), integrated by HHT with α = 0.

mod common;

use std::path::Path;

/// Four fixed steps h = 4e-2 … 5e-3 s and one adaptive run over the 4 s of the deck. The body
/// spins at |ω| ≈ 3 rad/s, so ωh ≤ 0.12: HHT is in its asymptotic range and the observed
/// order between successive runs is 2 to within the O(ωh)² relative error of the first
/// term of the error expansion (≤ 0.015 in the ratio, ≤ 0.02 in the exponent); we allow
/// 1.9–2.1. The study must exit with code 0, write its two CSV files and the diagram, and
/// find every window's reference converged in positions and rotations (an order-2 ladder
/// contracts by 4 per halving, the test asks for 2).
#[test]
fn study_reports_order_two_on_the_free_body() {
    let dir = common::TempDir::new("study");
    let _ = std::fs::remove_dir_all(&dir);
    let deck = Path::new(env!("CARGO_MANIFEST_DIR")).join("decks/free_body.dat");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg("study")
        .arg(&deck)
        .args(["--steps", "4e-2,2e-2,1e-2,5e-3", "--adaptive", "1e-6"])
        .args(["--nodes", "1", "--window", "1"])
        .arg("-o")
        .arg(&dir)
        .output()
        .expect("binary runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0));
    // Beside its errors, what the steps resolve of the modes (issue 24), one line per step
    // of the ladder (the spinning body's only finite frequency, its gyroscopic one).
    assert!(stdout.contains("what the steps resolve ("), "{stdout}");
    for h in ["4.000e-2", "2.000e-2", "1.000e-2", "5.000e-3"] {
        assert!(
            stdout.contains(&format!("  h = {h} s  highest")),
            "{stdout}"
        );
    }
    for f in [
        "study.csv",
        "study_windows.csv",
        "work_precision.svg",
        "work_precision.png",
    ] {
        let len = std::fs::metadata(dir.join(f)).map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "{f} missing or empty");
    }
    let mut rd = csv::Reader::from_path(dir.join("study.csv")).unwrap();
    let head = rd.headers().unwrap().clone();
    let col = |name: &str| head.iter().position(|h| h == name).unwrap();
    let (c_order, c_err, c_tol) = (
        col("observed_order"),
        col("error_rotation"),
        col("adaptive_tol"),
    );
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 5);
    let orders: Vec<f64> = rows
        .iter()
        .filter_map(|r| r[c_order].parse().ok())
        .collect();
    assert_eq!(orders.len(), 2, "orders of the first two runs: {orders:?}");
    for p in &orders {
        assert!((p - 2.0).abs() <= 0.1, "observed orders {orders:?}");
    }
    // Errors fall with h; the adaptive run has a finite, reported error.
    let errs: Vec<f64> = rows.iter().map(|r| r[c_err].parse().unwrap()).collect();
    assert!(errs[0] > errs[1] && errs[1] > errs[2] && errs[2] > errs[3]);
    assert_eq!(errs[3], 0.0, "the finest run is the reference");
    let adaptive = rows.iter().find(|r| !r[c_tol].is_empty()).unwrap();
    assert!(adaptive[c_err].parse::<f64>().unwrap().is_finite());
    let mut rw = csv::Reader::from_path(dir.join("study_windows.csv")).unwrap();
    let hw = rw.headers().unwrap().clone();
    let cols: Vec<usize> = ["position_converged", "rotation_converged"]
        .iter()
        .map(|name| hw.iter().position(|h| h == *name).unwrap())
        .collect();
    for r in rw.records() {
        let r = r.unwrap();
        for &c in &cols {
            assert_eq!(&r[c], "true");
        }
    }
    for f in ["study.csv", "study_windows.csv"] {
        let text = std::fs::read_to_string(dir.join(f)).unwrap().to_lowercase();
        assert!(!text.contains("nan") && !text.contains("inf"), "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A study whose runs all stop (`decks/stab_diverge.dat`, built to fail: 1e12 N on a steel
/// cantilever, Newton limited to 10 iterations): each run's row says where it stopped,
/// the CSVs mark the runs incomplete and hold no number for their errors (no `NaN`, no
/// `inf`), and the study exits non-zero since no error can be measured.
#[test]
fn study_of_runs_that_stop_reports_them_and_writes_no_non_numbers() {
    let dir = common::TempDir::new("study_stop");
    let _ = std::fs::remove_dir_all(&dir);
    let deck = Path::new(env!("CARGO_MANIFEST_DIR")).join("decks/stab_diverge.dat");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg("study")
        .arg(&deck)
        .args(["--steps", "1e-2,5e-3,2.5e-3", "-o"])
        .arg(&dir)
        .output()
        .expect("binary runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}\n{stderr}");
    assert_eq!(out.status.code(), Some(1));
    // Each stops, by Newton's divergence or by the energy guard refusing the blow-up
    // (since issue 35 §0, 3.3e16 J created at 7.2e-3 s on the 2.5e-3 s run; since issue
    // 37's co-rotated kept matrix Newton follows the blow-up further and the guard stops
    // all three, 4.0e15–6.4e15 J created).
    assert_eq!(stdout.matches("└ stopped: ").count(), 3, "{stdout}");
    let by_newton = stdout.matches("stopped: Newton did not converge").count();
    let by_guard = stdout.matches("stopped: the integration created").count();
    assert_eq!(by_newton + by_guard, 3, "{stdout}");
    assert!(stderr.contains("no run has a measurable error"));
    let mut rd = csv::Reader::from_path(dir.join("study.csv")).unwrap();
    let c = rd
        .headers()
        .unwrap()
        .iter()
        .position(|h| h == "complete")
        .unwrap();
    for r in rd.records() {
        assert_eq!(&r.unwrap()[c], "false");
    }
    for f in ["study.csv", "study_windows.csv"] {
        let text = std::fs::read_to_string(dir.join(f)).unwrap().to_lowercase();
        assert!(!text.contains("nan") && !text.contains("inf"), "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The space–time study (`--refine 1,2,4,8 --steps 4e-4,2e-4,1e-4`) on a cantilever under a
/// smooth tip force (`decks/cantilever_smooth_load.dat`, 4 → 32 elements). Two-node beams
/// with one-point quadrature converge at order 2 in the element length (the element's
/// bending error is (L_e²/12) × the curvature's second derivative, Taylor expansion of the
/// midpoint rule), HHT at order 2 in the step; the load being smooth, the response is in
/// the asymptotic range of both, where successive differences fall by 2² per halving to
/// within the next term of the expansion (relative O(L_e²) and O((ωh)²), below 5 % here),
/// so the observed orders must be 2 ± 0.1 in space (before the last pair, which has no
/// successor) and 2 ± 0.2 in time (HHT's α = −0.1 adds an O(h) term of size α(ωh)² that
/// is not yet negligible at the coarsest step). Every window's reference is then
/// converged in both variables, every run is scored, and the files and diagram are written.
#[test]
fn space_time_study_separates_second_order_errors_in_space_and_time() {
    let dir = common::TempDir::new("spacetime");
    let _ = std::fs::remove_dir_all(&dir);
    let deck = Path::new(env!("CARGO_MANIFEST_DIR")).join("decks/cantilever_smooth_load.dat");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg("study")
        .arg(&deck)
        .args(["--refine", "1,2,4,8", "--steps", "4e-4,2e-4,1e-4"])
        .args(["--nodes", "5", "--window", "0.05"])
        .arg("-o")
        .arg(&dir)
        .output()
        .expect("binary runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0));
    for f in [
        "spacetime.csv",
        "spacetime_windows.csv",
        "spacetime_ladders.csv",
        "table.txt",
        "work_precision.svg",
        "work_precision.png",
    ] {
        let len = std::fs::metadata(dir.join(f)).map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "{f} missing or empty");
    }
    let mut rd = csv::Reader::from_path(dir.join("spacetime_ladders.csv")).unwrap();
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    let mut space_orders = Vec::new();
    let mut time_orders = Vec::new();
    for r in &rows {
        assert_eq!(&r[5], "true", "every window converged: {r:?}");
        if let Ok(p) = r[4].parse::<f64>() {
            match &r[0] {
                "space" => space_orders.push(p),
                _ => time_orders.push(p),
            }
        }
    }
    // 4 meshes: orders of levels 1 and 2 (2 windows each); 3 steps: level 1.
    assert_eq!(space_orders.len(), 4, "{space_orders:?}");
    assert_eq!(time_orders.len(), 2, "{time_orders:?}");
    for p in &space_orders {
        assert!((p - 2.0).abs() <= 0.1, "space orders {space_orders:?}");
    }
    for p in &time_orders {
        assert!((p - 2.0).abs() <= 0.2, "time orders {time_orders:?}");
    }
    let mut rd = csv::Reader::from_path(dir.join("spacetime.csv")).unwrap();
    let runs: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    assert_eq!(runs.len(), 12);
    // Every run but the reference is scored, and the coarsest mesh's error is its space
    // error (the time error is 100 times smaller here).
    let errs: Vec<f64> = runs.iter().map(|r| r[9].parse().unwrap()).collect();
    assert_eq!(errs[11], 0.0);
    assert!(errs[..11].iter().all(|e| *e > 0.0));
    assert!(runs.iter().any(|r| &r[10] == "true"), "a frontier");
    // Two meshes cannot judge convergence in space: bad input, exit code 2.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg("study")
        .arg(&deck)
        .args([
            "--refine",
            "1,2",
            "--steps",
            "4e-4,2e-4,1e-4",
            "--nodes",
            "5",
        ])
        .arg("-o")
        .arg(&dir)
        .output()
        .expect("binary runs");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("at least three meshes"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The study over beam orders (`--order 1,2,4,8`, issue 18) on the same cantilever (4 beam
/// elements, each set to order p). The claim of elements of order p is that raising the
/// order beats dividing the elements at equal nodes: a two-node mesh with twice the nodes
/// cuts its error by 2² (order 2 in the element length, test above), so each doubling of p
/// (twice the nodes per element) must cut the space error by more than 4 — for a smooth
/// field it falls exponentially in p. The ladder's space and time checks stay those of the
/// refinement study: the reference (order 8) is converged in both and every window scored.
/// `--order 0` and two levels with the same number of nodes are bad input (exit 2).
#[test]
fn order_study_shows_errors_falling_faster_than_mesh_refinement() {
    let dir = common::TempDir::new("orderstudy");
    let _ = std::fs::remove_dir_all(&dir);
    let deck = Path::new(env!("CARGO_MANIFEST_DIR")).join("decks/cantilever_smooth_load.dat");
    let study = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
            .arg("study")
            .arg(&deck)
            .args(args)
            .args([
                "--steps",
                "4e-4,2e-4,1e-4",
                "--nodes",
                "5",
                "--window",
                "0.05",
            ])
            .arg("-o")
            .arg(&dir)
            .output()
            .expect("binary runs")
    };
    let out = study(&["--order", "1,2,4,8"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0));
    assert!(stdout.contains("space-time reference: refine 1 order 8"));
    let mut rd = csv::Reader::from_path(dir.join("spacetime_ladders.csv")).unwrap();
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    assert!(rows.iter().all(|r| &r[5] == "true"), "converged: {rows:?}");
    // Space errors per level (k·p = 1, 2, 4) and window, against order 8.
    let space: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| &r[0] == "space")
        .map(|r| (r[1].parse().unwrap(), r[3].parse().unwrap()))
        .collect();
    for w in 0..2 {
        let e: Vec<f64> = space.iter().skip(w).step_by(2).map(|x| x.1).collect();
        assert!(e[0] > 0.0, "order 1 has a space error: {e:?}");
        assert!(e[1] < e[0] / 4.0 && e[2] < e[1] / 4.0, "window {w}: {e:?}");
    }
    let mut rd = csv::Reader::from_path(dir.join("spacetime.csv")).unwrap();
    let runs: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    assert_eq!(runs.len(), 12);
    assert_eq!(
        runs.iter().map(|r| r[1].to_string()).collect::<Vec<_>>()[..],
        ["1", "1", "1", "2", "2", "2", "4", "4", "4", "8", "8", "8"]
    );
    for bad in [
        &["--order", "0,2,4"][..],
        &["--refine", "1,2", "--order", "2,4"],
    ] {
        let out = study(bad);
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--order 0") || err.contains("same number of nodes"),
            "{err}"
        );
    }
    // A space–time study takes one integrator: two are refused (exit 2, nothing run) with a
    // message naming them, not the "--adaptive" one (none was given).
    let out = study(&["--order", "1,2", "--integrator", "hht,esdirk3"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("runs one integrator, got 2 (hht:-0.1, esdirk3)")
            && !err.contains("--adaptive"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Accuracy asked for (issue 37 §1): with ADAPTIVE the ESDIRK schemes control their steps
/// by their embedded pairs (ESDIRK3(2), ESDIRK5(4)), the position error of the step and the
/// velocity error carried over the run (`T e_v`), so that the global error follows the
/// tolerance in proportion. On the simple pendulum (a 1 m hinge arm, index-3 constraints:
/// both schemes third order in positions) over 2 s, four tolerances 1e-3 … 1e-6 m against
/// a fixed-step reference at h = 6.25e-4 s (its own error ~3e-9 m: 1/8 of the next run's
/// 2.1e-8 m at order 3): the least-squares slope of ln error on ln tol is the issue's
/// target 1 ± 0.2 (measured 0.97 and 1.02; the estimate of positions alone, per step,
/// gave ESDIRK5 0.69 — the embedded difference is O(h⁵) where the constrained positions
/// err at O(h⁴) per step).
#[test]
fn adaptive_esdirk_errors_follow_the_tolerance() {
    let deck = Path::new(env!("CARGO_MANIFEST_DIR")).join("decks/simple_pendulum.dat");
    for scheme in ["esdirk3", "esdirk5"] {
        let dir = common::TempDir::new(&format!("study_tol_{scheme}"));
        let _ = std::fs::remove_dir_all(&dir);
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
            .arg("study")
            .arg(&deck)
            .args(["--integrator", scheme])
            .args(["--steps", "1e-2,5e-3,2.5e-3,1.25e-3,6.25e-4"])
            .args(["--adaptive", "1e-3,1e-4,1e-5,1e-6"])
            .args(["--until", "2", "--window", "0.5", "-o"])
            .arg(&dir)
            .output()
            .expect("binary runs");
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{stdout}");
        let mut rd = csv::Reader::from_path(dir.join("study.csv")).unwrap();
        let h = rd.headers().unwrap().clone();
        let col = |n: &str| h.iter().position(|x| x == n).unwrap();
        let (ct, ce) = (col("adaptive_tol"), col("error_position"));
        let pts: Vec<(f64, f64)> = rd
            .records()
            .map(|r| r.unwrap())
            .filter(|r| !r[ct].is_empty())
            .map(|r| (r[ct].parse::<f64>().unwrap(), r[ce].parse::<f64>().unwrap()))
            .collect();
        assert_eq!(pts.len(), 4, "{stdout}");
        let n = pts.len() as f64;
        let (mx, my) = pts.iter().fold((0.0, 0.0), |(a, b), (t, e)| {
            (a + t.ln() / n, b + e.ln() / n)
        });
        let (sxy, sxx) = pts.iter().fold((0.0, 0.0), |(a, b), (t, e)| {
            (a + (t.ln() - mx) * (e.ln() - my), b + (t.ln() - mx).powi(2))
        });
        let slope = sxy / sxx;
        assert!(
            (slope - 1.0).abs() <= 0.2,
            "{scheme}: slope {slope}: {pts:?}"
        );
        assert!(
            stdout.contains("tolerance proportionality: error ∝ tol^"),
            "{stdout}"
        );
        assert!(dir.join("tolerance.svg").exists());
    }
}
