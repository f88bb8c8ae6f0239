//! `MASS <node> M <m> [INERTIA Ixx Iyy Izz [Ixy Ixz Iyz]]`: a point mass with its rotary
//! inertia (grammar.md, "Elements").

use super::super::{Card, Parse, Parsed, node_list, row};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use std::fmt::Write;

/// The deck half of `MASS`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["MASS"],
    rows: &[
        row("MASS", "point mass with optional rotary inertia"),
        row("M", "mass of a MASS element, kg (>= 0)"),
        row(
            "INERTIA",
            "rotary inertia of a MASS, kg·m², global frame at t = 0",
        ),
    ],
    parse: Parse::One(parse),
    write,
};

fn parse(_: &mut Builder<'_>, c: &mut Cursor<'_, '_>, _: u32, _: &str) -> R<Parsed> {
    let n = c.uint("node number")?;
    c.expect_keyword(&["M"], "M <mass>")?;
    let (m, ms, mt) = c.number("M (mass)")?;
    if m < 0.0 {
        return Err(out_of_range("M (mass)", mt, ">= 0 kg", ms));
    }
    let mut inertia = Matrix3::zeros();
    if c.keyword(&["INERTIA"]).is_some() {
        let mut comp = [0.0; 6];
        let names = ["Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz"];
        for (k, name) in names.iter().enumerate() {
            if k == 3 && !c.next_is_number() {
                break;
            }
            let (v, s, t) = c.number(name)?;
            if k < 3 && v < 0.0 {
                return Err(out_of_range(name, t, ">= 0 kg·m²", s));
            }
            comp[k] = v;
        }
        inertia = Matrix3::new(
            comp[0], comp[3], comp[4], comp[3], comp[1], comp[5], comp[4], comp[5], comp[2],
        );
    }
    c.finish()?;
    Ok((vec![n], ElementKind::Mass { mass: m, inertia }))
}

fn write(_: &Model, e: &Element, s: &mut String) {
    s.push_str(&node_list(e));
    let ElementKind::Mass { mass, inertia } = &e.kind else {
        return;
    };
    let _ = write!(s, " M {mass:?}");
    if *inertia != Matrix3::zeros() {
        let i = inertia;
        let _ = write!(
            s,
            " INERTIA {:?} {:?} {:?}",
            i[(0, 0)],
            i[(1, 1)],
            i[(2, 2)]
        );
        if i[(0, 1)] != 0.0 || i[(0, 2)] != 0.0 || i[(1, 2)] != 0.0 {
            let _ = write!(s, " {:?} {:?} {:?}", i[(0, 1)], i[(0, 2)], i[(1, 2)]);
        }
    }
}
