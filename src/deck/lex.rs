//! Lexing: source text → logical lines of tokens with byte spans (nom 8).
//!
//! * Separators are whitespace and commas.
//! * `!` or `#` starts a comment that runs to the end of the physical line.
//! * A physical line whose last token is `&` continues on the next one; the `&` is dropped
//!   and the two lines form one logical line.
//! * A token is a maximal run of other characters; blanks and commas inside parentheses do
//!   not end it, so that `(2 * $zeta)` is one field (an expression, `expr.rs`). It is a
//!   *number* when the whole token
//!   matches `[+-]? (digits ['.' digits?] | '.' digits) ([eE] [+-]? digits)?`, otherwise a
//!   *word* (keywords, malformed numbers such as `2.1e`, stray text — the builder decides).
//!
//! The lexer never fails: every byte sequence gives a list of tokens.

use crate::model::Span;
use nom::{
    IResult, Parser,
    branch::alt,
    bytes::complete::take_while,
    character::complete::{char, digit0, digit1, one_of},
    combinator::{opt, value},
};

/// One token of the deck with its place in the source.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Token<'a> {
    /// The token's text, exactly as written.
    pub text: &'a str,
    /// Byte range in the source.
    pub span: Span,
    /// The value when the token is lexically a number (may be infinite for `1e999`), or
    /// the value of the expression it holds once parameters are resolved (`params.rs`).
    pub number: Option<f64>,
    /// Why the expression this token holds could not be evaluated (`params.rs`); reported
    /// when a numeric field reads the token.
    pub bad_expr: Option<Box<super::error::DeckError>>,
}

impl Token<'_> {
    /// Whether this token is the keyword `kw` (case-insensitive).
    pub fn is_kw(&self, kw: &str) -> bool {
        super::debug_check_keyword(kw);
        self.number.is_none() && self.text.eq_ignore_ascii_case(kw)
    }
}

/// A logical line: its tokens (never empty).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Line<'a> {
    /// Tokens in order, continuation marks removed.
    pub tokens: Vec<Token<'a>>,
}

fn is_sep(c: char) -> bool {
    c.is_whitespace() || c == ','
}

/// Checks the syntax of a number and returns what follows it. (Only the remainder's
/// length is used: `recognize` relies on pointer offsets, which nom 8's `digit0` does not
/// keep at the very end of the input.)
fn number_syntax(input: &str) -> IResult<&str, ()> {
    value(
        (),
        (
            opt(one_of("+-")),
            alt((
                value((), (digit1, opt((char('.'), digit0)))),
                value((), (char('.'), digit1)),
            )),
            opt((one_of("eE"), opt(one_of("+-")), digit1)),
        ),
    )
    .parse(input)
}

/// The value of `text` when the whole text is a number (`1e-3`, `2.1E11`, `-.5`, `+3`, `5.`).
/// Returns `None` for anything else (`2.1e`, `abc`, `1.2.3`, `inf`, `nan`). The value may be
/// infinite when the exponent is too large; callers check finiteness.
pub(crate) fn parse_number(text: &str) -> Option<f64> {
    let (rest, ()) = number_syntax(text).ok()?;
    if !rest.is_empty() {
        return None;
    }
    text.parse::<f64>().ok()
}

/// One token, skipping leading separators; `None` at a comment or at the end of the line.
fn next_token(input: &str) -> IResult<&str, Option<&str>> {
    let (input, _) = take_while(is_sep).parse(input)?;
    if input.is_empty() || input.starts_with('!') || input.starts_with('#') {
        return Ok((input, None));
    }
    // A maximal run of non-separators; inside parentheses only a comment ends it.
    let mut depth = 0usize;
    let mut end = input.len();
    for (i, c) in input.char_indices() {
        match c {
            '!' | '#' => {
                end = i;
                break;
            }
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            c if depth == 0 && is_sep(c) => {
                end = i;
                break;
            }
            _ => {}
        }
    }
    let tok = &input[..end];
    // Trailing blanks of an unclosed parenthesis are not part of the token.
    let tok = tok.trim_end_matches(is_sep);
    let rest = &input[tok.len()..];
    Ok((rest, Some(tok)))
}

