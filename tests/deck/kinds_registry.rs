//! The registry of element kinds (`src/kinds.rs`, issue 38 §0): every registered kind has
//! both halves (its deck card and its element builder), is documented in `grammar.md`, and
//! is used by a deck of `decks/` that reads, prints back and reads again to the same model
//! (`deck_roundtrip`'s check, made here per kind so that a kind without a deck fails).

use mecano::deck::{load_deck, parse_deck, registered_element_types, strip_spans, write_deck};
use mecano::elements::registry::{KINDS, kind};
use std::path::PathBuf;

fn decks() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("decks");
    let mut v: Vec<PathBuf> = [
        dir.clone(),
        dir.join("benchmarks"),
        dir.join("superelement"),
    ]
    .iter()
    .filter_map(|d| std::fs::read_dir(d).ok())
    .flatten()
    .filter_map(|e| e.ok().map(|e| e.path()))
    .filter(|p| p.extension().is_some_and(|x| x == "dat"))
    .collect();
    v.sort();
    v
}

/// Kinds no deck of `decks/` uses, in a deck of their own.
const EXTRA: &str = "TITLE kinds no deck of decks/ uses
NODES
  1 0 0 0 FIX ALL
  2 1 0 0
ELEMENTS
  1 MASS 2 M 1
  2 CLAMP 1 2
ANALYSIS DYNAMIC STEP 0.01 END 0.1
END
";

#[test]
fn every_registered_kind_has_both_halves() {
    let deck: Vec<&str> = registered_element_types().collect();
    assert!(
        deck.len() >= 4,
        "the registry lists the migrated kinds: {deck:?}"
    );
    for ty in &deck {
        assert!(kind(ty).is_some(), "{ty}: a card but no element builder");
    }
    for k in KINDS.iter() {
        for ty in k.types {
            assert!(deck.contains(ty), "{ty}: an element builder but no card");
        }
    }
}

#[test]
fn every_registered_kind_is_documented() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("grammar.md");
    let text = std::fs::read_to_string(path).expect("grammar.md");
    let reference = &text[text.find("## Keyword reference").expect("a reference")..];
    for ty in registered_element_types() {
        assert!(
            reference.contains(&format!("| `{ty}` |")),
            "{ty} has no row in grammar.md's keyword reference"
        );
        assert!(
            mecano::deck::KEYWORDS.iter().any(|k| k.name == ty),
            "{ty} is not in KEYWORDS"
        );
    }
}

#[test]
fn every_registered_kind_round_trips_through_the_writer() {
    let models: Vec<(PathBuf, mecano::model::Model)> = decks()
        .into_iter()
        .filter_map(|p| load_deck(&p).ok().map(|m| (p, m)))
        .chain([(
            PathBuf::from("EXTRA"),
            parse_deck(EXTRA, "EXTRA").expect("parses"),
        )])
        .collect();
    for ty in registered_element_types() {
        let using: Vec<_> = models
            .iter()
            .filter(|(_, m)| m.elements.values().any(|e| e.kind.keyword() == ty))
            .collect();
        assert!(!using.is_empty(), "{ty}: no deck of decks/ uses it");
        for (path, m) in using {
            let text = write_deck(m);
            let mut second = parse_deck(&text, "written")
                .unwrap_or_else(|e| panic!("{}: {:?}", path.display(), miette::Report::new(e)));
            let mut first = m.clone();
            strip_spans(&mut first);
            strip_spans(&mut second);
            assert_eq!(
                first,
                second,
                "{ty}, {}: round trip differs",
                path.display()
            );
            assert_eq!(write_deck(&second), text, "{ty}, {}", path.display());
        }
    }
}

#[test]
fn an_unknown_element_type_lists_every_registered_type() {
    let deck = "TITLE a typo\nNODES\n  1 0 0 0\n  2 1 0 0\nELEMENTS\n  1 BEEM 1 2 SEC 1\n\
                ANALYSIS DYNAMIC STEP 0.01 END 0.1\nEND\n";
    let e = parse_deck(deck, "typo.dat").expect_err("BEEM is no element type");
    let msg = e.to_string();
    assert!(msg.contains("`BEEM`"), "{msg}");
    for ty in registered_element_types().chain(["BEAM"]) {
        assert!(
            msg.split(|c: char| !c.is_ascii_alphanumeric())
                .any(|w| w == ty),
            "{ty} missing from: {msg}"
        );
    }
}
