//! `SUPERELEMENT FILES <dir> MODES <n> INTERFACE <fe> <node> … [RBE2|RBE3 …] [CACHE ON|OFF]`: a linear elastic body
//! reduced from an FE model (issue 38; grammar.md, "Superelements").

use super::super::{Card, Parse, Parsed, row};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use crate::model::{RbeKind, RbeSpec, SetSpec, SuperelementData};
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
        row(
            "RBE2",
            "SUPERELEMENT: RBE2 <FE node> SET|WITHIN: a rigid interface over many FE nodes",
        ),
        row(
            "RBE3",
            "SUPERELEMENT: RBE3 <FE node> SET|WITHIN [WEIGHTS]: an averaging interface (least-squares rigid fit)",
        ),
        row(
            "SET",
            "SUPERELEMENT RBE2/RBE3: the FE nodes joined (numbers of nodes.csv; a TO b for a range)",
        ),
        row(
            "WITHIN",
            "SUPERELEMENT RBE2/RBE3: every FE node within this distance of the interface node, m",
        ),
        row(
            "WEIGHTS",
            "SUPERELEMENT RBE3: one weight > 0 per SET node (default 1)",
        ),
        row(
            "CACHE",
            "SUPERELEMENT: CACHE ON|OFF: keep the reduction beside the FE files for the next run (default ON)",
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
        if c.peek()
            .is_none_or(|t| t.is_kw("RBE2") || t.is_kw("RBE3") || t.is_kw("CACHE"))
        {
            break;
        }
        if interface.len() == MAX_INTERFACE {
            let t = c.next("end of card")?;
            return Err(c.unexpected(t, &format!("at most {MAX_INTERFACE} interface nodes")));
        }
    }
    let rbe = rbe_clauses(c, &interface)?;
    let cache = match c.keyword(&["CACHE"]) {
        Some(_) => c.expect_keyword(&["ON", "OFF"], "ON or OFF after CACHE")?.0 == "ON",
        None => true,
    };
    c.finish()?;
    let data = SuperelementData {
        dir,
        modes,
        interface,
        modal: Vec::new(),
        rbe,
        cache,
    };
    Ok((nodes, ElementKind::Superelement(Box::new(data))))
}

/// Most FE nodes of one `SET`.
const MAX_SET: u32 = 1_000_000;

/// `[RBE2|RBE3 <fe> (SET <fe> [TO <fe>] … | WITHIN <r>) [WEIGHTS <w> …]] …`: interfaces over
/// many FE nodes; each `<fe>` one of `interface`'s, joined once.
fn rbe_clauses(c: &mut Cursor<'_, '_>, interface: &[u32]) -> R<Vec<RbeSpec>> {
    let mut out: Vec<RbeSpec> = Vec::new();
    while let Some((kw, _)) = c.keyword(&["RBE2", "RBE3"]) {
        let kind = match kw {
            "RBE2" => RbeKind::Rigid,
            _ => RbeKind::Average,
        };
        let t = c.peek();
        let (node, ns) = c.uint("the interface node's FE number (one of INTERFACE's)")?;
        let text = t.map_or("", |t| t.text);
        if node == 0 || !interface.contains(&node) {
            return Err(out_of_range(
                &format!("{kw} node"),
                text,
                "an FE number named in INTERFACE (≥ 1)",
                ns,
            ));
        }
        if out.iter().any(|r| r.node == node) {
            return Err(out_of_range(
                &format!("{kw} node"),
                text,
                "an interface node not joined by an RBE2 or RBE3 before",
                ns,
            ));
        }
        let (how, _) = c.expect_keyword(
            &["SET", "WITHIN"],
            "SET <FE nodes> or WITHIN <radius> (the FE nodes joined)",
        )?;
        let set = if how == "SET" {
            let mut v: Vec<u32> = Vec::new();
            while c.next_is_number() {
                let t = c.peek();
                let (a, s) = c.uint("FE node number (of nodes.csv)")?;
                let mut b = a;
                if c.keyword(&["TO"]).is_some() {
                    let (bb, bs) = c.uint("last FE node number of the range")?;
                    if bb <= a {
                        return Err(out_of_range(
                            "SET range end",
                            &bb.to_string(),
                            &format!("> {a}"),
                            bs,
                        ));
                    }
                    generation_size(a, bb, bs)?;
                    b = bb;
                }
                for p in a..=b {
                    if v.len() as u32 >= MAX_SET {
                        return Err(out_of_range(
                            "SET",
                            t.map_or("", |t| t.text),
                            &format!("at most {MAX_SET} FE nodes"),
                            s,
                        ));
                    }
                    if v.contains(&p) || p == node {
                        return Err(out_of_range(
                            "SET FE node",
                            &p.to_string(),
                            "an FE node not in the set already, not the interface node",
                            s,
                        ));
                    }
                    v.push(p);
                }
            }
            if v.is_empty() {
                return Err(c.missing("SET <FE node> [<FE node> …]: at least one FE node"));
            }
            SetSpec::Nodes(v)
        } else {
            SetSpec::Within(c.number_in("WITHIN (radius)", "> 0 m", |v| v > 0.0 && v.is_finite())?)
        };
        let mut weights = Vec::new();
        if let Some((_, ws)) = c.keyword(&["WEIGHTS"]) {
            let count = match (&set, kind) {
                (SetSpec::Nodes(v), RbeKind::Average) => v.len(),
                _ => {
                    return Err(out_of_range(
                        "WEIGHTS",
                        "WEIGHTS",
                        "WEIGHTS only after an RBE3's SET (one per FE node)",
                        ws,
                    ));
                }
            };
            while c.next_is_number() && weights.len() < count {
                weights.push(c.number_in("RBE3 weight", "> 0", |v| v > 0.0 && v.is_finite())?);
            }
            if weights.len() < count {
                return Err(c.missing(&format!(
                    "WEIGHTS: {count} weights, one per SET node ({} given)",
                    weights.len()
                )));
            }
        }
        out.push(RbeSpec {
            kind,
            node,
            set,
            weights,
        });
    }
    Ok(out)
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
    for r in &d.rbe {
        let kw = match r.kind {
            RbeKind::Rigid => "RBE2",
            RbeKind::Average => "RBE3",
        };
        let _ = write!(s, " {kw} {}", r.node);
        match &r.set {
            SetSpec::Nodes(v) => {
                let _ = write!(s, " SET");
                for p in v {
                    let _ = write!(s, " {p}");
                }
            }
            SetSpec::Within(x) => {
                let _ = write!(s, " WITHIN {x:?}");
            }
        }
        if !r.weights.is_empty() {
            let _ = write!(s, " WEIGHTS");
            for w in &r.weights {
                let _ = write!(s, " {w:?}");
            }
        }
    }
    if !d.cache {
        let _ = write!(s, " CACHE OFF");
    }
}
