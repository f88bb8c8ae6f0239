//! Issue 28's corpus: thousands of generated and mutated decks, plans and expressions
//! from a seeded generator (reproducible: the seed and the case number are in every
//! failure message). For each input: no panic, no hang (each parse is timed), and an
//! error is located (every deck error with a span gives a line and a column, its message
//! is short); for the inputs built to be bad, an error is certain. Complements
//! `deck_props.rs` (lexer and builder properties) and `model_props.rs` (the solver's
//! system built from mutated decks).

use mecano::deck::{ECHO_CHARS, eval_constant_located, limits, parse_deck};
use mecano::sweep::plan::Plan;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};
use std::time::Instant;

const SEED: u64 = 28;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn files(dir: &str, ext: &str) -> Vec<(PathBuf, String)> {
    let mut v: Vec<(PathBuf, String)> = std::fs::read_dir(root().join(dir))
        .expect("dir")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .filter_map(|p| std::fs::read_to_string(&p).ok().map(|t| (p, t)))
        .collect();
    v.sort();
    v
}

/// Tokens a careless or hostile writer puts in a field.
fn hostile_token(rng: &mut ChaCha8Rng) -> String {
    const FIXED: &[&str] = &[
        "1e999",
        "-1e308",
        "nan",
        "inf",
        "$nope",
        "((((1",
        "sqrt(-1)",
        "1/0",
        "é",
        "\u{0}",
        "&",
        "!",
        "#",
        "TO",
        "END",
        "ALL",
        "0",
        "-0",
        "4294967296",
        "99999999999999999999",
        "--1",
        "CAME",
        "RIGID",
        "1 1",
        "$",
        "()",
        "2^2^2^2^2^2^2^2^2^2",
        "log(0)",
        "\u{FEFF}",
        "1,,2",
        "(1 2 3)",
        "1e-400",
        "+",
        "-",
        ".",
        "1.2.3",
        "0x10",
        "ΩΩ",
        "\r",
        "TABLE",
        "SPLINE 2",
    ];
    match rng.random_range(0..10) {
        0 => "9".repeat(rng.random_range(500..3000)),
        1 => {
            let n = rng.random_range(90..400);
            format!("{}1{}", "(".repeat(n), ")".repeat(n))
        }
        2 => vec!["1"; rng.random_range(90..300)].join("^"),
        3 => format!("{}1", "-".repeat(rng.random_range(90..900))),
        4 => (0..rng.random_range(1..6))
            .map(|_| char::from(rng.random_range(0x20u8..0x7f)))
            .collect(),
        _ => FIXED[rng.random_range(0..FIXED.len())].to_string(),
    }
}

/// One random edit of `text`.
fn mutate(text: &str, rng: &mut ChaCha8Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    if lines.is_empty() {
        return hostile_token(rng);
    }
    let l = rng.random_range(0..lines.len());
    match rng.random_range(0..8) {
        0..=2 => {
            // Replace, delete or duplicate one field.
            let mut toks: Vec<String> = lines[l].split(' ').map(str::to_string).collect();
            let t = rng.random_range(0..toks.len());
            match rng.random_range(0..3) {
                0 => toks[t] = hostile_token(rng),
                1 => {
                    toks.remove(t);
                }
                _ => {
                    let d = toks[t].clone();
                    toks.insert(t, d);
                }
            }
            lines[l] = toks.join(" ");
        }
        3 => {
            let m = rng.random_range(0..lines.len());
            lines.swap(l, m);
        }
        4 => {
            let d = lines[l].clone();
            lines.insert(l, d);
        }
        5 => {
            lines.remove(l);
        }
        6 => {
            // Truncate the text at a random character.
            let joined = lines.join("\n");
            let mut cut = rng.random_range(0..=joined.len());
            while !joined.is_char_boundary(cut) {
                cut -= 1;
            }
            return joined[..cut].to_string();
        }
        _ => {
            let at = rng.random_range(0..=lines[l].len());
            if lines[l].is_char_boundary(at) {
                lines[l].insert_str(at, &hostile_token(rng));
            }
        }
    }
    lines.join("\n")
}

/// Parses `src`; checks the error (when there is one) is located and short, and the
/// parse took no longer than a second. Returns whether it was an error.
fn check_deck(src: &str, what: &str) -> bool {
    let t0 = Instant::now();
    let r = std::panic::catch_unwind(|| parse_deck(src, "corpus.dat"));
    let dt = t0.elapsed().as_secs_f64();
    let Ok(r) = r else {
        panic!("{what}: the parser panicked on:\n{src:.3000}");
    };
    // A parse of a deck this small takes milliseconds; a second means a hang or worse.
    assert!(dt < 1.0, "{what}: {dt} s");
    match r {
        Ok(_) => false,
        Err(e) => {
            for (i, err) in e.errors().iter().enumerate() {
                assert!(
                    err.span.is_some() && e.line_col(i).is_some(),
                    "{what}: error without a location: {err}"
                );
                // Echoes are cut to ECHO_CHARS characters; the rest of a message is ours.
                let msg = err.to_string();
                assert!(
                    msg.chars().count() < 8 * ECHO_CHARS + 600,
                    "{what}: a long message ({} chars): {msg:.300}",
                    msg.len()
                );
            }
            true
        }
    }
}

