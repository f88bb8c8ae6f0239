//! Stage 2, FUNCTIONS: `TABLE`, `CONSTANT`, `HAVERSINE`, `SPLINE`, `SINE`, `COSINE`,
//! `RAMP`, `EXPR` (grammar.md, "FUNCTIONS").

use super::cursor::*;
use super::*;
use crate::model::{CubicSpline, ElementKind, FunctionId, SplineError, SpringLength, TimeExpr};
use indexmap::IndexMap;
use nalgebra::Vector3;

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
                    field: tok.span,
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

    /// Every EXPR function shown finite by interval arithmetic (`model::Expr::prove_finite`)
    /// on the domain of each of its uses:
    /// - as a time function (a load, a driver, or not used): `f`, `ḟ`, `f̈` on
    ///   `[0, END + H/100]` (`[0, 1]`, the load factor, for a static analysis): the run
    ///   evaluates a law up to the end time and an ESDIRK stage's driver rate `1e-2 γ H`
    ///   past it (`H` the largest step, γ < 1);
    /// - as a SPRING's force–deflection curve: `F_c`, `F_c′` on `[−L_ref, D]`, from the
    ///   spring at zero length (it cannot be shorter: the element refuses such a state) to
    ///   a stretch by `D`, the diagonal of the box of the model's nodes at t = 0 (a spring
    ///   longer than the model's extent has left the mechanism; past it the run checks the
    ///   law's value at run time, `elements::spring`).
    ///
    /// An expression that cannot be shown finite is an error located at the innermost
    /// part of it whose enclosure blew up, with the piece of the domain.
    pub(super) fn check_functions(&mut self, analysis: &Analysis) {
        let end = match analysis {
            Analysis::Dynamic { end, max_step, .. } => end + 0.01 * max_step,
            Analysis::Static { .. } => 1.0,
        };
        // The deflection domain of each curve (the hull over the springs using it).
        let (mut lo, mut hi) = (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        );
        for n in self.nodes.values() {
            lo = lo.inf(&n.position);
            hi = hi.sup(&n.position);
        }
        let diameter = if self.nodes.is_empty() {
            0.0
        } else {
            (hi - lo).norm()
        };
        let mut curves: IndexMap<FunctionId, (f64, f64)> = IndexMap::new();
        for e in self.elements.values() {
            let ElementKind::Spring(d) = &e.kind else {
                continue;
            };
            let Some(f) = d.curve else { continue };
            let initial = match (self.nodes.get(&e.nodes[0]), self.nodes.get(&e.nodes[1])) {
                (Some(a), Some(b)) => (b.position - a.position).norm(),
                _ => continue,
            };
            let l_ref = match d.length {
                SpringLength::Free(l0) => l0,
                SpringLength::Initial | SpringLength::Preload(_) => initial,
            };
            let dom = curves
                .entry(f)
                .or_insert((f64::INFINITY, f64::NEG_INFINITY));
            dom.0 = dom.0.min(-l_ref);
            dom.1 = dom.1.max(diameter.max(initial));
        }
        let timed: std::collections::HashSet<FunctionId> = self
            .loads
            .iter()
            .filter_map(|l| l.function)
            .chain(self.drives.values().map(|d| d.function))
            .chain(self.elements.values().filter_map(|e| match &e.kind {
                ElementKind::Prescribed { drive, .. } => Some(drive.function),
                _ => None,
            }))
            .collect();
        let mut errors = Vec::new();
        for f in self.functions.values() {
            let Function::Expr(e) = &f.function else {
                continue;
            };
            let curve = curves.get(&f.id).copied();
            let mut uses = Vec::new();
            if timed.contains(&f.id) || curve.is_none() {
                uses.push((Use::Time, 0.0, end, 2u8));
            }
            if let Some((a, b)) = curve {
                uses.push((Use::Deflection, a, b, 1u8));
            }
            for (role, a, b, order) in uses {
                if let Err(blow) = e.expr.prove_finite(a, b, order) {
                    errors.push(not_finite(f.id.0, e, role, (a, b), &blow));
                }
            }
        }
        // A driver's law must have a continuous velocity (`drive_jumps`).
        let drivers: Vec<(FunctionId, Span)> = self
            .drives
            .values()
            .map(|d| (d.function, d.span))
            .chain(self.elements.values().filter_map(|e| match &e.kind {
                ElementKind::Prescribed { drive, .. } => Some((drive.function, drive.span)),
                _ => None,
            }))
            .collect();
        for (fid, at) in drivers {
            if let Some(f) = self.functions.get(&fid)
                && let Some(err) = drive_jumps(fid.0, &f.function, end, at)
            {
                errors.push(err);
            }
        }
        self.errors.extend(errors);
    }
}

