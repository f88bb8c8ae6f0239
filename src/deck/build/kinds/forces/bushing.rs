//! `BUSHING <n1> <n2> K kx ky kz krx kry krz [C …] [AXES e1 e2]`: a six-component linear
//! bushing in a frame fixed to its first node (issue 25 §3).

use super::super::{Card, Parse, Parsed, node_list, row};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use crate::model::BushingData;
use std::fmt::Write;

/// The deck half of `BUSHING`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["BUSHING"],
    rows: &[
        row(
            "BUSHING",
            "six-component linear bushing in a frame fixed to its first node",
        ),
        row("AXES", "BUSHING: axes e1 e2 of its frame, global at t = 0"),
    ],
    parse: Parse::One(parse),
    write,
};

/// `BUSHING <n1> <n2> K kx ky kz krx kry krz [C cx cy cz crx cry crz] [AXES e1 e2]`.
fn parse(_: &mut Builder<'_>, c: &mut Cursor<'_, '_>, _: u32, _: &str) -> R<Parsed> {
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

fn write(_: &Model, e: &Element, s: &mut String) {
    s.push_str(&node_list(e));
    let ElementKind::Bushing(b) = &e.kind else {
        return;
    };
    let six = |v: &[f64; 6]| v.map(|x| format!("{x:?}")).join(" ");
    let _ = write!(s, " K {} C {}", six(&b.stiffness), six(&b.damping));
    if b.axes != Matrix3::identity() {
        let col = |i: usize| super::super::v3(&b.axes.column(i).into_owned());
        let _ = write!(s, " AXES {} {}", col(0), col(1));
    }
}
