//! `RSPRING <hinge> [K k] [C c] [THETA0 θ0] [FRICTION Tf] [WREG ω]`: a rotational spring,
//! damper and friction on a HINGE's angle (issue 25 §3).

use super::super::{Card, Parse, Parsed, node_list, row};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use crate::model::RSpringData;
use std::fmt::Write;

/// The deck half of `RSPRING`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["RSPRING"],
    rows: &[
        row(
            "RSPRING",
            "rotational spring, damper and friction on a HINGE element",
        ),
        row("THETA0", "RSPRING: unloaded angle, rad (default 0)"),
        row("FRICTION", "RSPRING: Coulomb friction torque, N·m (>= 0)"),
        row(
            "WREG",
            "RSPRING: friction regularisation speed, rad/s (> 0, default 1e-3)",
        ),
    ],
    parse: Parse::One(parse),
    write,
};

/// `RSPRING <hinge> [K k] [C c] [THETA0 θ0] [FRICTION Tf] [WREG ω]`; the hinge is
/// resolved once every element is read (`Builder::resolve_hinges`).
fn parse(b: &mut Builder<'_>, c: &mut Cursor<'_, '_>, id: u32, _: &str) -> R<Parsed> {
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
                d.friction_speed = c.number_in("WREG (friction speed)", "> 0 rad/s", |v| v > 0.0)?
            }
        }
    }
    b.hinge_refs.push((ElementId(id), hinge, hs));
    Ok((Vec::new(), ElementKind::RSpring(Box::new(d))))
}

fn write(_: &Model, e: &Element, s: &mut String) {
    // Its nodes are its hinge's: the card names the hinge.
    let ElementKind::RSpring(r) = &e.kind else {
        s.push_str(&node_list(e));
        return;
    };
    let _ = write!(
        s,
        "{} K {:?} C {:?} THETA0 {:?} FRICTION {:?} WREG {:?}",
        r.hinge.0, r.stiffness, r.damping, r.angle0, r.friction, r.friction_speed
    );
}