/// Tokens of one physical line starting at byte `offset` of the source.
fn line_tokens(line: &str, offset: usize) -> Vec<Token<'_>> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Ok((r, Some(tok))) = next_token(rest) {
        let start = offset + (line.len() - r.len()) - tok.len();
        out.push(Token {
            text: tok,
            span: Span::new(start, start + tok.len()),
            number: parse_number(tok),
            bad_expr: None,
        });
        rest = r;
    }
    out
}

/// Splits the source into logical lines of tokens (blank and comment-only lines dropped).
pub(crate) fn lex(source: &str) -> Vec<Line<'_>> {
    let mut lines = Vec::new();
    let mut pending: Vec<Token<'_>> = Vec::new();
    let mut offset = 0;
    for phys in source.split('\n') {
        let mut toks = line_tokens(phys, offset);
        offset += phys.len() + 1;
        let continues = toks.last().is_some_and(|t| t.text == "&");
        if continues {
            toks.pop();
        }
        pending.extend(toks);
        if !continues && !pending.is_empty() {
            lines.push(Line {
                tokens: std::mem::take(&mut pending),
            });
        }
    }
    if !pending.is_empty() {
        lines.push(Line { tokens: pending });
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers() {
        assert_eq!(parse_number("1e-3"), Some(1e-3));
        assert_eq!(parse_number("2.1E11"), Some(2.1e11));
        assert_eq!(parse_number("-.5"), Some(-0.5));
        assert_eq!(parse_number("+3"), Some(3.0));
        assert_eq!(parse_number("5."), Some(5.0));
        assert_eq!(parse_number("0.1"), Some(0.1));
        assert_eq!(parse_number("0.8333333333333334"), Some(0.8333333333333334));
        assert_eq!(parse_number("12.25"), Some(12.25));
        assert_eq!(parse_number("1.5e3"), Some(1500.0));
        assert_eq!(parse_number("7800"), Some(7800.0));
        assert_eq!(parse_number("1.8660254037844386"), Some(1.8660254037844386));
        assert_eq!(parse_number("-1E+2"), Some(-100.0));
        assert!(parse_number("1e999").is_some_and(|v| v.is_infinite()));
    }

    #[test]
    fn not_numbers() {
        for t in [
            "2.1e", "abc", "1.2.3", ".", "-", "+", "e5", "inf", "nan", "1e+", "--1", "1-", "0x10",
            "", "1,5",
        ] {
            assert_eq!(parse_number(t), None, "{t:?}");
        }
    }

    #[test]
    fn tokens_comments_continuation() {
        let src = "NODES ! comment\n 1 0,0 0 # c\n2 1 &\n 0 0\n\n&\n";
        let lines = lex(src);
        let texts: Vec<Vec<&str>> = lines
            .iter()
            .map(|l| l.tokens.iter().map(|t| t.text).collect())
            .collect();
        assert_eq!(
            texts,
            vec![
                vec!["NODES"],
                vec!["1", "0", "0", "0"],
                vec!["2", "1", "0", "0"],
            ]
        );
        let t = &lines[1].tokens[2];
        assert_eq!(&src[t.span.start..t.span.end], "0");
        assert_eq!(t.span.start, 21);
    }

    #[test]
    fn blanks_inside_parentheses_stay_in_the_field() {
        let src = "C (2 * $z, 3) 4 (1 ! c\nX (a)(b c) d";
        let lines = lex(src);
        let texts: Vec<Vec<&str>> = lines
            .iter()
            .map(|l| l.tokens.iter().map(|t| t.text).collect())
            .collect();
        assert_eq!(
            texts,
            vec![
                vec!["C", "(2 * $z, 3)", "4", "(1"],
                vec!["X", "(a)(b c)", "d"]
            ]
        );
        let t = &lines[0].tokens[1];
        assert_eq!(&src[t.span.start..t.span.end], "(2 * $z, 3)");
    }

    #[test]
    fn crlf_and_unicode() {
        let lines = lex("TITLE é ü\r\n1 2\r\n");
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].tokens[1].text, "é");
        assert_eq!(lines[1].tokens[1].number, Some(2.0));
    }
}
