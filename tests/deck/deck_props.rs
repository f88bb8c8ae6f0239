//! Property tests: the parser never panics, whatever the input.

use mecano::deck::parse_deck;
use proptest::prelude::*;

const DECK: &str = include_str!("../../decks/pendulum.dat");

/// Words and fragments likely to reach deep into the parser.
const PIECES: &[&str] = &[
    "0",
    "1",
    "-1",
    "2",
    "24",
    "1e999",
    "-.5",
    "2.1e",
    "abc",
    "&",
    "!",
    "#",
    "\n",
    ",",
    " ",
    "TO",
    "LINE",
    "FIX",
    "ALL",
    "BEAM",
    "MASS",
    "HINGE",
    "UJOINT",
    "CAME",
    "RIGID",
    "SPLINE",
    "CLOSED",
    "CIRCLE",
    "PLANE",
    "ANGLE",
    "OFFSET",
    "MAT",
    "SEC",
    "AXIS",
    "AXIS2",
    "K",
    "END",
    "ANALYSIS",
    "STATIC",
    "DYNAMIC",
    "ADAPTIVE",
    "OUTPUT",
    "NODES",
    "ELEMENTS",
    "TABLE",
    "FUNCTION",
    "NONE",
    "4294967295",
    "4294967296",
    "é",
    "\u{0}",
    "\r",
];

/// Byte ranges of the whitespace-separated tokens of `s`.
fn token_ranges(s: &str) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    let mut start = None;
    for (i, c) in s.char_indices() {
        match (c.is_whitespace(), start) {
            (true, Some(st)) => {
                v.push((st, i));
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(st) = start {
        v.push((st, s.len()));
    }
    v
}

fn floor_char(s: &str, mut i: usize) -> usize {
    i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// Applies one edit: 0 delete a char, 1 insert a piece, 2 replace a char, 3 delete a token,
/// 4 replace a token, 5 duplicate a token.
fn mutate(s: &str, op: u8, at: usize, piece: &str) -> String {
    let toks = token_ranges(s);
    let mut out = s.to_string();
    match op % 6 {
        0 | 2 => {
            let i = floor_char(s, at % s.len().max(1));
            if let Some(c) = s[i..].chars().next() {
                let rep = if op % 6 == 2 { piece } else { "" };
                out.replace_range(i..i + c.len_utf8(), rep);
            }
        }
        1 => {
            let i = floor_char(s, at % (s.len() + 1));
            out.insert_str(i, piece);
        }
        _ => {
            if toks.is_empty() {
                return out;
            }
            let (a, b) = toks[at % toks.len()];
            match op % 6 {
                3 => out.replace_range(a..b, ""),
                4 => out.replace_range(a..b, piece),
                _ => {
                    let t = s[a..b].to_string();
                    out.insert_str(b, &format!(" {t}"));
                }
            }
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = parse_deck(&text, "random.dat");
    }

    #[test]
    fn random_keyword_soup_never_panics(idx in proptest::collection::vec(0usize..PIECES.len(), 0..60)) {
        let text: Vec<&str> = idx.iter().map(|i| PIECES[*i]).collect();
        let _ = parse_deck(&text.join(" "), "soup.dat");
    }

    #[test]
    fn mutated_pendulum_never_panics(
        edits in proptest::collection::vec((0u8..6, any::<usize>(), 0usize..PIECES.len()), 1..4)
    ) {
        let mut text = DECK.to_string();
        for (op, at, p) in edits {
            text = mutate(&text, op, at, PIECES[p]);
        }
        if let Err(e) = parse_deck(&text, "mutated.dat") {
            // Every reported error can be located and rendered.
            for i in 0..e.errors().len() {
                prop_assert!(e.line_col(i).is_some());
            }
            let _ = format!("{:?}", miette::Report::new(e));
        }
    }
}

#[test]
fn the_unmutated_deck_parses() {
    assert!(parse_deck(DECK, "pendulum.dat").is_ok());
}
