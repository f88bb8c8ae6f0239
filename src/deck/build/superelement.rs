//! Stage 2, ELEMENTS: `SUPERELEMENT` (issue 38; grammar.md, "Superelements").

use super::cursor::*;
use super::*;
use crate::model::SuperelementData;

/// What the card gives to the element loop: its interface nodes and kind.
type Parsed = (Vec<(u32, Span)>, ElementKind);

/// Most fixed-interface modes a superelement may keep (the FE model bounds it further).
const MAX_MODES: u32 = 10_000;
/// Most interface nodes of a superelement.
const MAX_INTERFACE: usize = 1_000;

impl Builder<'_> {
    /// `SUPERELEMENT FILES <dir> MODES <n> INTERFACE <fe> <node> [<fe> <node> …]`.
    pub(super) fn superelement_card(c: &mut Cursor<'_, '_>) -> R<Parsed> {
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
}
