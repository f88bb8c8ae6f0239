//! `BEAM <n1> <n2> [MAT m] SEC s [AXIS2 x y z] [DIVIDE n] [ORDER p] [ARC x y z]`, and its
//! generation `<first> TO <last> BEAM …` (node numbers stepped by one per element): the
//! geometrically exact beam (`elements::beam`), straight or on a circular arc, divided
//! into `n` elements whose nodes are generated on the axis (`model::mesh`).

use super::super::{Card, Generation, Parse, row, v3};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use crate::model::order::MAX_ORDER;
use std::fmt::Write;

/// The deck half of `BEAM`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["BEAM"],
    rows: &[
        row(
            "BEAM",
            "geometrically exact beam (two nodes, or p + 1 with ORDER)",
        ),
        row(
            "MAT",
            "material number of a BEAM (none for a section of PROPERTIES)",
        ),
        row("SEC", "section number of a BEAM"),
        row(
            "DIVIDE",
            "BEAM: divide into n equal elements, nodes generated on the axis",
        ),
        row(
            "ORDER",
            "BEAM: polynomial order p, p - 1 nodes generated at the GLL points",
        ),
        row(
            "ARC",
            "BEAM: centre of the circular arc that is the reference axis",
        ),
    ],
    parse: Parse::Generates(parse),
    write,
};

/// Reads the card after `BEAM` and adds the beams `g.first ..= g.last`.
fn parse(b: &mut Builder<'_>, c: &mut Cursor<'_, '_>, g: &Generation) -> R<()> {
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
    b.node_ref(n1.0, n1.1)?;
    b.node_ref(n2.0, n2.1)?;
    let (sec, ss) = sec.ok_or_else(|| miss("SEC <section number>"))?;
    let Some(section) = b.sections.get(&SectionId(sec)) else {
        let what = "section";
        return Err(DeckError::new(K::Undefined { what, id: sec }, ss));
    };
    // A section of properties per unit length takes no material.
    let material = match (section.needs_material(), mat) {
        (true, None) => return Err(miss("MAT <material number>")),
        (true, Some((m, ms))) => {
            if !b.materials.contains_key(&MaterialId(m)) {
                let what = "material";
                return Err(DeckError::new(K::Undefined { what, id: m }, ms));
            }
            Some(MaterialId(m))
        }
        (false, None) => None,
        (false, Some((m, ms))) => {
            let (element, material, section) = (g.first, m, sec);
            let kind = K::MaterialNotUsed {
                element,
                material,
                section,
            };
            return Err(DeckError::new(kind, ms));
        }
    };
    beams(
        b,
        g,
        (n1, n2),
        (material, SectionId(sec)),
        axis2.map(|(u, _, s)| (u, s)),
        (divide.unwrap_or(1), order, arc),
    )
}

/// Adds the beams `g.first ..= g.last`, the `i`-th from node `n1 + i` to `n2 + i`, each
/// checked (distinct nodes, non-zero length, AXIS2 across the axis, a valid arc).
fn beams(
    b: &mut Builder<'_>,
    g: &Generation,
    ((n1, s1), (n2, s2)): ((u32, Span), (u32, Span)),
    (material, section): (Option<MaterialId>, SectionId),
    axis2: Option<(Vector3<f64>, Span)>,
    (divide, order, arc): (u32, u32, Option<(Vector3<f64>, Span)>),
) -> R<()> {
    let (first, last, span) = (g.first, g.last, g.span);
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
        let bn = n2.checked_add(i).ok_or_else(overflow)?;
        let id = first + i;
        let na = b.node_ref(a, s1)?;
        let nb = b.node_ref(bn, s2)?;
        if a == bn {
            return Err(DeckError::new(
                K::BeamSameNode {
                    element: id,
                    node: a,
                },
                Span::new(s1.start, s2.end),
            ));
        }
        let (pa, pb) = match (b.nodes.get(&na), b.nodes.get(&nb)) {
            (Some(x), Some(y)) => (x.position, y.position),
            _ => continue,
        };
        let d = pb - pa;
        if d.norm() == 0.0 {
            return Err(DeckError::new(
                K::BeamZeroLength {
                    element: id,
                    first: a,
                    second: bn,
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
        b.add_element(
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
            g.id_span,
        );
        if divide > 1 {
            b.divide.push((ElementId(id), divide, span));
        }
    }
    Ok(())
}

/// Writes a beam's card as `parse` reads it: its two end nodes (a divided beam's ends, or
/// a beam of order p's first and last nodes) and its fields.
fn write(model: &Model, e: &Element, s: &mut String) {
    let division = model.divisions.get(&e.id);
    let nodes: Vec<String> = match division {
        Some(d) => d.ends.iter().map(|n| n.0.to_string()).collect(),
        // A beam of order p lists its interior nodes between its ends.
        None if e.nodes.len() > 2 => [e.nodes[0], e.nodes[e.nodes.len() - 1]]
            .iter()
            .map(|n| n.0.to_string())
            .collect(),
        None => e.nodes.iter().map(|n| n.0.to_string()).collect(),
    };
    s.push_str(&nodes.join(" "));
    if let ElementKind::Beam {
        material,
        section,
        axis2,
        order,
        arc,
    } = &e.kind
    {
        if let Some(m) = material {
            let _ = write!(s, " MAT {}", m.0);
        }
        let _ = write!(s, " SEC {}", section.0);
        if let Some(a) = axis2 {
            let _ = write!(s, " AXIS2 {}", v3(a));
        }
        if let Some(d) = division {
            let _ = write!(s, " DIVIDE {}", d.count());
        }
        if *order > 1 {
            let _ = write!(s, " ORDER {order}");
        }
        if let Some(c) = arc {
            let _ = write!(s, " ARC {}", v3(c));
        }
    }
}
