//! `UJOINT <n1> <n2> AXIS1 <x> <y> <z> AXIS2 <x> <y> <z>`: a universal (Cardan) joint, its
//! axes perpendicular at t = 0.

use super::super::v3;
use super::super::{Card, Parse, Parsed, node_list, row};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use std::fmt::Write;

/// The deck half of `UJOINT`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["UJOINT"],
    rows: &[
        row("UJOINT", "universal (Cardan) joint"),
        row("AXIS1", "UJOINT axis on the first node"),
    ],
    parse: Parse::One(parse),
    write,
};

fn parse(_: &mut Builder<'_>, c: &mut Cursor<'_, '_>, id: u32, _: &str) -> R<Parsed> {
    let n1 = c.uint("first node number")?;
    let n2 = c.uint("second node number")?;
    c.expect_keyword(&["AXIS1"], "AXIS1 <x> <y> <z>")?;
    let (a1, r1, s1) = c.axis("UJOINT AXIS1")?;
    c.expect_keyword(&["AXIS2"], "AXIS2 <x> <y> <z>")?;
    let (a2, r2, s2) = c.axis("UJOINT AXIS2")?;
    c.ctx = format!("element {id} (UJOINT)");
    Builder::refuse_drive(c)?;
    c.finish()?;
    let dot = r1.dot(&r2).abs() / (r1.norm() * r2.norm());
    if dot.is_nan() || dot > 1e-6 {
        return Err(DeckError::new(
            K::UJointNotPerpendicular { element: id, dot },
            Span::new(s1.start, s2.end),
        ));
    }
    Ok((
        vec![n1, n2],
        ElementKind::UJoint {
            axis1: a1,
            axis2: a2,
        },
    ))
}

fn write(_: &Model, e: &Element, s: &mut String) {
    s.push_str(&node_list(e));
    if let ElementKind::UJoint { axis1, axis2 } = &e.kind {
        let _ = write!(s, " AXIS1 {} AXIS2 {}", v3(axis1), v3(axis2));
    }
}
