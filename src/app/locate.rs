//! Places in a deck for the command line's messages: `file:line:col` of a span, and a
//! solver build error with the place of the card at fault.

use crate::{deck, solver};
use std::path::Path;

/// `path:line:col` of the byte `span.start` of the deck text `text` read from `path`.
pub fn locate(path: &Path, text: &str, span: crate::model::Span) -> String {
    let (line, col) = deck::line_col(text, span.start);
    format!("{}:{line}:{col}", path.display())
}

/// `file:line:col` of a byte offset of the deck at `path` (its text read again), or the
/// path alone when the deck cannot be read again (a pipe is not: it was read once).
fn locate_offset(path: &Path, offset: usize) -> String {
    let regular = std::fs::metadata(path).is_ok_and(|m| m.is_file());
    match deck::read_text(path).ok().filter(|_| regular) {
        Some(text) => locate(path, &text, crate::model::Span::new(offset, offset)),
        None => path.display().to_string(),
    }
}

/// A build error of the solver with its place in the deck where it has one (nodes whose
/// motion is undetermined point at their NODES card).
pub fn located_build_error(path: &Path, e: &solver::BuildError) -> String {
    match e {
        solver::BuildError::Undetermined(nodes) => nodes
            .iter()
            .map(|n| format!("{}: {n}", locate_offset(path, n.span.start)))
            .collect::<Vec<_>>()
            .join("\nerror: "),
        other => format!("{}: {other}", path.display()),
    }
}

/// [`located_build_error`], an element's own error (a `SUPERELEMENT`'s files, a beam's
/// data) placed at its card in `model`'s deck.
pub fn located_model_error(
    path: &Path,
    model: &crate::model::Model,
    e: &solver::BuildError,
) -> String {
    use crate::elements::BuildError as E;
    match e {
        solver::BuildError::Elements(E::Invalid { element, .. }) => {
            match model.elements.get(element) {
                Some(el) => format!("{}: {e}", locate_offset(path, el.span.start)),
                None => located_build_error(path, e),
            }
        }
        _ => located_build_error(path, e),
    }
}
