//! `RIGID <master> <n2> [<n3> …]`: a rigid body, every listed node moving with the first.

use super::super::{Card, Parse, Parsed, node_list};
use crate::deck::build::cursor::*;
use crate::deck::build::*;

/// The deck half of `RIGID`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["RIGID"],
    // Its row is the SECTIONS keyword's (deck/keywords.rs): one word, two uses.
    rows: &[],
    parse: Parse::One(parse),
    write: |_, e, s| s.push_str(&node_list(e)),
};

fn parse(_: &mut Builder<'_>, c: &mut Cursor<'_, '_>, id: u32, _: &str) -> R<Parsed> {
    c.ctx = format!("element {id} (RIGID)");
    Builder::refuse_drive(c)?;
    let mut ns = vec![c.uint("master node number")?, c.uint("second node number")?];
    while c.peek().is_some() {
        ns.push(c.uint("node number")?);
    }
    Ok((ns, ElementKind::Rigid))
}
