//! Stage 2, FUNCTIONS: `TABLE`, `CONSTANT`, `HAVERSINE`, `SPLINE`, `SINE`, `COSINE`,
//! `RAMP`, `EXPR` (grammar.md, "FUNCTIONS").

use super::cursor::*;
use super::*;
use crate::model::{CubicSpline, SplineError, TimeExpr};

const KINDS: [&str; 8] = [
    "TABLE",
    "CONSTANT",
    "HAVERSINE",
    "SPLINE",
    "SINE",
    "COSINE",
    "RAMP",
    "EXPR",
];

impl Builder<'_> {
    pub(super) fn function(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "FUNCTIONS card");
        let (id, id_span) = c.uint("function number")?;
        c.ctx = format!("function {id}");
        let (kw, _) = c.expect_keyword(&KINDS, &expected_list(&KINDS))?;
        let function = match kw {
            "CONSTANT" => {
                let (v, _, _) = c.number("the constant value")?;
                c.finish()?;
                Function::Constant(v)
            }
            "HAVERSINE" => {
                let (start, _, _) = c.number("the pulse's start time")?;
                let duration = c.number_in("the pulse's duration", "> 0 s", |v| v > 0.0)?;
                c.finish()?;
                Function::Haversine { start, duration }
            }
            "SPLINE" => spline(&mut c, span)?,
            "SINE" | "COSINE" => harmonic(&mut c, kw == "COSINE")?,
            "RAMP" => {
                let (t0, _, _) = c.number("the ramp's start time t0")?;
                let (f0, _, _) = c.number("the ramp's start value f0")?;
                let t1 = c.number_in("the ramp's end time t1", "> t0", |v| v > t0)?;
                let (f1, _, _) = c.number("the ramp's end value f1")?;
                c.finish()?;
                Function::Ramp { t0, f0, t1, f1 }
            }
            "EXPR" => {
                let tok = c.next("an expression of t")?;
                c.finish()?;
                let expr = super::super::params::time_expression(tok, &self.parameters)?;
                Function::Expr(TimeExpr {
                    text: tok.text.to_string(),
                    expr,
                })
            }
            _ => table(&mut c, span)?,
        };
        if let Some(first) = self.functions.get(&FunctionId(id)).map(|f| f.span) {
            self.duplicate("function", id, first, id_span);
            return Ok(());
        }
        self.functions.insert(
            FunctionId(id),
            FunctionDef {
                id: FunctionId(id),
                function,
                span,
            },
        );
        Ok(())
    }

    /// Every EXPR function finite, with its first two derivatives, over the analysis's
    /// span (`[0, END]`, or `[0, 1]` for the load steps of a static analysis), sampled at
    /// 1001 instants ([`Function::first_non_finite`]).
    pub(super) fn check_functions(&mut self, analysis: &Analysis) {
        let end = match analysis {
            Analysis::Dynamic { end, .. } => *end,
            Analysis::Static { .. } => 1.0,
        };
        for f in self.functions.values() {
            if let (Some(t), Function::Expr(e)) =
                (f.function.first_non_finite(0.0, end), &f.function)
            {
                self.errors.push(DeckError::new(
                    K::FunctionNotFinite {
                        id: f.id.0,
                        text: e.text.clone(),
                        t,
                        end,
                    },
                    f.span,
                ));
            }
        }
    }
}

/// The numbers up to the end of the card or the keyword `stop`, with their spans.
fn pairs(c: &mut Cursor<'_, '_>, stop: Option<&str>) -> R<Vec<(f64, Span, String)>> {
    let mut vals = Vec::new();
    while let Some(t) = c.peek() {
        if stop.is_some_and(|k| t.is_kw(k)) {
            break;
        }
        let (v, s, text) = c.number("a table value (t or f)")?;
        vals.push((v, s, text.to_string()));
    }
    Ok(vals)
}

fn table(c: &mut Cursor<'_, '_>, span: Span) -> R<Function> {
    let vals = pairs(c, None)?;
    if vals.is_empty() || vals.len() % 2 == 1 {
        return Err(DeckError::new(K::OddTable { count: vals.len() }, span));
    }
    for w in vals.chunks(2).collect::<Vec<_>>().windows(2) {
        let (prev, cur) = (&w[0][0], &w[1][0]);
        if cur.0 < prev.0 {
            return Err(DeckError::new(
                K::DecreasingTime {
                    found: cur.2.clone(),
                    previous: prev.2.clone(),
                },
                cur.1,
            ));
        }
    }
    Ok(Function::Table(
        vals.chunks(2).map(|p| (p[0].0, p[1].0)).collect(),
    ))
}

/// `SPLINE t1 f1 t2 f2 … [SLOPES s0 sn]`.
fn spline(c: &mut Cursor<'_, '_>, span: Span) -> R<Function> {
    let vals = pairs(c, Some("SLOPES"))?;
    let slopes = match c.keyword(&["SLOPES"]) {
        Some(_) => {
            let (s0, _, _) = c.number("the slope at the first point")?;
            let (sn, _, _) = c.number("the slope at the last point")?;
            c.finish()?;
            Some((s0, sn))
        }
        None => None,
    };
    if vals.len() % 2 == 1 {
        return Err(DeckError::new(K::OddSpline { count: vals.len() }, span));
    }
    let points = vals.chunks(2).map(|p| (p[0].0, p[1].0)).collect();
    CubicSpline::new(points, slopes)
        .map(Function::Spline)
        .map_err(|reason| {
            // Located at the time that does not increase, else at the card.
            let at = match reason {
                SplineError::NotIncreasing { index } => vals[2 * index].1,
                _ => span,
            };
            DeckError::new(K::BadSpline { reason }, at)
        })
}

/// `SINE|COSINE A (FREQ f | OMEGA ω) [PHASE φ] [START t0]`, keywords in any order.
fn harmonic(c: &mut Cursor<'_, '_>, cosine: bool) -> R<Function> {
    let (amplitude, _, _) = c.number("the amplitude")?;
    const KW: [&str; 4] = ["FREQ", "OMEGA", "PHASE", "START"];
    let mut seen = Seen::default();
    let (mut omega, mut phase, mut start) = (None, 0.0, None);
    while let Some(t) = c.peek() {
        let Some((kw, ks)) = c.keyword(&KW) else {
            return Err(c.unexpected(t, &expected_list(&KW)));
        };
        seen.add(kw, ks, &c.ctx)?;
        match kw {
            "FREQ" | "OMEGA" => {
                let other = if kw == "FREQ" { "OMEGA" } else { "FREQ" };
                if seen.has(other) {
                    return Err(conflict(other, kw, &c.ctx, ks));
                }
                let (what, unit) = if kw == "FREQ" {
                    ("FREQ (frequency)", "> 0 Hz")
                } else {
                    ("OMEGA (circular frequency)", "> 0 rad/s")
                };
                let v = c.number_in(what, unit, |v| v > 0.0)?;
                omega = Some(if kw == "FREQ" {
                    2.0 * std::f64::consts::PI * v
                } else {
                    v
                });
            }
            "PHASE" => phase = c.number("PHASE (rad)")?.0,
            _ => start = Some(c.number("START (time, s)")?.0),
        }
    }
    let omega = omega.ok_or_else(|| {
        DeckError::new(
            K::MissingKeyword {
                context: c.ctx.clone(),
                expected: "FREQ <Hz> or OMEGA <rad/s>".into(),
            },
            c.end_span(),
        )
    })?;
    Ok(Function::Harmonic {
        cosine,
        amplitude,
        omega,
        phase,
        start,
    })
}