/// A driver's law whose velocity jumps on `[0, end]`, refused: the driven coordinate's
/// velocity level `B v = a ḟ` cannot hold across the jump without an impulse, which a
/// step cannot represent (the integrator restarts the accelerations at a driver's
/// breakpoints, not the velocities: the run would go on with the velocity constraint
/// violated by `a Δḟ`, and the drivers' work, `∫ τ a ḟ dt`, undefined; the issue's
/// kinked law ran with a balance error of 0.177 and no word). The jumps looked for: an
/// EXPR's `abs` whose argument crosses 0 where the one-sided slopes differ (proven by
/// interval arithmetic, `model::Expr::velocity_jump`), and a SINE's or COSINE's START
/// (`ḟ` jumps by `A ω cos φ`, resp. `−A ω sin φ`, beyond its round-off `4 ε |A| ω`; `f`
/// itself by `A sin φ`, resp. `A cos φ`). A TABLE is refused for drivers elsewhere.
fn drive_jumps(id: u32, f: &Function, end: f64, at: Span) -> Option<DeckError> {
    let reason = match f {
        Function::Expr(e) => {
            let k = e.expr.velocity_jump(0.0, end)?;
            let start = (k.at.start as usize).min(e.text.len());
            let stop = (start + k.at.len as usize).min(e.text.len());
            let span = Span::new(e.field.start + start, e.field.start + stop);
            return Some(DeckError::new(
                K::BadDrive {
                    context: format!("function {id} (driving a joint or node)"),
                    reason: format!(
                        "its velocity jumps by {:.6e} at t = {} s, where the argument of `{}` crosses 0 (a kink of `{}`): a prescribed motion must have a continuous velocity (it would need an impulse); smooth the law (RAMP, HAVERSINE, SPLINE) or make the kinks cancel",
                        k.jump.mid(),
                        shown(0.5 * k.piece.0 + 0.5 * k.piece.1),
                        e.text.get(start..stop).unwrap_or(""),
                        e.text
                    ),
                },
                span,
            ));
        }
        Function::Harmonic {
            cosine,
            amplitude,
            omega,
            phase,
            start: Some(t0),
        } if *t0 > 0.0 && *t0 < end => {
            let (jf, jv) = if *cosine {
                (amplitude * phase.cos(), -amplitude * omega * phase.sin())
            } else {
                (amplitude * phase.sin(), amplitude * omega * phase.cos())
            };
            let round = 4.0 * f64::EPSILON * amplitude.abs() * omega.max(1.0);
            if jf.abs() <= round && jv.abs() <= round {
                return None;
            }
            format!(
                "{} with START {t0} s jumps there by {jf:.6e} (value) and {jv:.6e} (velocity): a prescribed motion must be continuous with its velocity (it would need an impulse), and a started wave jumps in one or the other; start it with an envelope (an EXPR with a RAMP-like factor, a SPLINE) or without START",
                if *cosine { "COSINE" } else { "SINE" }
            )
        }
        _ => return None,
    };
    Some(DeckError::new(
        K::BadDrive {
            context: format!("function {id} (driving a joint or node)"),
            reason,
        },
        at,
    ))
}

/// What the variable of a function is where it is used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Use {
    Time,
    Deflection,
    /// A CONTROL law, its sensors at the drawing at rest.
    Law,
}

/// `t` rounded to 9 significant digits (what a message shows).
fn shown(t: f64) -> f64 {
    format!("{t:.8e}").parse().unwrap_or(t)
}

/// The located error of an expression not shown finite on its domain.
fn not_finite(
    id: u32,
    e: &TimeExpr,
    role: Use,
    domain: (f64, f64),
    b: &crate::model::Blowup,
) -> DeckError {
    let start = (b.at.start as usize).min(e.text.len());
    let end = (start + b.at.len as usize).min(e.text.len());
    let part = e.text.get(start..end).unwrap_or(&e.text).to_string();
    let span = Span::new(e.field.start + start, e.field.start + end);
    let what = ["value", "first derivative", "second derivative"][usize::from(b.order.min(2))];
    let (var, unit) = match role {
        Use::Time => ("t", "s"),
        Use::Deflection => ("the deflection", "m"),
        Use::Law => ("t", "s"),
    };
    let at = shown(b.point.unwrap_or(0.5 * b.piece.0 + 0.5 * b.piece.1));
    DeckError::new(
        K::FunctionNotFinite(Box::new(crate::deck::error::FunctionNotFinite {
            owner: if matches!(role, Use::Law) {
                "CONTROL element (its sensors at the deck's drawing, at rest)"
            } else {
                "function"
            },
            id,
            text: e.text.clone(),
            part,
            what,
            var,
            at,
            unit,
            sure: b.point.is_some(),
            domain: (shown(domain.0), shown(domain.1)),
        })),
        span,
    )
}

/// The located error of a `CONTROL` law not shown finite on `[0, END]` with its sensors
/// at their initial values (`deck/build/control.rs`).
pub(super) fn law_not_finite(
    id: u32,
    e: &TimeExpr,
    domain: (f64, f64),
    b: &crate::model::Blowup,
) -> DeckError {
    not_finite(id, e, Use::Law, domain, b)
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
