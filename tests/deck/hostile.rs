//! Issue 28 (§2–§5): careless and hostile input, each class a test that failed before the
//! fix. Deep nesting is refused with a location (no stack overflow: these tests run on
//! the test harness's 2 MiB threads and through the binary); a Slurm script is never
//! written with an unvalidated value; a huge field is refused fast with a short message;
//! model errors point at their card; `sweep` reports failed cases and unknown names.

use crate::common;

use mecano::deck::{DeckErrorKind as K, DeckErrors, ECHO_CHARS, limits, load_deck, parse_deck};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

const BIN: &str = env!("CARGO_BIN_EXE_mecano-rs");

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A scratch directory removed when the test ends, also when it fails ([`common::TempDir`]).
fn tmp(name: &str) -> common::TempDir {
    common::TempDir::new(&format!("hostile_{name}"))
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A small valid deck (a falling mass) with `params` as its PARAMETERS section.
fn deck_with(params: &str) -> String {
    format!(
        "TITLE t\nPARAMETERS\n{params}\nNODES\n 1 0 0 0\nELEMENTS\n 1 MASS 1 M 1\n\
         ANALYSIS DYNAMIC STEP 1e-3 END 2e-3\nEND\n"
    )
}

/// The first error of `src` and its line and column.
fn first_error(src: &str) -> (K, (usize, usize), String) {
    let e = parse_deck(src, "d.dat").expect_err("a bad deck");
    let lc = e.line_col(0).expect("the error is located");
    (e.errors()[0].kind.clone(), lc, e.errors()[0].to_string())
}

/// Renders the diagnostic as the binary prints it (miette, no colours).
fn rendered(e: DeckErrors) -> String {
    let mut s = String::new();
    miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
        .render_report(&mut s, &e)
        .expect("render");
    s
}

// ------------------------------------------------------------------------------------ §2

#[test]
fn deep_expressions_are_located_errors_in_process() {
    // Within the field limit (1024 bytes): the expression parser's own depth bound.
    let deep = [
        format!("{}1{}", "(".repeat(500), ")".repeat(500)),
        format!("{}1{}", "sqrt(".repeat(150), ")".repeat(150)),
        format!("{}1", "-".repeat(1000)),
        vec!["1"; 500].join("^"),
    ];
    for d in &deep {
        let (kind, (line, col), msg) = first_error(&deck_with(&format!("  x {d}")));
        assert!(matches!(kind, K::ExpressionTooDeep { .. }), "{msg}");
        assert_eq!(line, 3, "{msg}");
        assert!(col > 5 && col < 1030, "{col}");
        assert!(msg.len() < 200, "short message: {msg}");
    }
    // 100,000 levels (the inputs): refused by the line limit, located.
    for d in [
        format!("{}1{}", "(".repeat(100_000), ")".repeat(100_000)),
        format!("{}1", "-".repeat(100_000)),
    ] {
        let (kind, (line, col), _) = first_error(&deck_with(&format!("  x {d}")));
        assert!(matches!(kind, K::TooLarge { .. }));
        assert_eq!((line, col), (3, limits::MAX_LINE_BYTES + 1));
    }
    // `--set` values: the constant evaluator, 60,000 levels.
    let e = mecano::deck::eval_constant_located(&format!(
        "{}1{}",
        "(".repeat(60_000),
        ")".repeat(60_000)
    ))
    .expect_err("too deep");
    assert!(
        e.0 > 1 && e.0 < 200 && e.1.contains("nested too deeply"),
        "{e:?}"
    );
    assert!(e.1.len() < 300, "{}", e.1);
}

#[test]
fn deep_expressions_exit_2_through_the_binary() {
    let dir = tmp("deep");
    let n = 100_000;
    let cases = [
        ("parens", format!("{}1{}", "(".repeat(n), ")".repeat(n))),
        ("sqrt", format!("{}1{}", "sqrt(".repeat(n), ")".repeat(n))),
        ("minus", format!("{}1", "-".repeat(n))),
        ("power", vec!["1"; n].join("^")),
        ("short", format!("{}1{}", "(".repeat(400), ")".repeat(400))),
    ];
    for (name, d) in &cases {
        let deck = dir.join(format!("{name}.dat"));
        std::fs::write(&deck, deck_with(&format!("  x {d}"))).expect("write");
        let o = Command::new(BIN)
            .arg(&deck)
            .arg("--check")
            .output()
            .expect("runs");
        let t = text(&o);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{name}: {}",
            &t[..t.len().min(2000)]
        );
        assert!(
            t.contains(&format!("{name}.dat:3:")),
            "{name}: located: {t:.2000}"
        );
        assert!(t.len() < 40_000, "{name}: {} bytes of diagnostic", t.len());
    }
    // `--set k=` with 60,000 nested parentheses: clap's usage error (2) with the reason
    // (clap's message repeats the argument as given; ours adds a short one).
    let set = format!("x={}1{}", "(".repeat(60_000), ")".repeat(60_000));
    let deck = dir.join("short.dat");
    let o = Command::new(BIN)
        .arg(&deck)
        .args(["--check", "--set", &set])
        .output()
        .expect("runs");
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t:.2000}");
    assert!(
        t.contains("nested too deeply") && t.len() < 130_000,
        "{t:.2000}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn deep_plans_are_refused_not_overflowed() {
    let dir = tmp("deepplan");
    let n = 100_000;
    for (name, v) in [
        ("arrays", format!("{}{}", "[".repeat(n), "]".repeat(n))),
        ("tables", format!("{}1{}", "{a=".repeat(n), "}".repeat(n))),
    ] {
        let plan = dir.join(format!("{name}.toml"));
        std::fs::write(
            &plan,
            format!(
                "deck = {:?}\nx = {v}\n",
                root().join("decks/bounce_sweep.dat")
            ),
        )
        .expect("write");
        let o = Command::new(BIN)
            .args(["sweep", plan.to_str().expect("utf-8"), "--list"])
            .output()
            .expect("runs");
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{name}: {t:.2000}");
        assert!(t.contains("line 2"), "{name}: located: {t:.2000}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// ------------------------------------------------------------------------------------ §3

fn emit(out: &Path, extra: &[&str]) -> Output {
    Command::new(BIN)
        .args(["sweep", "sweeps/bounce.toml", "--emit", "slurm", "-o"])
        .arg(out)
        .args(extra)
        .current_dir(root())
        .output()
        .expect("runs")
}

#[test]
fn hostile_scheduler_options_are_refused_and_no_script_is_written() {
    let dir = tmp("slurm");
    let marker = dir.join("INJECTED");
    let inject = format!("01:00:00\ntouch {}", marker.display());
    let hostile: Vec<Vec<String>> = vec![
        vec!["--time".into(), inject.clone()],
        vec!["--time".into(), "1:00:00:00".into()],
        vec!["--time".into(), "01:00:00 ; rm -rf ~".into()],
        vec!["--time".into(), "1-2-3".into()],
        vec!["--mem".into(), "1G\n#SBATCH --uid=0".into()],
        vec!["--mem".into(), "1GB".into()],
        vec!["--mem".into(), "$(reboot)".into()],
        vec!["--partition".into(), "debug\ntouch x".into()],
        vec!["--partition".into(), "a,,b".into()],
        vec!["--partition".into(), "a b".into()],
        vec!["--chunk".into(), "0".into()],
        vec!["--max-running".into(), "0".into()],
    ];
    for args in &hostile {
        let out = dir.join("out");
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = emit(&out, &a);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {t}");
        assert!(
            t.contains(&args[0]) && t.contains("refused"),
            "{args:?}: {t}"
        );
        assert!(!t.contains('\n') || t.lines().count() < 5, "{t}");
        assert!(
            !out.join("sweep.sbatch").exists(),
            "{args:?}: a script was written"
        );
        assert!(!out.exists(), "{args:?}: nothing is written");
    }
    // An output directory a #SBATCH line cannot hold.
    let bad_out = dir.join("a\nb%c");
    let o = emit(&bad_out, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(!bad_out.exists());
    // Slurm's own formats are accepted, and the script holds them as given.
    for (time, mem, part) in [
        ("30", "500", "debug"),
        ("10:00", "4G", "a,b-c.d_e"),
        ("1-0", "1024M", "x"),
        ("2-12:30", "1T", "x"),
        ("0-01:00:00", "64k", "x"),
    ] {
        let out = dir.join("ok");
        let o = emit(
            &out,
            &[
                "--time",
                time,
                "--mem",
                mem,
                "--partition",
                part,
                "--max-running",
                "2",
            ],
        );
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        let s = std::fs::read_to_string(out.join("sweep.sbatch")).expect("script");
        assert!(s.contains(&format!("#SBATCH --time={time}\n")), "{s}");
        assert!(s.contains(&format!("#SBATCH --mem={mem}\n")), "{s}");
        assert!(s.contains(&format!("#SBATCH --partition={part}\n")), "{s}");
        assert!(s.contains("%2\n"), "{s}");
        let _ = std::fs::remove_dir_all(&out);
    }
    assert!(!marker.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

// ------------------------------------------------------------------------------------ §4

#[test]
fn a_50_mb_field_is_refused_fast_with_a_short_message() {
    // 50 MB of digits in a numeric field, built in memory (the file route reads at most
    // MAX_DECK_BYTES + 1 bytes, see below). Before: 40 s, 689 MB, 280 MB of message.
    let mut src = String::from("NODES\n 1 0 0 ");
    src.push_str(&"1".repeat(50_000_000));
    src.push_str("\nANALYSIS STATIC\nEND\n");
    let t0 = Instant::now();
    let e = parse_deck(&src, "big.dat").expect_err("too large");
    let dt = t0.elapsed().as_secs_f64();
    assert_eq!(e.line_col(0), Some((2, limits::MAX_LINE_BYTES + 1)));
    let r = rendered(e);
    // Measured: ~1 ms in the test profile (one pass up to the line limit); 2 s is a
    // bound no linear reader misses and the old quadratic echo could not meet.
    assert!(dt < 2.0, "{dt} s");
    assert!(
        r.len() < 3 * limits::MAX_LINE_BYTES,
        "{} bytes of diagnostic",
        r.len()
    );
    // The same field within the line limit but over the field limit, and a huge keyword
    // in a small deck: the message echoes at most ECHO_CHARS characters of the token.
    let long = "9".repeat(5000);
    let src = format!("NODES\n 1 0 0 &\n {long}\nANALYSIS STATIC\nEND\n");
    let (kind, lc, _) = first_error(&src);
    assert!(
        matches!(kind, K::TooLarge { .. }) && lc == (3, 2),
        "{kind:?} {lc:?}"
    );
    let kw = "Q".repeat(1000);
    let (_, lc, msg) = first_error(&format!("NODES\n 1 0 0 {kw}\nANALYSIS STATIC\nEND\n"));
    assert_eq!(lc, (2, 8));
    assert!(
        msg.len() < 2 * ECHO_CHARS + 200 && msg.contains('…'),
        "{msg}"
    );
    // A TABLE with more values than a card may hold: located at the first one too many.
    let mut src = String::from("FUNCTIONS\n 1 TABLE");
    for _ in 0..(limits::MAX_CARD_FIELDS / 1000 + 1) {
        src.push_str(" &\n");
        src.push_str(&" 0 0".repeat(500));
    }
    src.push_str("\nANALYSIS STATIC\nEND\n");
    let (kind, (line, _), _) = first_error(&src);
    assert!(
        matches!(kind, K::TooLarge { what: "a card", .. }),
        "{kind:?}"
    );
    assert_eq!(line, 2 + limits::MAX_CARD_FIELDS / 1000);
}

#[test]
fn a_deck_file_beyond_the_size_limit_is_not_loaded() {
    let dir = tmp("size");
    let deck = dir.join("huge.dat");
    // Many short valid lines: only the size limit is broken.
    let line = "! a comment line of some sixty bytes, repeated to pass 16 MiB\n";
    let n = limits::MAX_DECK_BYTES / line.len() + 10;
    std::fs::write(&deck, line.repeat(n)).expect("write");
    let t0 = Instant::now();
    let e = load_deck(&deck).expect_err("too large");
    assert!(matches!(
        e.errors()[0].kind,
        K::TooLarge {
            what: "the deck",
            ..
        }
    ));
    let (l, c) = e.line_col(0).expect("located");
    assert_eq!(c, 1);
    assert_eq!(l, limits::MAX_DECK_BYTES / line.len() + 1);
    assert!(t0.elapsed().as_secs_f64() < 5.0);
    let o = Command::new(BIN)
        .arg(&deck)
        .arg("--check")
        .output()
        .expect("runs");
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).len() < 5000, "{}", text(&o).len());
    let _ = std::fs::remove_dir_all(&dir);
}

// ------------------------------------------------------------------------------------ §5

const NODES: &str = "NODES\n 1 0 0 0\n 2 1 0 0\n 3 1 1 0\n";
const TAIL: &str = "ANALYSIS DYNAMIC STEP 1e-3 END 2e-3\nEND\n";

/// The first error of a deck with these ELEMENTS cards (line 6 is the first of them).
fn element_error(elements: &str) -> (K, (usize, usize), String) {
    first_error(&format!("{NODES}ELEMENTS\n{elements}\n{TAIL}"))
}

#[test]
fn model_errors_point_at_their_card() {
    for (card, col) in [
        (" 1 RIGID 1 2 1", 14),
        (" 1 HINGE 2 2 AXIS 0 0 1", 12),
        (" 1 SPHERICAL 3 3", 16),
        (" 1 UJOINT 1 1 AXIS1 1 0 0 AXIS2 0 1 0", 13),
        (" 1 CLAMP 1 1", 12),
        (" 1 PRISMATIC 1 1 AXIS 1 0 0", 16),
        (" 1 CAME 2 2 CAM LINE FOLLOWER POINT K 1e6", 11),
    ] {
        let (kind, lc, msg) = element_error(card);
        assert!(matches!(kind, K::NodeToItself { .. }), "{card}: {msg}");
        assert_eq!(lc, (6, col), "{card}: {msg}");
    }
    for (card, col) in [
        (" 1 CAME 1 2 CAM POINT FOLLOWER POINT K 1e6", 23),
        (" 1 CAME 1 2 CAM LINE FOLLOWER LINE K 1e6", 22),
        (" 1 CAME 1 2 CAM SPLINE 2 0 0 1 0 FOLLOWER LINE K 1e6", 34),
    ] {
        let (kind, lc, msg) = element_error(card);
        assert!(matches!(kind, K::CameProfiles { .. }), "{card}: {msg}");
        assert_eq!(lc, (6, col), "{card}: {msg}");
    }
    for (card, col) in [
        (
            " 1 CAME 1 2 CAM SPLINE 3 0 0 1 0 1 0 FOLLOWER POINT K 1e6",
            34,
        ),
        (
            " 1 CAME 1 2 CAM SPLINE CLOSED 4 0 0 1 0 1 0 0 1 FOLLOWER POINT K 1e6",
            41,
        ),
        (
            " 1 CAME 1 2 CAM SPLINE CLOSED 3 0 0 1 0 0 0 FOLLOWER POINT K 1e6",
            41,
        ),
    ] {
        let (kind, lc, msg) = element_error(card);
        assert!(
            matches!(kind, K::SplinePointsCoincide { .. }),
            "{card}: {msg}"
        );
        assert_eq!(lc, (6, col), "{card}: {msg}");
    }
    // The same cards with distinct nodes and supported profiles are accepted.
    for card in [
        " 1 RIGID 1 2 3",
        " 1 CAME 1 2 CAM SPLINE CLOSED 4 0 0 1 0 1 1 0 0 FOLLOWER POINT K 1e6",
        " 1 CAME 1 2 CAM CIRCLE 1 FOLLOWER LINE K 1e6",
    ] {
        let src = format!("{NODES}ELEMENTS\n{card}\n{TAIL}");
        parse_deck(&src, "d.dat").unwrap_or_else(|e| panic!("{card}: {e}"));
    }
}

#[test]
fn a_non_utf8_byte_is_located_also_after_end() {
    let dir = tmp("utf8");
    for (name, bytes, lc) in [
        (
            "body",
            b"NODES\n 1 0 0 0\n 2 1\xff 0 0\nEND\n".to_vec(),
            (3, 5),
        ),
        (
            "after_end",
            b"NODES\n 1 0 0 0\nEND\n\xc3(\n".to_vec(),
            (4, 1),
        ),
    ] {
        let p = dir.join(format!("{name}.dat"));
        std::fs::write(&p, &bytes).expect("write");
        let e = load_deck(&p).expect_err("not UTF-8");
        assert!(matches!(e.errors()[0].kind, K::NotUtf8 { .. }));
        assert_eq!(e.line_col(0), Some(lc), "{name}");
        let o = Command::new(BIN)
            .arg(&p)
            .arg("--check")
            .output()
            .expect("runs");
        assert_eq!(o.status.code(), Some(2));
        assert!(
            text(&o).contains(&format!("{name}.dat:{}:{}", lc.0, lc.1)),
            "{}",
            text(&o)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn sweep_plan(dir: &Path, extra: &str) -> Output {
    let plan = dir.join("p.toml");
    std::fs::write(
        &plan,
        format!(
            "deck = {:?}\nout = {:?}\n[[parameter]]\nname = \"k\"\nvalues = [1e6]\n\
             [[quantity]]\nname = \"v\"\nnode = 2\ncolumn = \"vy\"\nstat = \"last\"\n{extra}",
            root().join("decks/bounce_sweep.dat").display().to_string(),
            dir.join("out").display().to_string()
        ),
    )
    .expect("write");
    Command::new(BIN)
        .args(["sweep", plan.to_str().expect("utf-8"), "-q"])
        .output()
        .expect("runs")
}

#[test]
fn sweep_refuses_unknown_names_and_reports_failed_cases() {
    let dir = tmp("sweepnames");
    for (extra, line) in [
        (
            "[[reference]]\nquantity = \"nope\"\nparameter = \"k\"\nlabel = \"r\"\npoints = [[1, 2]]\n",
            12,
        ),
        (
            "[[guide]]\nquantity = \"v\"\nparameter = \"E\"\nlabel = \"g\"\nexponent = 1\nthrough = [1, 2]\n",
            13,
        ),
    ] {
        let o = sweep_plan(&dir, extra);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{t}");
        assert!(t.contains(&format!("line {line}")), "{t}");
        assert!(!dir.join("out").exists());
    }
    // Every quantity missing (node 9 is not written): not a success.
    let plan_q = "[[quantity]]\nname = \"w\"\nnode = 9\ncolumn = \"vy\"\nstat = \"last\"\n";
    let o = sweep_plan(&dir, plan_q);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let _ = std::fs::remove_dir_all(&dir);
}

// ------------------------------------------------------------------------- issue 35 §1

/// A run's loops end within bounds the deck states: Newton within MAXIT ≤ 1000 iterations
/// per step, the step loop only while its time can still advance (END/MINSTEP ≤ 1e12, so
/// that `t + h` never rounds to `t`); and no real number beyond 1e100 (or a non-zero one
/// below 1e-100) enters the model. Each refusal is at its field.
#[test]
fn loop_bounds_and_magnitudes_are_refused_at_their_field() {
    let base = "TITLE t\nNODES\n 1 0 0 0\nELEMENTS\n 1 MASS 1 M 1\nANALYSIS DYNAMIC STEP 1e-3 END 2e-3\nEND\n";
    assert!(parse_deck(base, "d.dat").is_ok());
    for (from, to, says) in [
        ("END 2e-3", "END 2e-3 MAXIT 4294967295", "MAXIT"),
        ("END 2e-3", "END 2e-3 MAXIT 1001", "MAXIT"),
        ("END 2e-3", "END 1e10", "END/MINSTEP"),
        ("END 2e-3", "END 1 MINSTEP 1e-13", "END/MINSTEP"),
        ("M 1", "M 1e-101", "1e-100 to 1e100"),
        ("M 1", "M 1e101", "1e-100 to 1e100"),
        ("1 0 0 0", "1 0 1e308 0", "1e-100 to 1e100"),
        ("M 1", "M 2^400", "1e-100 to 1e100"),
    ] {
        let src = base.replace(from, to);
        let (kind, (line, _), msg) = first_error(&src);
        assert!(matches!(kind, K::OutOfRange { .. }), "`{to}`: {msg}");
        assert!(msg.contains(says), "`{to}`: {msg}");
        let want = src.lines().position(|l| l.contains(to)).unwrap() + 1;
        assert_eq!(line, want, "`{to}`: {msg}");
    }
    // At the bounds: accepted.
    for (from, to) in [
        ("END 2e-3", "END 2e-3 MAXIT 1000"),
        ("M 1", "M 1e100"),
        ("M 1", "M 1e-100"),
        ("END 2e-3", "END 1 MINSTEP 1e-12"),
    ] {
        parse_deck(&base.replace(from, to), "d.dat").unwrap_or_else(|e| panic!("`{to}`: {e}"));
    }
}
