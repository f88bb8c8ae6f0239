//! What a deck may hold (grammar.md, "Limits"): checked before the deck is lexed further,
//! so that reading any input stays linear in time and memory and no message or snippet
//! echoes an unbounded part of it (issue 28 §4: a 50 MB field took 40 s and 689 MB).
//!
//! A limit broken is one located error; the source handed to the diagnostic is cut at
//! that place, so the snippet shows at most one line of [`MAX_LINE_BYTES`].

use super::error::{DeckError, DeckErrorKind};
use super::lex::Line;
use crate::model::Span;

/// Largest deck file, bytes (16 MiB: a model of some 300,000 nodes).
pub const MAX_DECK_BYTES: usize = 16 << 20;
/// Longest physical line, bytes (longer lists continue with `&`).
pub const MAX_LINE_BYTES: usize = 16 << 10;
/// Longest field (token), bytes: a number, a keyword or an expression.
pub const MAX_TOKEN_BYTES: usize = 1024;
/// Most fields in one card (logical line, continuations included): a TABLE of up to
/// 49,999 `t f` pairs, a SPLINE of up to 49,990 points.
pub const MAX_CARD_FIELDS: usize = 100_000;

/// Largest magnitude of a real number of a deck's fields (issue 35 §1). The solver forms
/// products of a few of them — a stiffness times a step squared over a mass, a coordinate
/// squared, a frequency times the end time, a load's squared norm — and each such product
/// of numbers within `[MIN_MAGNITUDE, MAX_MAGNITUDE]` stays within `[1e-300, 1e300]`, inside
/// double precision (`2.2e-308 … 1.8e308`): a value beyond it would overflow at run time
/// (1e308 in a coordinate, a stiffness, a load, a frequency), so it is refused as input,
/// located. No quantity of mechanics in SI units comes near either bound.
pub const MAX_MAGNITUDE: f64 = 1e100;
/// Smallest magnitude of a non-zero real number of a deck's fields ([`MAX_MAGNITUDE`]).
pub const MIN_MAGNITUDE: f64 = 1e-100;
/// The range [`magnitude_ok`] accepts, as error messages state it.
pub const MAGNITUDE_RANGE: &str = "0, or a magnitude from 1e-100 to 1e100 (products of a few deck numbers, e.g. a stiffness times a step squared, must stay within double precision)";

/// Whether `v` is 0 or of a magnitude within `[MIN_MAGNITUDE, MAX_MAGNITUDE]`.
pub fn magnitude_ok(v: f64) -> bool {
    v == 0.0 || (MIN_MAGNITUDE..=MAX_MAGNITUDE).contains(&v.abs())
}

/// A limit broken: the error and where to cut the source for its diagnostic.
pub(crate) struct Broken {
    /// The error (located).
    pub error: DeckError,
    /// The source's length to keep for the diagnostic.
    pub cut: usize,
}

fn floor_boundary(s: &str, mut i: usize) -> usize {
    i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn broken(
    what: &'static str,
    limit: usize,
    unit: &'static str,
    span: Span,
    cut: usize,
) -> Box<Broken> {
    Box::new(Broken {
        error: DeckError::new(DeckErrorKind::TooLarge { what, limit, unit }, span),
        cut,
    })
}

/// Checks the line lengths of `source` and its size; `total` is the size of the whole
/// file (larger than `source` when only its beginning was read). One pass over the
/// bytes, stopping at the first limit broken.
pub(crate) fn check_text(source: &str, total: usize) -> Result<(), Box<Broken>> {
    let mut start = 0;
    for line in source.split('\n') {
        if line.len() > MAX_LINE_BYTES {
            let at = floor_boundary(source, start + MAX_LINE_BYTES);
            return Err(broken(
                "a line",
                MAX_LINE_BYTES,
                "bytes",
                Span::new(at, at),
                at,
            ));
        }
        start += line.len() + 1;
    }
    if total > MAX_DECK_BYTES {
        let at = floor_boundary(source, MAX_DECK_BYTES);
        // Cut at the start of the line the limit falls in: the snippet shows the line
        // before it, whole.
        let cut = source[..at].rfind('\n').map_or(0, |p| p + 1);
        return Err(broken(
            "the deck",
            MAX_DECK_BYTES,
            "bytes",
            Span::new(cut, cut),
            cut,
        ));
    }
    Ok(())
}

/// Checks the fields of the lexed lines (their length and number per card).
pub(crate) fn check_lines(source: &str, lines: &[Line<'_>]) -> Result<(), Box<Broken>> {
    for line in lines {
        if let Some(t) = line.tokens.get(MAX_CARD_FIELDS) {
            let at = t.span.start;
            return Err(broken(
                "a card",
                MAX_CARD_FIELDS,
                "fields",
                Span::new(at, t.span.end),
                source.len(),
            ));
        }
        if let Some(t) = line.tokens.iter().find(|t| t.text.len() > MAX_TOKEN_BYTES) {
            let at = t.span.start;
            let end = at + t.text.chars().next().map_or(0, char::len_utf8);
            return Err(broken(
                "a field",
                MAX_TOKEN_BYTES,
                "bytes",
                Span::new(at, end),
                source.len(),
            ));
        }
    }
    Ok(())
}
