//! Stage 2 helpers: a cursor over a card's tokens and the small checks every card shares.

use super::*;

/// A read-only walk over the tokens of one card.
pub(super) struct Cursor<'t, 'a> {
    pub(super) toks: &'t [Token<'a>],
    pub(super) pos: usize,
    pub(super) ctx: String,
}

impl<'t, 'a> Cursor<'t, 'a> {
    pub(super) fn new(card: &'t Card<'a>, ctx: impl Into<String>) -> Self {
        Cursor {
            toks: &card.tokens,
            pos: 0,
            ctx: ctx.into(),
        }
    }

    pub(super) fn peek(&self) -> Option<&'t Token<'a>> {
        self.toks.get(self.pos)
    }

    /// An empty span just after the card's last token.
    pub(super) fn end_span(&self) -> Span {
        let e = self.toks.last().map_or(0, |t| t.span.end);
        Span::new(e, e)
    }

    pub(super) fn missing(&self, what: &str) -> DeckError {
        DeckError::new(
            K::MissingField {
                expected: format!("{what} in {}", self.ctx),
            },
            self.end_span(),
        )
    }

    pub(super) fn next(&mut self, what: &str) -> R<&'t Token<'a>> {
        let t = self.toks.get(self.pos).ok_or_else(|| self.missing(what))?;
        self.pos += 1;
        Ok(t)
    }

    pub(super) fn skip(&mut self) {
        self.pos += 1;
    }

    /// A finite number: written as a number, or an expression of parameters (its value was
    /// computed by `params.rs`; an expression that failed reports its own error here).
    pub(super) fn number(&mut self, what: &str) -> R<(f64, Span, &'a str)> {
        let t = self.next(what)?;
        if let Some(e) = &t.bad_expr {
            return Err((**e).clone());
        }
        match t.number {
            Some(v) if v.is_finite() && !crate::deck::limits::magnitude_ok(v) => {
                let found = if super::super::expr::looks_like_expression(t.text) {
                    format!("{} = {v:?}", t.text)
                } else {
                    t.text.to_string()
                };
                Err(out_of_range(
                    what,
                    &found,
                    crate::deck::limits::MAGNITUDE_RANGE,
                    t.span,
                ))
            }
            Some(v) if v.is_finite() => Ok((v, t.span, t.text)),
            Some(_) => Err(DeckError::new(
                K::NonFinite {
                    expected: what.to_string(),
                    found: t.text.to_string(),
                },
                t.span,
            )),
            None => Err(DeckError::new(
                K::ExpectedNumber {
                    expected: what.to_string(),
                    found: t.text.to_string(),
                },
                t.span,
            )),
        }
    }

    /// A number, checked by `ok`, else an [`K::OutOfRange`] error stating `range`.
    pub(super) fn number_in(
        &mut self,
        what: &str,
        range: &str,
        ok: impl Fn(f64) -> bool,
    ) -> R<f64> {
        let (v, span, text) = self.number(what)?;
        if ok(v) {
            Ok(v)
        } else if super::super::expr::looks_like_expression(text) {
            Err(out_of_range(what, &format!("{text} = {v:?}"), range, span))
        } else {
            Err(out_of_range(what, text, range, span))
        }
    }

