//! The modes through the command line: `mecano-rs modes`, bad requests, `--check`,
//! `ANALYSIS MODES` decks, and the step-resolution block of every dynamic run's summary.

use super::*;

#[test]
fn cli_writes_the_modes_of_the_cantilever() {
    let dir = common::TempDir::new("modes_cli");
    let _ = std::fs::remove_dir_all(&dir);
    let d = deck("cantilever_modes.dat");
    let out = mecano(&[
        "modes",
        d.to_str().unwrap(),
        "--count",
        "8",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.join("modes.csv")).unwrap();
    let f: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(3).unwrap().parse().unwrap())
        .collect();
    assert_eq!(f.len(), 8);
    // Same targets as the library test, through the files (modes 1 and 3).
    assert!((f[0] - TIMOSHENKO_HZ[0]).abs() <= 1e-6 * TIMOSHENKO_HZ[0] + 0.5e-5);
    assert!((f[2] - TIMOSHENKO_HZ[1]).abs() <= 1e-6 * TIMOSHENKO_HZ[1] + 0.5e-5);
    assert!(csv.starts_with("mode,kind,frequency_hz,natural_hz,damping_ratio,period_s,kinetic_BEAM,strain_BEAM,kinetic_MASS,strain_MASS"));
    let shapes = std::fs::read_to_string(dir.join("modes_shapes.csv")).unwrap();
    assert_eq!(
        shapes.lines().count(),
        1 + 8,
        "one output node, eight modes"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["complete"], true);
    assert_eq!(summary["rigid_modes"], 0);
    assert!(!csv.contains("NaN") && !csv.contains("inf"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_requests_exit_2_and_write_nothing() {
    let base = common::TempDir::new("modes_bad");
    let _ = std::fs::remove_dir_all(&base);
    // The four-bar's hinges are redundant (3 of 15 equations): one free unknown.
    let four = deck("four_bar.dat");
    let o = base.join("four");
    let out = mecano(&[
        "modes",
        four.to_str().unwrap(),
        "--count",
        "2",
        "-o",
        o.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("2 modes asked for") && err.contains("1 free unknowns"),
        "{err}"
    );
    assert!(!o.exists());
    // --at past END.
    let cant = deck("cantilever_modes.dat");
    let out = mecano(&[
        "modes",
        cant.to_str().unwrap(),
        "--at",
        "5",
        "-o",
        o.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!o.exists());
    // Nothing to vibrate: every node fixed.
    let text = "TITLE fixed\nMATERIALS\n  1 E 2.1e11 NU 0.3 RHO 7800\nSECTIONS\n  1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8\nNODES\n  1 0 0 0 FIX ALL\n  2 1 0 0 FIX ALL\nELEMENTS\n  1 BEAM 1 2 MAT 1 SEC 1\nANALYSIS DYNAMIC STEP 1e-3 END 1\n";
    std::fs::create_dir_all(&base).unwrap();
    let p = base.join("fixed.dat");
    std::fs::write(&p, text).unwrap();
    let out = mecano(&["modes", p.to_str().unwrap(), "-o", o.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nothing to vibrate"));
    assert!(!o.exists());
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn four_bar_mechanism_has_one_mode_and_check_reports_the_step() {
    // Redundant constraints eliminated by the rank-revealing null space: one free motion.
    let model = load(&deck("four_bar.dat"), &[], 1, None).unwrap();
    let a = modes(&model, About::Initial, 1);
    assert_eq!(a.free_unknowns, 1);
    assert_eq!(
        a.constraints.0 - a.constraints.1,
        3,
        "three redundant equations"
    );
    // --check states the highest frequency and what the step resolves.
    let out = mecano(&["--check", deck("cantilever_modes.dat").to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("highest frequency") && text.contains("what the step resolves"),
        "{text}"
    );
}

/// `ANALYSIS MODES 8` in a deck: running the deck performs the modal analysis of
/// `mecano-rs modes DECK --count 8` (the same modes.csv, byte for byte, as the cantilever
/// deck of `ANALYSIS DYNAMIC` asked for 8 modes), `modes` takes the deck's 8 as its
/// default count, and a count above the free unknowns is refused (exit 2, nothing written).
#[test]
fn analysis_modes_deck_runs_the_modal_analysis() {
    let base = common::TempDir::new("modes_deck");
    let _ = std::fs::remove_dir_all(&base);
    std::fs::create_dir_all(&base).unwrap();
    let original = std::fs::read_to_string(deck("cantilever_modes.dat")).unwrap();
    let dynamic = "ANALYSIS DYNAMIC ALPHA 0 STEP 2e-4 END 0.3";
    assert!(original.contains(dynamic));
    let p = base.join("cantilever.dat");
    std::fs::write(&p, original.replace(dynamic, "ANALYSIS MODES 8")).unwrap();
    let (p, a, b, c) = (
        p.to_str().unwrap(),
        base.join("run"),
        base.join("modes"),
        base.join("reference"),
    );
    let ok = |o: std::process::Output| {
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    // Each run's wall time, which bounds the seconds its summary.json states.
    let timed = |args: &[&str]| {
        let t0 = std::time::Instant::now();
        ok(mecano(args));
        t0.elapsed().as_secs_f64()
    };
    let wall_a = timed(&[p, "-q", "-o", a.to_str().unwrap()]);
    let wall_b = timed(&["modes", p, "-q", "-o", b.to_str().unwrap()]);
    let d = deck("cantilever_modes.dat");
    let (d, c) = (d.to_str().unwrap(), c.to_str().unwrap());
    let wall_c = timed(&["modes", d, "--count", "8", "-q", "-o", c]);
    // `cpu_seconds` (issue 34 §8): in the summary of an ANALYSIS MODES deck's run and of
    // `mecano-rs modes`, finite, ≥ 0 and no more than the process's wall time.
    for (dir, wall) in [
        (a.clone(), wall_a),
        (b.clone(), wall_b),
        (Path::new(c).to_path_buf(), wall_c),
    ] {
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        let cpu = s["cpu_seconds"]
            .as_f64()
            .unwrap_or_else(|| panic!("{}: no cpu_seconds in {s}", dir.display()));
        eprintln!(
            "{}: cpu_seconds {cpu:.4} (process {wall:.3} s)",
            dir.display()
        );
        assert!(
            cpu.is_finite() && cpu >= 0.0 && cpu <= wall,
            "{cpu} vs {wall}"
        );
    }
    let read = |dir: &Path| std::fs::read_to_string(dir.join("modes.csv")).unwrap();
    let reference = read(Path::new(c));
    assert_eq!(reference.lines().count(), 1 + 8);
    assert_eq!(read(&a), reference);
    assert_eq!(read(&b), reference);
    assert!(!a.join("energy.csv").exists(), "no time run");
    // 72 free unknowns (one beam of order 12: 12 nodes of 6): 100 modes are refused.
    let q = base.join("too_many.dat");
    std::fs::write(&q, original.replace(dynamic, "ANALYSIS MODES 100")).unwrap();
    let o = base.join("too_many");
    let out = mecano(&[q.to_str().unwrap(), "-q", "-o", o.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("100 modes asked for"));
    assert!(!o.exists());
    let _ = std::fs::remove_dir_all(&base);
}

/// Every dynamic run's summary.json states what the step resolves: the block holds the
/// lowest five elastic modes about the initial state (the frequencies of the library's
/// analysis, to round-off) and the mesh's highest, with `1/(f h)` samples per period and
/// HHT's closed-form damping and period error at that frequency; a model above the dense
/// limit says "not computed"; a static run has no block.
#[test]
fn dynamic_run_summary_states_what_the_step_resolves() {
    let base = common::TempDir::new("modes_summary");
    let _ = std::fs::remove_dir_all(&base);
    std::fs::create_dir_all(&base).unwrap();
    let summary = |dir: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
    };
    let run = |deck: &Path, dir: &Path| {
        let o = mecano(&[deck.to_str().unwrap(), "-q", "-o", dir.to_str().unwrap()]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    // The cantilever with its tip mass, cut to two steps (the block depends on the model).
    let text = std::fs::read_to_string(deck("cantilever_modes.dat"))
        .unwrap()
        .replace("END 0.3", "END 4e-4");
    let p = base.join("cantilever.dat");
    std::fs::write(&p, &text).unwrap();
    let dir = base.join("cantilever");
    run(&p, &dir);
    let block = &summary(&dir)["step_resolution"];
    assert_eq!(block["computed"], true, "{block}");
    let (alpha, h) = (0.0, 2e-4);
    assert_eq!(block["alpha"], alpha);
    assert_eq!(block["step"], h);
    let a = modes(&model_from(&text), About::Initial, 5);
    let rows = block["modes"].as_array().unwrap();
    assert_eq!(rows.len(), 5 + 1, "five elastic modes and the highest");
    let highest = block["highest_frequency_hz"].as_f64().unwrap();
    assert_eq!(rows[5]["frequency_hz"].as_f64().unwrap(), highest);
    assert!((highest - a.highest_hz).abs() <= 1e-9 * highest);
    for (r, m) in rows.iter().zip(&a.modes) {
        let f = r["frequency_hz"].as_f64().unwrap();
        // The same solve of the same model: equal to round-off (1e-9 relative).
        assert!(
            (f - m.natural_hz).abs() <= 1e-9 * f,
            "{f} vs {}",
            m.natural_hz
        );
    }
    for r in rows {
        let f = r["frequency_hz"].as_f64().unwrap();
        let s = r["samples_per_period"].as_f64().unwrap();
        assert!((s * f * h - 1.0).abs() < 1e-12, "{r}");
        // α = 0, the trapezoidal rule: no numerical damping, period error
        // Ω/(2 atan(Ω/2)) − 1 (closed form; src/modes/hht.rs's test holds it to 1e-11).
        let w = 2.0 * PI * f * h;
        let exact = w / (2.0 * (w / 2.0).atan()) - 1.0;
        assert!(r["hht_damping"].as_f64().unwrap().abs() < 1e-12, "{r}");
        let e = r["period_error"].as_f64().unwrap();
        assert!((e - exact).abs() <= 1e-9 * (1.0 + exact), "{e} vs {exact}");
    }
    // 301 beams of one free node each: 1806 unknowns, above the dense limit of --check.
    let long = "MATERIALS\n 1 E 2.1e11 NU 0.3 RHO 7800\nSECTIONS\n 1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8\n\
NODES\n 1 0 0 0 FIX ALL\n 2 TO 302 LINE 0.01 0 0 1 0 0\nELEMENTS\n 1 TO 301 BEAM 1 2 MAT 1 SEC 1\n\
ANALYSIS DYNAMIC STEP 1e-5 END 2e-5\nOUTPUT NODES 302 ELEMENTS NONE\n";
    let p = base.join("long.dat");
    std::fs::write(&p, long).unwrap();
    let dir = base.join("long");
    run(&p, &dir);
    let block = &summary(&dir)["step_resolution"];
    assert_eq!(block["computed"], false, "{block}");
    assert!(
        block["reason"]
            .as_str()
            .unwrap()
            .starts_with("not computed: 1806 unknowns")
    );
    // A static run: no step, no block.
    let p = base.join("static.dat");
    std::fs::write(
        &p,
        text.replace(
            "ANALYSIS DYNAMIC ALPHA 0 STEP 2e-4 END 4e-4",
            "ANALYSIS STATIC",
        ),
    )
    .unwrap();
    let dir = base.join("static");
    run(&p, &dir);
    assert!(summary(&dir).get("step_resolution").is_none());
    let _ = std::fs::remove_dir_all(&base);
}
