//! `HINGE` and `PRISMATIC <n1> <n2> AXIS <x> <y> <z> [DRIVE <f> [AMPLITUDE <a>]]`: a revolute
//! or sliding joint, its angle or travel optionally driven as a·f(t) (`build/drives.rs`).

use super::super::v3;
use super::super::{Card, Parse, Parsed, node_list, row};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use std::fmt::Write;

/// The deck half of `HINGE` and `PRISMATIC`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["HINGE", "PRISMATIC"],
    rows: &[
        row("HINGE", "revolute joint"),
        row("PRISMATIC", "prismatic (sliding) joint"),
        row(
            "DRIVE",
            "HINGE or PRISMATIC: the angle or travel prescribed as a·f(t) (function number)",
        ),
    ],
    parse: Parse::One(parse),
    write,
};

fn parse(b: &mut Builder<'_>, c: &mut Cursor<'_, '_>, id: u32, ty: &str) -> R<Parsed> {
    let n1 = c.uint("first node number")?;
    let n2 = c.uint("second node number")?;
    c.expect_keyword(&["AXIS"], "AXIS <x> <y> <z>")?;
    let (axis, _, _) = c.axis(&format!("{ty} AXIS"))?;
    if let Some(d) = b.drive_option(c)? {
        c.finish()?;
        b.drives.insert(ElementId(id), d);
    }
    c.finish()?;
    let kind = if ty == "HINGE" {
        ElementKind::Hinge { axis }
    } else {
        ElementKind::Prismatic { axis }
    };
    Ok((vec![n1, n2], kind))
}

fn write(model: &Model, e: &Element, s: &mut String) {
    s.push_str(&node_list(e));
    let (ElementKind::Hinge { axis } | ElementKind::Prismatic { axis }) = &e.kind else {
        return;
    };
    let _ = write!(s, " AXIS {}", v3(axis));
    if let Some(d) = model.drives.get(&e.id) {
        let _ = write!(s, " DRIVE {} AMPLITUDE {:?}", d.function.0, d.amplitude);
    }
}
