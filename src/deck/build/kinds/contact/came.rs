//! `CAME <cam> <follower> CAM <profile> FOLLOWER <profile> K <k> [C c] [MU μ] [VREG v]
//! [CLIP ON|OFF] [IMPACT_STEPS n]`: cam–follower contact between two profiles
//! (grammar.md, "Elements").

use super::super::v3;
use super::super::{Card, Parse, node_list, row};
use crate::deck::build::checks::{came_profiles, spline_points};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use std::fmt::Write;

/// The deck half of `CAME`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["CAME"],
    rows: &[
        row("CAME", "cam-follower contact element"),
        row("CAM", "CAME: the cam's profile (first node)"),
        row("FOLLOWER", "CAME: the follower's profile (second node)"),
        row("POINT", "CAME profile: a point"),
        row("CIRCLE", "CAME profile: a circle of given radius"),
        row("CLOSED", "CAME SPLINE: a closed (periodic) curve"),
        row("ANGLE", "CAME LINE: in-plane direction angle, degrees"),
        row("OFFSET", "CAME profile: origin offset in the node frame, m"),
        row(
            "PLANE",
            "CAME profile: plane vectors e1 e2 in the node frame",
        ),
        row(
            "CLIP",
            "CAME: clip the adhesive part of the contact force (ON/OFF)",
        ),
        row("ON", "CLIP ON"),
        row("OFF", "CLIP OFF"),
    ],
    parse: Parse::One(|_, c, id, _| {
        let cam = c.uint("cam node number")?;
        let fol = c.uint("follower node number")?;
        let data = came(c, id)?;
        Ok((vec![cam, fol], ElementKind::Came(Box::new(data))))
    }),
    write,
};

fn write(_: &Model, e: &Element, s: &mut String) {
    s.push_str(&node_list(e));
    let ElementKind::Came(c) = &e.kind else {
        return;
    };
    let _ = write!(
        s,
        " CAM {} FOLLOWER {} K {:?} C {:?} MU {:?} VREG {:?} CLIP {} IMPACT_STEPS {}",
        write_profile(&c.cam),
        write_profile(&c.follower),
        c.stiffness,
        c.damping,
        c.friction,
        c.friction_speed,
        if c.clip_tension { "ON" } else { "OFF" },
        c.impact_steps
    );
}

fn write_profile(p: &PlacedProfile) -> String {
    let mut s = match &p.profile {
        Profile::Line => "LINE".to_string(),
        Profile::Point => "POINT".to_string(),
        Profile::Circle { radius } => format!("CIRCLE {radius:?}"),
        Profile::Spline { points, closed } => {
            let mut s = String::from("SPLINE");
            if *closed {
                s.push_str(" CLOSED");
            }
            let _ = write!(s, " {}", points.len());
            for [x, y] in points {
                let _ = write!(s, " {x:?} {y:?}");
            }
            s
        }
    };
    if p.offset != Vector3::zeros() {
        let _ = write!(s, " OFFSET {}", v3(&p.offset));
    }
    if p.frame != Matrix3::identity() {
        let e1: Vector3<f64> = p.frame.column(0).into();
        let e2: Vector3<f64> = p.frame.column(1).into();
        let _ = write!(s, " PLANE {} {}", v3(&e1), v3(&e2));
    }
    s
}

fn profile(c: &mut Cursor<'_, '_>, which: &str) -> R<PlacedProfile> {
    const TYPES: [&str; 4] = ["LINE", "POINT", "CIRCLE", "SPLINE"];
    let (ty, _) = c.expect_keyword(&TYPES, &format!("a {which} profile ({})", TYPES.join(", ")))?;
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

fn came(c: &mut Cursor<'_, '_>, id: u32) -> R<CameData> {
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
            "CAM" => cam = Some(profile(c, "CAM")?),
            "FOLLOWER" => {
                fol_span = ks;
                fol = Some(profile(c, "FOLLOWER")?);
            }
            "K" => k = Some(c.number_in("K (contact stiffness)", "> 0 N/m", |v| v > 0.0)?),
            "C" => damping = c.number_in("C (contact damping)", ">= 0 N·s/m", |v| v >= 0.0)?,
            "MU" => mu = c.number_in("MU (friction coefficient)", ">= 0", |v| v >= 0.0)?,
            "VREG" => vreg = c.number_in("VREG (friction speed)", "> 0 m/s", |v| v > 0.0)?,
            "CLIP" => clip = c.expect_keyword(&["ON", "OFF"], "ON or OFF after CLIP")?.0 == "ON",
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
