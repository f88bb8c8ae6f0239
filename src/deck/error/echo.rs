//! How much of the deck's text an error message may echo: every echo cut to a bound, so
//! that no message grows with the input (issue 28).

use super::DeckErrorKind;

/// The most characters of a token an error message echoes (issue 28: a 50 MB field
/// was repeated whole in its message).
pub const ECHO_CHARS: usize = 40;

/// `s` cut to its first [`ECHO_CHARS`] characters, with `…` when something was cut.
pub fn short(s: &str) -> String {
    match s.char_indices().nth(ECHO_CHARS) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

impl DeckErrorKind {
    /// Cuts every echo of the deck's text to [`short`] (lists of names to a few times
    /// that), so that no message grows with the input.
    pub(crate) fn shorten(&mut self) {
        use DeckErrorKind as K;
        let cut = |s: &mut String| *s = short(s);
        let cut_list = |s: &mut String| {
            if let Some((i, _)) = s.char_indices().nth(8 * ECHO_CHARS) {
                s.truncate(i);
                s.push('…');
            }
        };
        match self {
            K::UnknownSection { found, .. }
            | K::CardOutsideSection { found, .. }
            | K::UnknownKeyword { found, .. }
            | K::UnknownElementType { found, .. }
            | K::ExpectedNumber { found, .. }
            | K::ExpectedInteger { found, .. }
            | K::NonFinite { found, .. }
            | K::ExtraToken { found, .. }
            | K::OutOfRange { found, .. }
            | K::BadParameterName { found } => cut(found),
            K::RepeatedKeyword { keyword, .. } => cut(keyword),
            K::BadAxis { x, y, z, .. } => [x, y, z].into_iter().for_each(cut),
            K::DecreasingTime { found, previous } => {
                cut(found);
                cut(previous);
            }
            K::BadExpression { text, .. } | K::ExpressionTooDeep { text, .. } => cut(text),
            K::FunctionNotFinite(f) => {
                cut(&mut f.text);
                cut(&mut f.part);
            }
            K::ExpressionNotFinite { text, what } => {
                cut(text);
                cut(what);
            }
            K::UnknownFunction { name, text } => {
                cut(name);
                cut(text);
            }
            K::UndefinedParameter { name, known } | K::UnknownOverride { name, known } => {
                cut(name);
                cut_list(known);
            }
            K::DuplicateParameter { name, .. } => cut(name),
            _ => {}
        }
    }
}
