//! `SUPERELEMENT FILES <dir> MODES <n> INTERFACE <fe> <node> …`: a linear elastic body
//! reduced from an FE model (issue 38; grammar.md, "Superelements").

use super::super::{Card, Parse, Parsed, row};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use crate::model::SuperelementData;
use std::fmt::Write;

/// The deck half of `SUPERELEMENT`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["SUPERELEMENT"],
    rows: &[
        row(
            "SUPERELEMENT",
            "a linear elastic body reduced from an FE model (Craig–Bampton in a floating frame)",
        ),
        row(
            "FILES",
            "SUPERELEMENT: directory of K.mtx, M.mtx, nodes.csv, dofs.csv (relative to the deck's)",
        ),
        row(
            "INTERFACE",
            "SUPERELEMENT: pairs <FE node> <node>; the first is the frame node",
        ),
    ],
    parse: Parse::One(parse),
    write,
};

/// Most fixed-interface modes a superelement may keep (the FE model bounds it further).
const MAX_MODES: u32 = 10_000;
/// Most interface nodes of a superelement.
const MAX_INTERFACE: usize = 1_000;

/// `SUPERELEMENT FILES <dir> MODES <n> INTERFACE <fe> <node> [<fe> <node> …]`.
fn parse(_: &mut Builder<'_>, c: &mut Cursor<'_, '_>, _: u32, _: &str) -> R<Parsed> {
    c.expect_keyword(
        &["FILES"],
        "FILES <directory of K.mtx, M.mtx, nodes.csv, dofs.csv>",
    )?;
    let dir = c.next("the directory of the FE model's files")?;
    let dir = std::path::PathBuf::from(dir.text);
    c.expect_keyword(&["MODES"], "MODES <number of fixed-interface modes>")?;
    let t = c.peek();
    let (modes, ms) = c.uint("MODES (fixed-interface modes kept)")?;
    if modes > MAX_MODES {
        let text = t.map_or("", |t| t.text);
        return Err(out_of_range(
            "MODES",
            text,
            &format!("0 to {MAX_MODES}"),
            ms,
        ));
    }
    c.expect_keyword(
        &["INTERFACE"],
        "INTERFACE <FE node> <node> [<FE node> <node> …]",
    )?;
    let mut interface = Vec::new();
    let mut nodes = Vec::new();
    loop {
        let (fe, fs) = c.uint("FE node number (of nodes.csv)")?;
        if let Some(k) = interface.iter().position(|&a| a == fe) {
            let (_, first): &(u32, Span) = &nodes[k];
            return Err(DeckError::new(
                K::OutOfRange {
                    field: "INTERFACE FE node".into(),
                    found: fe.to_string(),
                    range: format!(
                        "an FE node not named before (named at byte {})",
                        first.start
                    ),
                },
                fs,
            ));
        }
        interface.push(fe);
        nodes.push(c.uint("node number (of NODES) the FE node is attached to")?);
        if c.peek().is_none() {
            break;
        }
        if interface.len() == MAX_INTERFACE {
            let t = c.next("end of card")?;
            return Err(c.unexpected(t, &format!("at most {MAX_INTERFACE} interface nodes")));
        }
    }
    let data = SuperelementData {
        dir,
        modes,
        interface,
        modal: Vec::new(),
    };
    Ok((nodes, ElementKind::Superelement(Box::new(data))))
}

fn write(_: &Model, e: &Element, s: &mut String) {
    // Its interface nodes follow INTERFACE; its modal nodes are generated.
    let ElementKind::Superelement(d) = &e.kind else {
        return;
    };
    let _ = write!(s, "FILES {} MODES {} INTERFACE", d.dir.display(), d.modes);
    for (fe, node) in d.interface.iter().zip(&e.nodes) {
        let _ = write!(s, " {fe} {}", node.0);
    }
}
