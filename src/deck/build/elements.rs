//! Stage 2, ELEMENTS: beams, joints, masses, springs, contact (CAME) and profiles.

use super::checks::{came_profiles, same_node, spline_points};
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
        const TYPES: [&str; 6] = ["BEAM", "CAME", "PID", "CONTROL", "PRESCRIBED", "CLEARANCE"];
        let t = c.next("element type (BEAM, MASS, HINGE, ...)")?;
        let card = kinds::card(|k| t.is_kw(k));
        let old = TYPES.iter().find(|k| t.is_kw(k)).copied();
        let Some(ty) = card.map(|(_, ty)| ty).or(old) else {
            return Err(DeckError::new(
                K::UnknownElementType {
                    found: t.text.to_string(),
                },
                t.span,
            ));
        };
        if last.is_some() && ty != "BEAM" {
            return Err(c.unexpected(t, "BEAM (only beams can be generated with TO)"));
        }
        let (nodes, kind): (Vec<(u32, Span)>, ElementKind) = match (card, ty) {
            (Some((card, ty)), _) => (card.parse)(self, &mut c, id, ty)?,
            (None, "BEAM") => {
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
            (None, "PID") => self.pid_card(&mut c, id)?,
            (None, "CONTROL") => self.control_card(&mut c, id)?,
            (None, "PRESCRIBED") => {
                let (n, kind) = self.prescribed(&mut c)?;
                (vec![n], kind)
            }
            (None, "CLEARANCE") => {
                let bearing = c.uint("bearing node number")?;
                let journal = c.uint("journal node number")?;
                let data = Self::clearance(&mut c)?;
                (
                    vec![bearing, journal],
                    ElementKind::Clearance(Box::new(data)),
                )
            }
            (None, _) => {
                let cam = c.uint("cam node number")?;
                let fol = c.uint("follower node number")?;
                let data = Self::came(&mut c, id)?;
                (vec![cam, fol], ElementKind::Came(Box::new(data)))
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

    pub(super) fn profile(c: &mut Cursor<'_, '_>, which: &str) -> R<PlacedProfile> {
        const TYPES: [&str; 4] = ["LINE", "POINT", "CIRCLE", "SPLINE"];
        let (ty, _) =
            c.expect_keyword(&TYPES, &format!("a {which} profile ({})", TYPES.join(", ")))?;
        let ctx = format!("{which} profile");
        let profile = match ty {
            "LINE" => Profile::Line,
            "POINT" => Profile::Point,
            "CIRCLE" => Profile::Circle {
                radius: c.number_in("CIRCLE radius", "> 0 m", |v| v > 0.0)?,
            },
            _ => {
                let closed = c.keyword(&["CLOSED"]).is_some();
                let min = if closed { 3 } else { 2 };
                let t = c.peek();
                let (n, ns) = c.uint("number of SPLINE points")?;
                if (n as usize) < min {
                    let text = t.map_or("", |t| t.text);
                    let range = if closed {
                        ">= 3 points for a CLOSED spline"
                    } else {
                        ">= 2 points"
                    };
                    return Err(out_of_range("number of SPLINE points", text, range, ns));
                }
                let mut points = Vec::new();
                let mut spans = Vec::new();
                for _ in 0..n {
                    let (x, sx, _) = c.number("SPLINE point x")?;
                    let (y, sy, _) = c.number("SPLINE point y")?;
                    points.push([x, y]);
                    spans.push(Span::new(sx.start, sy.end));
                }
                spline_points(&points, &spans, closed)?;
                Profile::Spline { points, closed }
            }
        };
        let mut offset = Vector3::zeros();
        let mut frame = Matrix3::identity();
        let mut angle = None;
        let mut seen = Seen::default();
        let kws: &[&'static str] = if ty == "LINE" {
            &["OFFSET", "PLANE", "ANGLE"]
        } else {
            &["OFFSET", "PLANE"]
        };
        while let Some((kw, ks)) = c.keyword(kws) {
            seen.add(kw, ks, &ctx)?;
            match kw {
                "OFFSET" => offset = c.vec3("OFFSET")?.0,
                "ANGLE" => angle = Some(c.number("ANGLE (degrees)")?.0),
                _ => {
                    let (e1, _, _) = c.axis("PLANE e1")?;
                    let (e2, _, s2) = c.axis("PLANE e2")?;
                    let d = e1.dot(&e2);
                    let e2 = if d.abs() <= 1e-12 { e2 } else { e2 - e1 * d };
                    let e2 = unit(e2).filter(|v| v.cross(&e1).norm() > 1e-9);
                    let Some(e2) = e2 else {
                        return Err(DeckError::new(
                            K::PlaneParallel,
                            Span::new(ks.start, s2.end),
                        ));
                    };
                    frame = Matrix3::from_columns(&[e1, e2, e1.cross(&e2)]);
                }
            }
        }
        if let Some(deg) = angle {
            let (s, co) = deg.to_radians().sin_cos();
            let c1: Vector3<f64> = frame.column(0).into();
            let c2: Vector3<f64> = frame.column(1).into();
            let n1 = c1 * co + c2 * s;
            let n2 = c2 * co - c1 * s;
            frame = Matrix3::from_columns(&[n1, n2, n1.cross(&n2)]);
        }
        Ok(PlacedProfile {
            profile,
            offset,
            frame,
        })
    }

    pub(super) fn came(c: &mut Cursor<'_, '_>, id: u32) -> R<CameData> {
        const KW: [&str; 8] = [
            "CAM",
            "FOLLOWER",
            "K",
            "C",
            "MU",
            "VREG",
            "CLIP",
            "IMPACT_STEPS",
        ];
        let mut seen = Seen::default();
        let mut fol_span = c.end_span();
        let (mut cam, mut fol, mut k) = (None, None, None);
        let (mut damping, mut mu, mut vreg, mut clip, mut steps) = (0.0, 0.0, 1e-3, true, 10);
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(&KW) else {
                return Err(c.unexpected(t, &expected_list(&KW)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "CAM" => cam = Some(Self::profile(c, "CAM")?),
                "FOLLOWER" => {
                    fol_span = ks;
                    fol = Some(Self::profile(c, "FOLLOWER")?);
                }
                "K" => k = Some(c.number_in("K (contact stiffness)", "> 0 N/m", |v| v > 0.0)?),
                "C" => damping = c.number_in("C (contact damping)", ">= 0 N·s/m", |v| v >= 0.0)?,
                "MU" => mu = c.number_in("MU (friction coefficient)", ">= 0", |v| v >= 0.0)?,
                "VREG" => vreg = c.number_in("VREG (friction speed)", "> 0 m/s", |v| v > 0.0)?,
                "CLIP" => {
                    clip = c.expect_keyword(&["ON", "OFF"], "ON or OFF after CLIP")?.0 == "ON"
                }
                _ => {
                    let (n, s) = c.uint("IMPACT_STEPS")?;
                    if n < 1 {
                        return Err(out_of_range("IMPACT_STEPS", "0", ">= 1", s));
                    }
                    steps = n;
                }
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
        let (cam, fol) = (
            cam.ok_or_else(|| miss("CAM <profile>"))?,
            fol.ok_or_else(|| miss("FOLLOWER <profile>"))?,
        );
        came_profiles(id, &cam.profile, &fol.profile, fol_span)?;
        Ok(CameData {
            stiffness: k.ok_or_else(|| miss("K <contact stiffness>"))?,
            damping,
            friction: mu,
            friction_speed: vreg,
            clip_tension: clip,
            impact_steps: steps,
            cam,
            follower: fol,
        })
    }
}