#[test]
fn mutated_decks_never_panic_and_their_errors_are_located() {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let decks = files("decks", "dat");
    assert!(decks.len() > 20);
    let (mut n, mut bad) = (0, 0);
    let t0 = Instant::now();
    for (path, text) in &decks {
        for k in 0..60 {
            let mut src = text.clone();
            for _ in 0..rng.random_range(1..4) {
                src = mutate(&src, &mut rng);
            }
            let what = format!("seed {SEED}, {} mutation {k}", path.display());
            bad += usize::from(check_deck(&src, &what));
            n += 1;
        }
    }
    println!(
        "{n} mutated decks, {bad} refused, {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    assert!(n >= 2000 && bad > n / 4, "{n} decks, {bad} refused");
}

#[test]
fn decks_known_to_be_bad_are_refused_with_a_location() {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED + 1);
    let decks = files("decks", "dat");
    let mut n = 0;
    for (path, text) in &decks {
        for k in 0..25 {
            let first_line = match k % 5 {
                // A card before any section: always an error, whatever follows.
                0 => format!("ZZZ{} 1 2", rng.random_range(0..1000)),
                // A deep expression in a parameter.
                1 => {
                    let d = rng.random_range(101..500);
                    format!("PARAMETERS\n q {}1{}", "(".repeat(d), ")".repeat(d))
                }
                // A field beyond the field limit.
                2 => format!(
                    "TITLE x\nNODES\n 1 {}",
                    "7".repeat(limits::MAX_TOKEN_BYTES + 1)
                ),
                // A line beyond the line limit.
                3 => format!("! {}", "c".repeat(limits::MAX_LINE_BYTES)),
                // A joint on one node.
                _ => {
                    let node = rng.random_range(1..100);
                    format!("NODES\n {node} 0 0 0\nELEMENTS\n 9999 SPHERICAL {node} {node}")
                }
            };
            let src = format!("{first_line}\n{}", mutate(text, &mut rng));
            let what = format!("seed {}, {} bad deck {k}", SEED + 1, path.display());
            assert!(check_deck(&src, &what), "{what}: accepted:\n{src:.500}");
            n += 1;
        }
    }
    assert!(n > 500);
}

#[test]
fn generated_expressions_never_panic_and_errors_have_a_column() {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED + 2);
    const PARTS: &[&str] = &[
        "1", "2.5", "1e3", "pi", "sqrt(", "sin(", "exp(", "log(", "abs(", "(", ")", "+", "-", "*",
        "/", "^", " ", "$a", ".", "e", "é", "1e308", "0",
    ];
    for k in 0..3000 {
        let n = rng.random_range(0..if k % 10 == 0 { 3000 } else { 30 });
        let s: String = (0..n)
            .map(|_| PARTS[rng.random_range(0..PARTS.len())])
            .collect();
        let t0 = Instant::now();
        let r = std::panic::catch_unwind(|| eval_constant_located(&s));
        let Ok(r) = r else {
            panic!("seed {}, expression {k} panicked: {s:.300}", SEED + 2);
        };
        assert!(t0.elapsed().as_secs_f64() < 1.0, "expression {k}");
        match r {
            Ok(v) => assert!(v.is_finite()),
            Err((col, msg)) => {
                assert!(col >= 1 && col <= s.chars().count() + 1, "{k}: {col}");
                assert!(
                    msg.chars().count() < 8 * ECHO_CHARS + 300,
                    "{k}: {msg:.300}"
                );
            }
        }
    }
}

#[test]
fn mutated_plans_never_panic() {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED + 3);
    let plans = files("sweeps", "toml");
    assert!(!plans.is_empty());
    let mut n = 0;
    for (path, text) in &plans {
        for k in 0..150 {
            let src = mutate(text, &mut rng);
            let t0 = Instant::now();
            let p: &Path = path;
            let r = std::panic::catch_unwind(|| {
                Plan::parse(&src, p, Some(Path::new("/nonexistent/out")))
            });
            assert!(
                r.is_ok(),
                "{} mutation {k} panicked:\n{src:.2000}",
                path.display()
            );
            assert!(
                t0.elapsed().as_secs_f64() < 2.0,
                "{} mutation {k}",
                path.display()
            );
            n += 1;
        }
        // Known bad: a reference to an unknown quantity, deep nesting.
        for bad in [
            format!(
                "{text}\n[[reference]]\nquantity = \"zz_none\"\nparameter = \"x\"\nlabel = \"r\"\npoints = [[1, 2]]\n"
            ),
            format!("{text}\nzz = {}{}\n", "[".repeat(5000), "]".repeat(5000)),
        ] {
            let r = Plan::parse(&bad, path, Some(Path::new("/nonexistent/out")));
            let e = r.expect_err("a bad plan").to_string();
            assert!(e.contains("line"), "{}: {e:.300}", path.display());
        }
    }
    assert!(n >= 500);
}
