//! `mecano-rs study`, through the binary, on a deck whose convergence is known in closed
//! form: the torque-free rigid body (`decks/free_body.dat`), integrated by HHT with α = 0.

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
    let dir = std::env::temp_dir().join(format!("mecano_study_{}", std::process::id()));
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
    let dir = std::env::temp_dir().join(format!("mecano_study_stop_{}", std::process::id()));
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
    assert_eq!(
        stdout.matches("stopped: Newton did not converge").count(),
        3
    );
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
