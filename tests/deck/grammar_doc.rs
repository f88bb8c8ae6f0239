//! `grammar.md` documents every keyword the parser accepts, documents nothing the parser
//! does not accept, and its examples are valid decks.

use crate::common;

use mecano::deck::{KEYWORDS, parse_deck};
use std::collections::BTreeSet;

fn grammar() -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("grammar.md");
    std::fs::read_to_string(path).expect("grammar.md exists")
}

/// Contents of the `inline code` spans of `text` (fenced blocks excluded).
fn code_spans(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_fence = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_fence = !in_fence;
            continue;
        }
        if in_fence {
            continue;
        }
        let parts: Vec<&str> = line.split('`').collect();
        out.extend(parts.iter().skip(1).step_by(2).map(|s| s.to_string()));
    }
    out
}

fn is_keyword_like(w: &str) -> bool {
    let mut c = w.chars();
    c.next().is_some_and(|f| f.is_ascii_uppercase())
        && c.all(|ch| ch.is_ascii_uppercase() || ch.is_ascii_digit() || ch == '_')
}

#[test]
fn every_keyword_is_documented() {
    let spans: BTreeSet<String> = code_spans(&grammar()).into_iter().collect();
    let missing: Vec<&str> = KEYWORDS
        .iter()
        .map(|k| k.name)
        .filter(|name| !spans.contains(*name))
        .collect();
    assert!(
        missing.is_empty(),
        "keywords accepted by the parser but not documented in grammar.md (as `KEYWORD`): {missing:?}"
    );
}

#[test]
fn keywords_have_docs_and_known_sections() {
    let sections = [
        "deck",
        "MATERIALS",
        "SECTIONS",
        "NODES",
        "ELEMENTS",
        "FUNCTIONS",
        "LOADS",
        "INITIAL",
        "ANALYSIS",
        "OUTPUT",
    ];
    let mut seen = BTreeSet::new();
    for k in KEYWORDS.iter() {
        assert!(is_keyword_like(k.name), "{k:?}");
        assert!(!k.doc.is_empty(), "{k:?}");
        assert!(sections.contains(&k.section), "{k:?}");
        assert!(seen.insert(k.name), "keyword {} listed twice", k.name);
    }
}

#[test]
fn the_reference_documents_only_accepted_keywords() {
    let text = grammar();
    let start = text
        .find("## Keyword reference")
        .expect("a keyword reference section");
    let end = text[start..]
        .find("\n## Errors")
        .map_or(text.len(), |e| start + e);
    let known: BTreeSet<&str> = KEYWORDS.iter().map(|k| k.name).collect();
    let unknown: BTreeSet<String> = code_spans(&text[start..end])
        .iter()
        .flat_map(|s| s.split_whitespace().map(str::to_string).collect::<Vec<_>>())
        .filter(|w| is_keyword_like(w) && !known.contains(w.as_str()))
        .collect();
    assert!(
        unknown.is_empty(),
        "documented in grammar.md but not accepted by the parser: {unknown:?}"
    );
}

/// The example decks: the fenced blocks from `## Full example` on.
fn examples() -> Vec<String> {
    let text = grammar();
    let start = text
        .find("## Full example")
        .expect("a full example section");
    let mut blocks = Vec::new();
    let mut cur: Option<String> = None;
    for line in text[start..].lines() {
        if line.starts_with("```") {
            match cur.take() {
                Some(b) => blocks.push(b),
                None => cur = Some(String::new()),
            }
        } else if let Some(b) = cur.as_mut() {
            b.push_str(line);
            b.push('\n');
        }
    }
    blocks
}

#[test]
fn the_examples_parse() {
    let blocks = examples();
    assert!(blocks.len() >= 2, "expected the examples");
    for b in &blocks {
        if let Err(e) = parse_deck(b, "grammar.md example") {
            panic!("{:?}", miette::Report::new(e));
        }
    }
    // The first example is the scene of decks/pendulum.dat.
    let m = parse_deck(&blocks[0], "example").expect("parses");
    assert_eq!((m.nodes.len(), m.elements.len()), (24, 25));
}

/// Every example runs (not only parses): its model builds (no documented feature is
/// refused) and the analysis completes with finite states — a dynamic one cut to ten of
/// its steps to keep the test cheap, a static one in full.
#[test]
fn the_examples_run() {
    for (k, b) in examples().iter().enumerate() {
        let mut m = parse_deck(b, "grammar.md example").expect("parses");
        if let Some(n) = m.modes {
            modal_example_runs(k, b, n);
            continue;
        }
        if let mecano::model::Analysis::Dynamic { step, .. } = m.analysis {
            assert!(m.set_fixed_step(step, 10.0 * step, None));
        }
        let mut h = mecano::output::History::new(1);
        let report = mecano::solver::run(&m, &mut h)
            .unwrap_or_else(|e| panic!("example {k} does not start: {e:?}"));
        assert!(
            report.failure.is_none(),
            "example {k} failed: {:?}",
            report.failure
        );
        let last = h.nodes.last().expect("states recorded");
        assert!(
            last.iter()
                .all(|s| s.x.iter().chain(s.r.iter()).all(|v| v.is_finite())),
            "example {k}: non-finite state"
        );
    }
}

/// An `ANALYSIS MODES n` example: `mecano-rs DECK` performs the modal analysis and writes
/// `modes.csv` (a header and n rows of finite numbers) into the output directory, and
/// nothing else of a time run (no energy.csv).
fn modal_example_runs(k: usize, text: &str, n: u32) {
    let dir = common::TempDir::new(&format!("grammar_modes_{k}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let deck = dir.join("example.dat");
    std::fs::write(&deck, text).expect("deck written");
    let out = dir.join("out");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck)
        .arg("-q")
        .arg("-o")
        .arg(&out)
        .output()
        .expect("mecano-rs runs");
    assert_eq!(
        o.status.code(),
        Some(0),
        "example {k}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let csv = std::fs::read_to_string(out.join("modes.csv")).expect("modes.csv written");
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), n as usize, "example {k}: {csv}");
    assert!(
        rows.iter()
            .flat_map(|r| r.split(','))
            .all(|f| f.parse::<f64>().map_or(true, f64::is_finite)),
        "example {k}: {csv}"
    );
    assert!(out.join("summary.json").exists() && !out.join("energy.csv").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
