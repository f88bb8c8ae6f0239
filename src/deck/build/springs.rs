//! Stage 2, ELEMENTS, once every element is read: the hinge an `RSPRING`, a `PID` or a
//! `CONTROL` acts on (their cards: `kinds/forces/rspring.rs`, `control.rs`).

use super::*;

impl Builder<'_> {
    /// Gives every RSPRING its hinge's nodes and axis; the hinge must be a HINGE element.
    pub(super) fn resolve_hinges(&mut self) {
        for (id, hinge, span) in std::mem::take(&mut self.hinge_refs) {
            let found = match self.elements.get(&ElementId(hinge)) {
                None => Err(K::Undefined {
                    what: "element",
                    id: hinge,
                }),
                Some(h) => match &h.kind {
                    ElementKind::Hinge { axis, .. } => Ok((h.nodes.clone(), *axis)),
                    other => Err(K::NotAHinge {
                        by: self
                            .elements
                            .get(&id)
                            .map_or("RSPRING", |e| e.kind.keyword()),
                        what: match self.elements.get(&id).map(|e| e.kind.keyword()) {
                            Some("CONTROL") => {
                                "its TORQUE acts on, and its angle(h) and rate(h) read,"
                            }
                            Some("PID") => "a PID acts on",
                            _ => "an RSPRING acts on",
                        },
                        element: id.0,
                        target: hinge,
                        found: other.keyword(),
                    }),
                },
            };
            match found {
                Err(kind) => self.errors.push(DeckError::new(kind, span)),
                Ok((nodes, axis)) => {
                    if let Some(el) = self.elements.get_mut(&id) {
                        match &mut el.kind {
                            ElementKind::RSpring(d) if d.hinge.0 == hinge => {
                                d.axis = axis;
                                el.nodes = nodes;
                            }
                            _ => {}
                        }
                    }
                }
            }
        }
        // A PID's or CONTROL's input acts on its actuator's and sensors' nodes (a hinge's
        // two), once all hinges are known (deck/build/control.rs).
        let hinge_nodes = |h: ElementId| match self.elements.get(&h) {
            Some(e) if matches!(e.kind, ElementKind::Hinge { .. }) => {
                Some([e.nodes[0], e.nodes[1]])
            }
            _ => None,
        };
        let nodes: Vec<(ElementId, Vec<NodeId>)> = self
            .elements
            .iter()
            .filter_map(|(id, e)| match &e.kind {
                ElementKind::Control(d) => Some((*id, d.nodes(hinge_nodes))),
                _ => None,
            })
            .collect();
        for (id, n) in nodes {
            if let Some(el) = self.elements.get_mut(&id) {
                el.nodes = n;
            }
        }
    }
}
