//! Stage 2, ELEMENTS: beams, joints, masses, springs, contact (CAME) and profiles.

use super::checks::same_node;
use super::cursor::*;
use super::kinds;
use super::*;
use crate::model::order::MAX_ORDER;

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
        // The kinds not yet in the registry (`crate::kinds`), read below.
        const TYPES: [&str; 1] = ["BEAM"];
        let t = c.next("element type (BEAM, MASS, HINGE, ...)")?;
        let card = kinds::card(|k| t.is_kw(k));
        let old = TYPES.iter().find(|k| t.is_kw(k)).copied();
        let Some(ty) = card.map(|(_, ty)| ty).or(old) else {
            let types: Vec<&str> = TYPES.into_iter().chain(kinds::types()).collect();
            return Err(DeckError::new(
                K::UnknownElementType {
                    found: t.text.to_string(),
                    expected: types.join(", "),
                },
                t.span,
            ));
        };
        if last.is_some() && ty != "BEAM" {
            return Err(c.unexpected(t, "BEAM (only beams can be generated with TO)"));
        }
        let (nodes, kind): (Vec<(u32, Span)>, ElementKind) = match (card, ty) {
            (Some((card, ty)), _) => (card.parse)(self, &mut c, id, ty)?,
            (None, _) => {
                let n1 = c.uint("first node number")?;
                let n2 = c.uint("second node number")?;
                let mut seen = Seen::default();
                let (mut mat, mut sec, mut axis2, mut divide) = (None, None, None, None);
                let (mut order, mut arc) = (1, None);
                const KW: [&str; 6] = ["MAT", "SEC", "AXIS2", "DIVIDE", "ORDER", "ARC"];
                while let Some(t) = c.peek() {
                    let Some((kw, ks)) = c.keyword(&KW) else {
                        return Err(c.unexpected(t, &expected_list(&KW)));
                    };
                    seen.add(kw, ks, &c.ctx)?;
                    match kw {
                        "MAT" => mat = Some(c.uint("material number")?),
                        "SEC" => sec = Some(c.uint("section number")?),
                        "DIVIDE" => {
                            let t = c.peek();
                            let (n, ns) = c.uint("DIVIDE (number of elements)")?;
                            if n == 0 || n > MAX_GENERATION {
                                let text = t.map_or("", |t| t.text);
                                let range = format!("1 to {MAX_GENERATION} elements");
                                return Err(out_of_range("DIVIDE", text, &range, ns));
                            }
                            divide = Some(n);
                        }
                        "ORDER" => {
                            let t = c.peek();
                            let (p, ps) = c.uint("ORDER (polynomial order of the beam)")?;
                            if p == 0 || p > MAX_ORDER {
                                let text = t.map_or("", |t| t.text);
                                let range = format!("1 to {MAX_ORDER}");
                                return Err(out_of_range("ORDER", text, &range, ps));
                            }
                            order = p;
                        }
                        "ARC" => {
                            let (v, s, _) = c.vec3("ARC (centre of the arc)")?;
                            arc = Some((v, s));
                        }
                        _ => axis2 = Some(c.axis("AXIS2")?),
                    }
                }
                let miss = |what: &str| {
                    DeckError::new(
                        K::MissingKeyword {
                            context: c.ctx.clone(),
                            expected: what.into(),
                        },
                        c.end_span(),
                    )
                };
                // Report the first mistake in reading order: nodes come before MAT.
                self.node_ref(n1.0, n1.1)?;
                self.node_ref(n2.0, n2.1)?;
                let (sec, ss) = sec.ok_or_else(|| miss("SEC <section number>"))?;
                let Some(section) = self.sections.get(&SectionId(sec)) else {
                    let what = "section";
                    return Err(DeckError::new(K::Undefined { what, id: sec }, ss));
                };
                // A section of properties per unit length takes no material.
                let material = match (section.needs_material(), mat) {
                    (true, None) => return Err(miss("MAT <material number>")),
                    (true, Some((m, ms))) => {
                        if !self.materials.contains_key(&MaterialId(m)) {
                            let what = "material";
                            return Err(DeckError::new(K::Undefined { what, id: m }, ms));
                        }
                        Some(MaterialId(m))
                    }
                    (false, None) => None,
                    (false, Some((m, ms))) => {
                        let (element, material, section) = (id, m, sec);
                        let kind = K::MaterialNotUsed {
                            element,
                            material,
                            section,
                        };
                        return Err(DeckError::new(kind, ms));
                    }
                };
                return self.beams(
                    id,
                    last.unwrap_or(id),
                    (n1, n2),
                    (material, SectionId(sec)),
                    axis2.map(|(u, _, s)| (u, s)),
                    (divide.unwrap_or(1), order, arc),
                    span,
                    id_span,
                );
            }
        };
        if ty != "BEAM" {
            same_node(ty, id, &nodes)?;
        }
        let mut ids = Vec::with_capacity(nodes.len());
        for (n, s) in nodes {
            ids.push(self.node_ref(n, s)?);
        }
        self.add_element(id, ids, kind, span, id_span);
        Ok(())
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

    #[allow(clippy::too_many_arguments)]
    pub(super) fn beams(
        &mut self,
        first: u32,
        last: u32,
        ((n1, s1), (n2, s2)): ((u32, Span), (u32, Span)),
        (material, section): (Option<MaterialId>, SectionId),
        axis2: Option<(Vector3<f64>, Span)>,
        (divide, order, arc): (u32, u32, Option<(Vector3<f64>, Span)>),
        span: Span,
        id_span: Span,
    ) -> R<()> {
        for i in 0..=(last - first) {
            let overflow = || {
                DeckError::new(
                    K::BadGeneration {
                        first,
                        last,
                        reason: "generated node numbers exceed 4294967295".into(),
                    },
                    span,
                )
            };
            let a = n1.checked_add(i).ok_or_else(overflow)?;
            let b = n2.checked_add(i).ok_or_else(overflow)?;
            let id = first + i;
            let na = self.node_ref(a, s1)?;
            let nb = self.node_ref(b, s2)?;
            if a == b {
                return Err(DeckError::new(
                    K::BeamSameNode {
                        element: id,
                        node: a,
                    },
                    Span::new(s1.start, s2.end),
                ));
            }
            let (pa, pb) = match (self.nodes.get(&na), self.nodes.get(&nb)) {
                (Some(x), Some(y)) => (x.position, y.position),
                _ => continue,
            };
            let d = pb - pa;
            if d.norm() == 0.0 {
                return Err(DeckError::new(
                    K::BeamZeroLength {
                        element: id,
                        first: a,
                        second: b,
                    },
                    Span::new(s1.start, s2.end),
                ));
            }
            if let Some((ax, axs)) = axis2
                && ax.cross(&d).norm() <= 1e-6 * d.norm() * ax.norm()
            {
                return Err(DeckError::new(K::Axis2Parallel { element: id }, axs));
            }
            if let Some((centre, cs)) = arc {
                let reason = match crate::model::arc::Arc::new(&pa, &pb, &centre) {
                    Err(e) => Some(e.to_string()),
                    // AXIS2 must cross the arc everywhere.
                    Ok(a) if axis2.is_some_and(|(ax, _)| a.meets_tangent(&ax)) => {
                        Some("AXIS2 is parallel to the arc's tangent somewhere on it".to_string())
                    }
                    Ok(_) => None,
                };
                if let Some(reason) = reason {
                    return Err(DeckError::new(
                        K::BadArc {
                            element: id,
                            reason,
                        },
                        cs,
                    ));
                }
            }
            self.add_element(
                id,
                vec![na, nb],
                ElementKind::Beam {
                    material,
                    section,
                    axis2: axis2.map(|a| a.0),
                    order,
                    arc: arc.map(|a| a.0),
                },
                span,
                id_span,
            );
            if divide > 1 {
                self.divide.push((ElementId(id), divide, span));
            }
        }
        Ok(())
    }
}
