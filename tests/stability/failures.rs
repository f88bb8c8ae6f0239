//! Runs built to diverge fail cleanly: a diagnosis, histories up to the failure, marked
//! incomplete, no NaN written.

use super::*;

/// Two decks built to diverge, through the binary: `decks/stab_diverge.dat` (a steel
/// cantilever hit by 1e12 N at once, steps not allowed to be cut) and
/// `decks/stab_pendulum_undamped.dat` (α = 0 on unresolved beam modes: the energy grows
/// until Newton fails near t = 2.26 s). Each: exit code 1; the diagnosis on standard error
/// names the time, the step, the residual history and the worst node or element (its equation); `summary.json` says
/// `"complete": false` with the failure; no NaN or infinity in any output file.
#[test]
fn a_diverging_run_fails_cleanly() {
    for name in ["stab_diverge", "stab_pendulum_undamped"] {
        fails_cleanly(name);
    }
}

pub(super) fn fails_cleanly(name: &str) {
    let scratch = common::TempDir::new(name);
    let dir = scratch.path();
    let deck = common::deck_path(&format!("{name}.dat"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck)
        .arg("-o")
        .arg(dir)
        .output()
        .expect("binary runs");
    let err = String::from_utf8_lossy(&out.stderr);
    println!("exit {:?}\n{err}", out.status.code());
    assert_eq!(out.status.code(), Some(1));
    for needle in [
        "at t = ",
        "with step h = ",
        "relative residual by iteration",
    ] {
        assert!(err.contains(needle), "diagnosis lacks {needle:?}: {err}");
    }
    assert!(
        err.contains("largest residual: node ") || err.contains("largest residual: element "),
        "diagnosis names no worst node or element: {err}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["complete"], serde_json::json!(false));
    assert!(
        summary["failure"]["worst"]
            .as_str()
            .unwrap()
            .starts_with("node ")
            || summary["failure"]["worst"]
                .as_str()
                .unwrap()
                .starts_with("element ")
    );
    assert!(summary["failure"]["time"].as_f64().is_some());
    let mut files = 0;
    for f in std::fs::read_dir(dir).unwrap() {
        let p = f.unwrap().path();
        let text = std::fs::read_to_string(&p).unwrap();
        // A non-finite value is a whole field `nan`, `inf`, `-inf` or `infinity` (not a
        // key such as summary.json's `rho_inf`).
        let low = text.to_ascii_lowercase();
        let non_finite = low
            .split(|c: char| c == ',' || c == ':' || c == '"' || c.is_whitespace())
            .any(|w| matches!(w.trim_start_matches(['-', '+']), "nan" | "inf" | "infinity"));
        assert!(!non_finite, "{} has a non-finite value", p.display());
        files += 1;
    }
    assert!(files >= 3);
}
