//! All the errors of one deck ([`DeckErrors`]), with the deck's text, rendered like a
//! compiler diagnostic by miette; and the line and column of a byte offset.

use super::DeckError;
use miette::{Diagnostic, LabeledSpan, NamedSource, SourceCode};
use std::fmt;

/// Every error found in one deck (never empty), with the deck's text and file name so that
/// miette can render them: the first error is the main diagnostic, the others are
/// [`Diagnostic::related`].
#[derive(Debug)]
pub struct DeckErrors {
    source: NamedSource<String>,
    errors: Vec<DeckError>,
}

impl DeckErrors {
    /// Wraps `errors` (sorted by position, file errors first) with the deck's text.
    pub fn new(source: &str, file_name: &str, mut errors: Vec<DeckError>) -> Self {
        errors.iter_mut().for_each(|e| e.kind.shorten());
        errors.sort_by_key(|e| e.span.map(|s| (s.start, s.end)));
        DeckErrors {
            source: NamedSource::new(file_name, source.to_string()),
            errors,
        }
    }

    /// The errors, in source order.
    pub fn errors(&self) -> &[DeckError] {
        &self.errors
    }

    /// The deck's file name as given.
    pub fn file_name(&self) -> &str {
        self.source.name()
    }

    /// Line and column (1-based; the column counts characters) of error `i`, or `None` when
    /// it has no span or `i` is out of bounds.
    pub fn line_col(&self, i: usize) -> Option<(usize, usize)> {
        let span = self.errors.get(i)?.span?;
        Some(line_col(self.source.inner(), span.start))
    }
}

/// 1-based line and column (in characters) of byte `offset` of `text`.
pub(crate) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |p| p + 1);
    let col = before[line_start..].chars().count() + 1;
    (line, col)
}

impl fmt::Display for DeckErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.errors.first() {
            Some(e) => e.fmt(f),
            None => write!(f, "invalid deck"),
        }
    }
}

impl std::error::Error for DeckErrors {}

impl Diagnostic for DeckErrors {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new(
            self.errors.first().map_or("mecano::deck", DeckError::code),
        ))
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        let n = self.errors.len();
        (n > 1).then(|| {
            Box::new(format!(
                "{n} errors in `{}`; see grammar.md for the deck language",
                self.source.name()
            )) as Box<dyn fmt::Display>
        })
    }

    fn source_code(&self) -> Option<&dyn SourceCode> {
        Some(&self.source)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        self.errors.first().and_then(|e| {
            e.labeled_span()
                .map(|l| Box::new(std::iter::once(l)) as Box<dyn Iterator<Item = LabeledSpan>>)
        })
    }

    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn Diagnostic> + 'a>> {
        if self.errors.len() < 2 {
            return None;
        }
        Some(Box::new(
            self.errors[1..].iter().map(|e| e as &dyn Diagnostic),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::line_col;

    #[test]
    fn line_col_counts_chars() {
        let t = "ab\nçd\nx";
        assert_eq!(line_col(t, 0), (1, 1));
        assert_eq!(line_col(t, 3), (2, 1));
        assert_eq!(line_col(t, 5), (2, 2));
        assert_eq!(line_col(t, 7), (3, 1));
        assert_eq!(line_col(t, 100), (3, 2));
    }
}
