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
pub(crate) mod expr;
mod keywords;
mod lex;
pub mod limits;
mod params;
mod source;
mod write;

pub use error::{DeckError, DeckErrorKind, DeckErrors, ECHO_CHARS, short};
pub(crate) use keywords::debug_check_keyword;
pub use keywords::{KEYWORDS, KeywordDoc};
pub use source::{PIPE_WAIT, read_source, read_text};
pub use write::write_deck;

use crate::model::{Model, Span};
use std::path::Path;

/// The element types of the registered kinds (`crate::kinds`: each read, written and
/// documented by its own card), in the registry's order.
pub fn registered_element_types() -> impl Iterator<Item = &'static str> {
    build::types()
}

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

/// The 1-based line and column (in characters) of the byte `offset` of `text`: where a
/// message that is not a [`DeckError`] points (`file:line:col`).
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    error::line_col(text, offset)
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

/// [`load_deck`] with parameter overrides (see [`parse_deck_with`]). The text is read by
/// [`read_source`]: a regular file or a pipe, at most the size limit plus one byte.
pub fn load_deck_with(path: &Path, overrides: &[(String, f64)]) -> Result<Model, DeckErrors> {
    let text = read_source(path)?;
    let mut model = parse_deck_with(&text, &path.display().to_string(), overrides)?;
    model.resolve_superelement_dirs(path.parent().unwrap_or(Path::new(".")));
    Ok(model)
}

/// Sets every span in `model` to `Span::default()` (to compare models read from different
/// texts).
pub fn strip_spans(model: &mut Model) {
    let zero = Span::default();
    model.modes_span = zero;
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
        match &mut e.kind {
            crate::model::ElementKind::Prescribed { drive, .. } => drive.span = zero,
            crate::model::ElementKind::Control(c) => {
                if let crate::model::control::ControlLaw::Expr(law) = &mut c.law {
                    law.field = zero;
                }
            }
            _ => {}
        }
    }
}
