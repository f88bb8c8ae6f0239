//! Stage 2, ELEMENTS: the element loop — the element number (or a `first TO last`
//! generation) and type, the rest of the card read by its kind (`kinds`, the registry).

use super::checks::same_node;
use super::cursor::*;
use super::kinds;
use super::*;

impl Builder<'_> {
    // ---------------------------------------------------------------- ELEMENTS
    pub(super) fn element(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "ELEMENTS card");
        let (id, id_span) = c.uint("element number")?;
        c.ctx = format!("element {id}");
        let mut last = None;
        if c.keyword(&["TO"]).is_some() {
            let (l, ls) = c.uint("last element number of the generation")?;
            if l <= id {
                return Err(DeckError::new(
                    K::BadGeneration {
                        first: id,
                        last: l,
                        reason: "the last number must be greater than the first".into(),
                    },
                    Span::new(id_span.start, ls.end),
                ));
            }
            generation_size(id, l, Span::new(id_span.start, ls.end))?;
            self.fits(
                0,
                u64::from(l - id) + 1,
                id,
                l,
                Span::new(id_span.start, ls.end),
            )?;
            c.ctx = format!("elements {id} TO {l}");
            last = Some(l);
        }
        let t = c.next("element type (BEAM, MASS, HINGE, ...)")?;
        let Some((card, ty)) = kinds::card(|k| t.is_kw(k)) else {
            let types: Vec<&str> = kinds::types().collect();
            return Err(DeckError::new(
                K::UnknownElementType {
                    found: t.text.to_string(),
                    expected: types.join(", "),
                },
                t.span,
            ));
        };
        match card.parse {
            kinds::Parse::Generates(parse) => {
                let g = kinds::Generation {
                    first: id,
                    last: last.unwrap_or(id),
                    span,
                    id_span,
                };
                parse(self, &mut c, &g)
            }
            kinds::Parse::One(parse) => {
                if last.is_some() {
                    let only = kinds::generated_types();
                    let what = format!("{only} (only {only} can be generated with TO)");
                    return Err(c.unexpected(t, &what));
                }
                let (nodes, kind) = parse(self, &mut c, id, ty)?;
                same_node(ty, id, &nodes)?;
                let mut ids = Vec::with_capacity(nodes.len());
                for (n, s) in nodes {
                    ids.push(self.node_ref(n, s)?);
                }
                self.add_element(id, ids, kind, span, id_span);
                Ok(())
            }
        }
    }

    pub(super) fn add_element(
        &mut self,
        id: u32,
        nodes: Vec<NodeId>,
        kind: ElementKind,
        span: Span,
        at: Span,
    ) {
        if let Some(first) = self.elements.get(&ElementId(id)).map(|e| e.span) {
            self.duplicate("element", id, first, at);
            return;
        }
        self.elements.insert(
            ElementId(id),
            Element {
                id: ElementId(id),
                nodes,
                kind,
                span,
            },
        );
    }
}
