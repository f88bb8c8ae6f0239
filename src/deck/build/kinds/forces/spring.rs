//! `SPRING <n1> <n2> [K k] [C c] [L0 l | PRELOAD p] [CURVE f]`: a two-node spring–damper
//! along the line of its nodes (issue 25 §3; grammar.md, "Springs, bushings and
//! rotational springs").

use super::super::{Card, Parse, Parsed, node_list, row};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use crate::model::{SpringData, SpringLength};
use std::fmt::Write;

/// The deck half of `SPRING`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["SPRING"],
    rows: &[
        row(
            "SPRING",
            "two-node spring-damper along the line of its nodes (K, C, L0 or PRELOAD, CURVE)",
        ),
        row(
            "L0",
            "SPRING: free length, m (>= 0; default: initial distance)",
        ),
        row(
            "PRELOAD",
            "SPRING: tension at the initial distance, N (instead of L0)",
        ),
        row(
            "CURVE",
            "SPRING: function number of a force-deflection curve F(deflection), N",
        ),
    ],
    parse: Parse::One(parse),
    write,
};

/// `SPRING <n1> <n2> [K k] [C c] [L0 l | PRELOAD p] [CURVE f]`.
fn parse(bld: &mut Builder<'_>, c: &mut Cursor<'_, '_>, id: u32, _: &str) -> R<Parsed> {
    let n1 = c.uint("first node number")?;
    let n2 = c.uint("second node number")?;
    const KW: [&str; 5] = ["K", "C", "L0", "PRELOAD", "CURVE"];
    let mut seen = Seen::default();
    let mut data = SpringData {
        stiffness: 0.0,
        damping: 0.0,
        length: SpringLength::Initial,
        curve: None,
    };
    while let Some(t) = c.peek() {
        let Some((kw, ks)) = c.keyword(&KW) else {
            return Err(c.unexpected(t, &expected_list(&KW)));
        };
        seen.add(kw, ks, &c.ctx)?;
        match kw {
            "K" => data.stiffness = c.number_in("K (stiffness)", ">= 0 N/m", |v| v >= 0.0)?,
            "C" => data.damping = c.number_in("C (damping)", ">= 0 N·s/m", |v| v >= 0.0)?,
            "L0" | "PRELOAD" => {
                let other = if kw == "L0" { "PRELOAD" } else { "L0" };
                if seen.has(other) {
                    return Err(conflict(other, kw, &c.ctx, ks));
                }
                data.length = if kw == "L0" {
                    SpringLength::Free(c.number_in("L0 (free length)", ">= 0 m", |v| v >= 0.0)?)
                } else {
                    SpringLength::Preload(c.number("PRELOAD (tension at t = 0, N)")?.0)
                };
            }
            _ => {
                let (f, fs) = c.uint("CURVE (function number)")?;
                data.curve = Some(bld.function_ref(f, fs)?);
            }
        }
    }
    let (a, b) = (bld.node_ref(n1.0, n1.1)?, bld.node_ref(n2.0, n2.1)?);
    if let (Some(x), Some(y)) = (bld.nodes.get(&a), bld.nodes.get(&b))
        && x.position == y.position
        && n1.0 != n2.0
    {
        let reason = if matches!(data.length, SpringLength::Free(_)) {
            "its line of action is undefined at t = 0: the nodes must start apart"
        } else {
            "a spring of zero length with no free length given: move a node, or give L0 (the nodes must still start apart)"
        };
        return Err(DeckError::new(
            K::SpringZeroLength {
                element: id,
                first: n1.0,
                second: n2.0,
                reason,
            },
            Span::new(n1.1.start, n2.1.end),
        ));
    }
    Ok((vec![n1, n2], ElementKind::Spring(Box::new(data))))
}

fn write(_: &Model, e: &Element, s: &mut String) {
    s.push_str(&node_list(e));
    let ElementKind::Spring(p) = &e.kind else {
        return;
    };
    let _ = write!(s, " K {:?} C {:?}", p.stiffness, p.damping);
    match p.length {
        SpringLength::Initial => {}
        SpringLength::Free(l) => {
            let _ = write!(s, " L0 {l:?}");
        }
        SpringLength::Preload(f) => {
            let _ = write!(s, " PRELOAD {f:?}");
        }
    }
    if let Some(f) = p.curve {
        let _ = write!(s, " CURVE {}", f.0);
    }
}
