//! The deck: text → raw cards (syntax) → [`crate::model::Model`] (meaning).
//!
//! The language is documented in `grammar.md`. Three layers:
//! 1. `lex` (nom): logical lines of tokens with byte spans (comments, `&` continuations,
//!    numbers such as `1e-3`, `2.1E11`, `-.5`);
//! 2. `cards`: tokens grouped into cards by section keyword;
//! 3. `build`: cards → [`Model`], references resolved, defaults applied, values checked.
//!
//! Every error of a deck is reported at once ([`DeckErrors`]), each with its span, and
//! [`parse_deck`] never panics. [`write_deck`] prints a model back in canonical form.

mod build;
mod cards;
mod error;
mod expr;
mod keywords;
mod lex;
pub mod limits;
mod params;
mod write;

pub use error::{DeckError, DeckErrorKind, DeckErrors, ECHO_CHARS, short};
pub(crate) use keywords::debug_check_keyword;
pub use keywords::{KEYWORDS, KeywordDoc};
pub use write::write_deck;

use crate::model::{Model, Span};
use std::path::Path;

/// Parses a deck's text into a validated model, or returns every error found.
/// `file_name` is only used in diagnostics. Never panics.
pub fn parse_deck(source: &str, file_name: &str) -> Result<Model, DeckErrors> {
    parse_deck_with(source, file_name, &[])
}

/// [`parse_deck`] with parameter overrides (`--set name=value`, a sweep's case): each
/// `(name, value)` replaces the value of the deck's parameter `name` (see `grammar.md`,
/// PARAMETERS); a name the deck does not define is an error.
pub fn parse_deck_with(
    source: &str,
    file_name: &str,
    overrides: &[(String, f64)],
) -> Result<Model, DeckErrors> {
    let too_large =
        |b: Box<limits::Broken>| DeckErrors::new(&source[..b.cut], file_name, vec![b.error]);
    limits::check_text(source, source.len()).map_err(too_large)?;
    let lines = lex::lex(source);
    limits::check_lines(source, &lines).map_err(too_large)?;
    let empty = lines.is_empty();
    let mut errors = Vec::new();
    let mut cards = cards::cards(lines, &mut errors);
    let parameters = params::resolve(source, &mut cards, overrides, &mut errors);
    build::build_model(source, &cards, errors, empty, parameters)
        .map_err(|errors| DeckErrors::new(source, file_name, errors))
}

/// Whether `name` is a valid parameter name (a letter or `_`, then letters, digits, `_`).
pub fn is_parameter_name(name: &str) -> bool {
    expr::is_name(name)
}

/// The value of `text` read as an expression of numbers (no parameters), e.g. the value
/// of `--set h=1e-4/2`; `None` when it is not a finite number or expression.
pub fn eval_constant(text: &str) -> Option<f64> {
    expr::eval(text, &|_| None).ok()
}

/// [`eval_constant`] with the reason when it is not a value: the 1-based character
/// column in `text` where the problem starts and what is wrong (echoing at most a short
/// prefix of `text`).
pub fn eval_constant_located(text: &str) -> Result<f64, (usize, String)> {
    expr::eval(text, &|_| None).map_err(|e| {
        let column = text[..e.at.min(text.len())].chars().count() + 1;
        let tok = lex::Token {
            text,
            span: Span::new(0, text.len()),
            number: None,
            bad_expr: None,
        };
        let mut err = params::expr_error(&tok, e);
        err.kind.shorten();
        (column, err.kind.to_string())
    })
}

/// Reads and parses a deck file. A missing or unreadable file, or one that is not UTF-8,
/// gives a [`DeckErrors`] with a single error without span.
pub fn load_deck(path: &Path) -> Result<Model, DeckErrors> {
    load_deck_with(path, &[])
}

/// [`load_deck`] with parameter overrides (see [`parse_deck_with`]).
pub fn load_deck_with(path: &Path, overrides: &[(String, f64)]) -> Result<Model, DeckErrors> {
    let name = path.display().to_string();
    let file_error = |kind| DeckErrors::new("", &name, vec![DeckError { kind, span: None }]);
    let io = |e: std::io::Error| {
        file_error(DeckErrorKind::Io {
            path: name.clone(),
            reason: e.to_string(),
        })
    };
    // At most one byte past the limit is read: a larger file is refused, not loaded.
    let mut bytes = Vec::new();
    let file = std::fs::File::open(path).map_err(io)?;
    std::io::Read::read_to_end(
        &mut std::io::Read::take(file, limits::MAX_DECK_BYTES as u64 + 1),
        &mut bytes,
    )
    .map_err(io)?;
    let total = bytes.len();
    match String::from_utf8(bytes) {
        Ok(text) if total <= limits::MAX_DECK_BYTES => parse_deck_with(&text, &name, overrides),
        Ok(text) => Err(limits::check_text(&text, total).err().map_or_else(
            || file_error(DeckErrorKind::EmptyDeck),
            |b| DeckErrors::new(&text[..b.cut], &name, vec![b.error]),
        )),
        Err(e) => {
            // Located at the first invalid byte: the text before it is the source of the
            // diagnostic (its lines are checked first, so the snippet stays short).
            let offset = e.utf8_error().valid_up_to();
            let valid = &e.as_bytes()[..offset];
            let text = std::str::from_utf8(valid).unwrap_or_default();
            // A file cut at the size limit may end inside a character: then it is too
            // large, not malformed.
            let cut_inside = total > limits::MAX_DECK_BYTES && offset + 4 > limits::MAX_DECK_BYTES;
            let checked = limits::check_text(text, if cut_inside { total } else { offset });
            let error = checked.err().unwrap_or_else(|| {
                Box::new(limits::Broken {
                    error: DeckError::new(
                        DeckErrorKind::NotUtf8 {
                            path: name.clone(),
                            offset,
                        },
                        Span::new(offset, offset),
                    ),
                    cut: offset,
                })
            });
            Err(DeckErrors::new(
                &text[..error.cut],
                &name,
                vec![error.error],
            ))
        }
    }
}

/// Sets every span in `model` to `Span::default()` (to compare models read from different
/// texts).
pub fn strip_spans(model: &mut Model) {
    let zero = Span::default();
    model.nodes.values_mut().for_each(|x| x.span = zero);
    model.materials.values_mut().for_each(|x| x.span = zero);
    model.sections.values_mut().for_each(|x| x.span = zero);
    for f in model.functions.values_mut() {
        f.span = zero;
        if let crate::model::Function::Expr(e) = &mut f.function {
            e.field = zero;
        }
    }
    model.elements.values_mut().for_each(|x| x.span = zero);
    model.loads.iter_mut().for_each(|x| x.span = zero);
    model.initial.iter_mut().for_each(|x| x.span = zero);
    model.drives.values_mut().for_each(|x| x.span = zero);
    for e in model.elements.values_mut() {
        if let crate::model::ElementKind::Prescribed { drive, .. } = &mut e.kind {
            drive.span = zero;
        }
    }
}
