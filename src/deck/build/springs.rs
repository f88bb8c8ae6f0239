//! Stage 2, ELEMENTS: the spring family of issue 25 §3 — `SPRING`, `BUSHING`, `RSPRING`
//! (grammar.md, "Springs, bushings and rotational springs").

use super::cursor::*;
use super::*;
use crate::model::{BushingData, RSpringData, SpringData, SpringLength};

/// What a spring card gives to the element loop: its nodes and kind.
type Parsed = (Vec<(u32, Span)>, ElementKind);

impl Builder<'_> {
    /// `SPRING <n1> <n2> [K k] [C c] [L0 l | PRELOAD p] [CURVE f]`.
    pub(super) fn spring_card(&self, c: &mut Cursor<'_, '_>, id: u32) -> R<Parsed> {
        let n1 = c.uint("first node number")?;
        let n2 = c.uint("second node number")?;
        const KW: [&str; 5] = ["K", "C", "L0", "PRELOAD", "CURVE"];
        let mut seen = Seen::default();
        let mut data = SpringData {
            stiffness: 0.0,
            damping: 0.0,
            length: SpringLength::Initial,
            curve: None,
        };
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(&KW) else {
                return Err(c.unexpected(t, &expected_list(&KW)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "K" => data.stiffness = c.number_in("K (stiffness)", ">= 0 N/m", |v| v >= 0.0)?,
                "C" => data.damping = c.number_in("C (damping)", ">= 0 N·s/m", |v| v >= 0.0)?,
                "L0" | "PRELOAD" => {
                    let other = if kw == "L0" { "PRELOAD" } else { "L0" };
                    if seen.has(other) {
                        return Err(conflict(other, kw, &c.ctx, ks));
                    }
                    data.length = if kw == "L0" {
                        SpringLength::Free(c.number_in("L0 (free length)", ">= 0 m", |v| v >= 0.0)?)
                    } else {
                        SpringLength::Preload(c.number("PRELOAD (tension at t = 0, N)")?.0)
                    };
                }
                _ => {
                    let (f, fs) = c.uint("CURVE (function number)")?;
                    data.curve = Some(self.function_ref(f, fs)?);
                }
            }
        }
        let (a, b) = (self.node_ref(n1.0, n1.1)?, self.node_ref(n2.0, n2.1)?);
        if let (Some(x), Some(y)) = (self.nodes.get(&a), self.nodes.get(&b))
            && x.position == y.position
            && n1.0 != n2.0
        {
            let reason = if matches!(data.length, SpringLength::Free(_)) {
                "its line of action is undefined at t = 0: the nodes must start apart"
            } else {
                "a spring of zero length with no free length given: move a node, or give L0 (the nodes must still start apart)"
            };
            return Err(DeckError::new(
                K::SpringZeroLength {
                    element: id,
                    first: n1.0,
                    second: n2.0,
                    reason,
                },
                Span::new(n1.1.start, n2.1.end),
            ));
        }
        Ok((vec![n1, n2], ElementKind::Spring(Box::new(data))))
    }

    /// `BUSHING <n1> <n2> K kx ky kz krx kry krz [C cx cy cz crx cry crz] [AXES e1 e2]`.
    pub(super) fn bushing_card(c: &mut Cursor<'_, '_>) -> R<Parsed> {
        let n1 = c.uint("first node number")?;
        let n2 = c.uint("second node number")?;
        const KW: [&str; 3] = ["K", "C", "AXES"];
        const NAMES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];
        let mut seen = Seen::default();
        let (mut k, mut damping, mut axes) = (None, [0.0; 6], Matrix3::identity());
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(&KW) else {
                return Err(c.unexpected(t, &expected_list(&KW)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "K" | "C" => {
                    let mut v = [0.0; 6];
                    for (i, name) in NAMES.iter().enumerate() {
                        let (what, unit) = if kw == "K" {
                            (
                                format!("K{name} (stiffness)"),
                                if i < 3 { ">= 0 N/m" } else { ">= 0 N·m/rad" },
                            )
                        } else {
                            (
                                format!("C{name} (damping)"),
                                if i < 3 {
                                    ">= 0 N·s/m"
                                } else {
                                    ">= 0 N·m·s/rad"
                                },
                            )
                        };
                        v[i] = c.number_in(&what, unit, |x| x >= 0.0)?;
                    }
                    if kw == "K" {
                        k = Some(v);
                    } else {
                        damping = v;
                    }
                }
                _ => {
                    let (e1, _, _) = c.axis("AXES e1")?;
                    let (e2, _, s2) = c.axis("AXES e2")?;
                    let d = e1.dot(&e2);
                    let e2 = if d.abs() <= 1e-12 { e2 } else { e2 - e1 * d };
                    let Some(e2) = unit(e2).filter(|v| v.cross(&e1).norm() > 1e-9) else {
                        return Err(out_of_range(
                            "AXES e2",
                            "a vector parallel to e1",
                            "a direction not parallel to e1",
                            Span::new(ks.start, s2.end),
                        ));
                    };
                    axes = Matrix3::from_columns(&[e1, e2, e1.cross(&e2)]);
                }
            }
        }
        let stiffness = k.ok_or_else(|| {
            DeckError::new(
                K::MissingKeyword {
                    context: c.ctx.clone(),
                    expected: "K <kx> <ky> <kz> <krx> <kry> <krz>".into(),
                },
                c.end_span(),
            )
        })?;
        let data = BushingData {
            stiffness,
            damping,
            axes,
        };
        Ok((vec![n1, n2], ElementKind::Bushing(Box::new(data))))
    }

    /// `RSPRING <hinge> [K k] [C c] [THETA0 θ0] [FRICTION Tf] [WREG ω]`; the hinge is
    /// resolved once every element is read ([`Builder::resolve_hinges`]).
    pub(super) fn rspring_card(&mut self, c: &mut Cursor<'_, '_>, id: u32) -> R<Parsed> {
        let (hinge, hs) = c.uint("HINGE element number")?;
        const KW: [&str; 5] = ["K", "C", "THETA0", "FRICTION", "WREG"];
        let mut seen = Seen::default();
        let mut d = RSpringData {
            hinge: ElementId(hinge),
            axis: Vector3::z(),
            stiffness: 0.0,
            damping: 0.0,
            angle0: 0.0,
            friction: 0.0,
            friction_speed: 1e-3,
        };
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(&KW) else {
                return Err(c.unexpected(t, &expected_list(&KW)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "K" => d.stiffness = c.number_in("K (stiffness)", ">= 0 N·m/rad", |v| v >= 0.0)?,
                "C" => d.damping = c.number_in("C (damping)", ">= 0 N·m·s/rad", |v| v >= 0.0)?,
                "THETA0" => d.angle0 = c.number("THETA0 (unloaded angle, rad)")?.0,
                "FRICTION" => {
                    d.friction = c.number_in("FRICTION (torque)", ">= 0 N·m", |v| v >= 0.0)?
                }
                _ => {
                    d.friction_speed =
                        c.number_in("WREG (friction speed)", "> 0 rad/s", |v| v > 0.0)?
                }
            }
        }
        self.hinge_refs.push((ElementId(id), hinge, hs));
        Ok((Vec::new(), ElementKind::RSpring(Box::new(d))))
    }

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
