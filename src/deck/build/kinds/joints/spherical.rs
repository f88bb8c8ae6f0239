//! `SPHERICAL` and `CLAMP <n1> <n2>`: relative translation blocked; everything blocked.

use super::super::{Card, Parse, Parsed, node_list, row};
use crate::deck::build::cursor::*;
use crate::deck::build::*;

/// The deck half of `SPHERICAL` and `CLAMP`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["SPHERICAL", "CLAMP"],
    rows: &[
        row("SPHERICAL", "spherical joint"),
        row("CLAMP", "two nodes welded together"),
    ],
    parse: Parse::One(parse),
    write: |_, e, s| s.push_str(&node_list(e)),
};

fn parse(_: &mut Builder<'_>, c: &mut Cursor<'_, '_>, id: u32, ty: &str) -> R<Parsed> {
    let n1 = c.uint("first node number")?;
    let n2 = c.uint("second node number")?;
    c.ctx = format!("element {id} ({ty})");
    Builder::refuse_drive(c)?;
    c.finish()?;
    let kind = if ty == "CLAMP" {
        ElementKind::Clamp
    } else {
        ElementKind::Spherical
    };
    Ok((vec![n1, n2], kind))
}