    /// A whole number in `0..=u32::MAX`, written as digits or as an expression of
    /// parameters whose value is a whole number in that range.
    pub(super) fn uint(&mut self, what: &str) -> R<(u32, Span)> {
        let t = self.next(what)?;
        if let Some(e) = &t.bad_expr {
            return Err((**e).clone());
        }
        let whole = |v: &f64| v.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(v);
        if let Some(v) = t
            .number
            .filter(|v| super::super::expr::looks_like_expression(t.text) && whole(v))
        {
            return Ok((v as u32, t.span));
        }
        let digits = t.text.strip_prefix('+').unwrap_or(t.text);
        let ok = !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit());
        match digits.parse::<u32>() {
            Ok(v) if ok => Ok((v, t.span)),
            _ => Err(DeckError::new(
                K::ExpectedInteger {
                    expected: what.to_string(),
                    found: t.text.to_string(),
                },
                t.span,
            )),
        }
    }

    /// Whether the next token is a number or an expression (also one that failed: reading
    /// it reports why).
    pub(super) fn next_is_number(&self) -> bool {
        self.peek()
            .is_some_and(|t| t.number.is_some() || t.bad_expr.is_some())
    }

    pub(super) fn vec3(&mut self, what: &str) -> R<(Vector3<f64>, Span, [&'a str; 3])> {
        let (x, s0, tx) = self.number(&format!("{what} x component"))?;
        let (y, _, ty) = self.number(&format!("{what} y component"))?;
        let (z, s1, tz) = self.number(&format!("{what} z component"))?;
        Ok((
            Vector3::new(x, y, z),
            Span::new(s0.start, s1.end),
            [tx, ty, tz],
        ))
    }

    /// A direction: a non-zero finite vector, normalised.
    pub(super) fn axis(&mut self, what: &str) -> R<(Vector3<f64>, Vector3<f64>, Span)> {
        let (v, span, t) = self.vec3(what)?;
        match unit(v) {
            Some(u) => Ok((u, v, span)),
            None => Err(DeckError::new(
                K::BadAxis {
                    what: what.to_string(),
                    x: t[0].into(),
                    y: t[1].into(),
                    z: t[2].into(),
                },
                span,
            )),
        }
    }

    /// If the next token is one of `kws`, consumes it and returns the canonical keyword.
    pub(super) fn keyword(&mut self, kws: &[&'static str]) -> Option<(&'static str, Span)> {
        let t = self.peek()?;
        let k = kws.iter().find(|k| t.is_kw(k))?;
        self.pos += 1;
        Some((k, t.span))
    }

    /// The next token must be one of `kws`.
    pub(super) fn expect_keyword(
        &mut self,
        kws: &[&'static str],
        what: &str,
    ) -> R<(&'static str, Span)> {
        if let Some(k) = self.keyword(kws) {
            return Ok(k);
        }
        let t = self.next(what)?;
        Err(self.unexpected(t, what))
    }

    pub(super) fn unexpected(&self, t: &Token<'_>, expected: &str) -> DeckError {
        DeckError::new(
            K::UnknownKeyword {
                found: t.text.to_string(),
                context: self.ctx.clone(),
                expected: expected.to_string(),
            },
            t.span,
        )
    }

    /// No tokens may remain.
    pub(super) fn finish(&self) -> R<()> {
        match self.peek() {
            None => Ok(()),
            Some(t) => Err(DeckError::new(
                K::ExtraToken {
                    found: t.text.to_string(),
                    context: self.ctx.clone(),
                },
                t.span,
            )),
        }
    }
}

/// Most items one `a TO b` generation may produce: far beyond any model this solver can
/// run, and small enough that a typo (`2 TO 4294967295`) is an error, not an exhausted memory.
pub const MAX_GENERATION: u32 = 1_000_000;

pub(super) fn generation_size(first: u32, last: u32, span: Span) -> R<()> {
    if last - first >= MAX_GENERATION {
        return Err(DeckError::new(
            K::BadGeneration {
                first,
                last,
                reason: format!(
                    "{} items, more than the {MAX_GENERATION} one generation may produce",
                    u64::from(last - first) + 1
                ),
            },
            span,
        ));
    }
    Ok(())
}

pub(super) fn out_of_range(what: &str, text: &str, range: &str, span: Span) -> DeckError {
    DeckError::new(
        K::OutOfRange {
            field: what.to_string(),
            found: text.to_string(),
            range: range.to_string(),
        },
        span,
    )
}

/// Records keywords met in one card to reject repeats.
#[derive(Default)]
pub(super) struct Seen(pub(super) Vec<&'static str>);

impl Seen {
    pub(super) fn add(&mut self, kw: &'static str, span: Span, ctx: &str) -> R<()> {
        if self.0.contains(&kw) {
            return Err(DeckError::new(
                K::RepeatedKeyword {
                    keyword: kw.to_string(),
                    context: ctx.to_string(),
                },
                span,
            ));
        }
        self.0.push(kw);
        Ok(())
    }
    pub(super) fn has(&self, kw: &str) -> bool {
        self.0.contains(&kw)
    }
}

pub(super) fn expected_list(kws: &[&str]) -> String {
    format!("one of {}", kws.join(", "))
}
