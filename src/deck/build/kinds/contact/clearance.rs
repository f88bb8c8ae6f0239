//! `CLEARANCE <bearing> <journal> AXIS … RADIUS … CLEARANCE … LAW …`: a revolute joint
//! with radial clearance (grammar.md, "Elements").

use super::super::v3;
use super::super::{Card, Parse, row};
use crate::deck::build::cursor::*;
use crate::deck::build::*;
use crate::model::{ClearanceData, ContactLaw};
use std::fmt::Write;

/// The deck half of `CLEARANCE`.
pub(in crate::deck::build) const CARD: Card = Card {
    types: &["CLEARANCE"],
    rows: &[
        row(
            "CLEARANCE",
            "revolute joint with radial clearance (element type; and its clearance, m)",
        ),
        row("RADIUS", "CLEARANCE: bearing radius, m"),
        row("KV", "CLEARANCE LAW: Kelvin–Voigt k c"),
        row(
            "LN",
            "CLEARANCE LAW: Lankarani–Nikravesh K e (Hertz with hysteresis damping)",
        ),
        row(
            "EXPONENT",
            "CLEARANCE LAW LN: Hertz exponent n (> 0, default 1.5)",
        ),
        row(
            "VMIN",
            "CLEARANCE LAW LN: least approach speed, m/s (> 0, default 1e-4)",
        ),
    ],
    parse: Parse::One(|_, c, _, _| {
        let bearing = c.uint("bearing node number")?;
        let journal = c.uint("journal node number")?;
        let data = Builder::clearance(c)?;
        Ok((
            vec![bearing, journal],
            ElementKind::Clearance(Box::new(data)),
        ))
    }),
    write,
};

fn write(_: &Model, e: &Element, s: &mut String) {
    s.push_str(&super::super::node_list(e));
    let ElementKind::Clearance(c) = &e.kind else {
        return;
    };
    let law = match c.law {
        ContactLaw::KelvinVoigt { k, c } => format!("KV {k:?} {c:?}"),
        ContactLaw::LankaraniNikravesh {
            k,
            exponent,
            restitution,
        } => format!("LN {k:?} {restitution:?} EXPONENT {exponent:?}"),
    };
    let _ = write!(
        s,
        " AXIS {} RADIUS {:?} CLEARANCE {:?} LAW {law} MU {:?} VREG {:?} VMIN {:?} IMPACT_STEPS {}",
        v3(&c.axis),
        c.radius,
        c.clearance,
        c.friction,
        c.friction_speed,
        c.min_approach,
        c.impact_steps
    );
}

impl Builder<'_> {
    /// `CLEARANCE <bearing> <journal> AXIS x y z RADIUS R CLEARANCE c LAW (KV k c | LN K e
    /// [EXPONENT n]) [MU μ] [VREG v] [VMIN v] [IMPACT_STEPS n]`, keywords in any order.
    fn clearance(c: &mut Cursor<'_, '_>) -> R<ClearanceData> {
        const KW: [&str; 9] = [
            "AXIS",
            "RADIUS",
            "CLEARANCE",
            "LAW",
            "EXPONENT",
            "MU",
            "VREG",
            "VMIN",
            "IMPACT_STEPS",
        ];
        let mut seen = Seen::default();
        let (mut axis, mut radius, mut clearance, mut law) = (None, None, None, None);
        let (mut exponent, mut mu, mut vreg, mut vmin, mut steps) = (None, 0.0, 1e-3, 1e-4, 10);
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(&KW) else {
                return Err(c.unexpected(t, &expected_list(&KW)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "AXIS" => axis = Some(c.axis("CLEARANCE AXIS")?.0),
                "RADIUS" => {
                    radius = Some(c.number_in("RADIUS (bearing radius)", "> 0 m", |v| v > 0.0)?)
                }
                "CLEARANCE" => {
                    let (v, s, t) = c.number("CLEARANCE (radial clearance)")?;
                    clearance = Some((v, s, t));
                }
                "LAW" => {
                    let (ty, _) = c.expect_keyword(&["KV", "LN"], "KV or LN after LAW")?;
                    law = Some(if ty == "KV" {
                        let k = c.number_in("KV stiffness k", "> 0 N/m", |v| v > 0.0)?;
                        let d = c.number_in("KV damping c", ">= 0 N·s/m", |v| v >= 0.0)?;
                        ContactLaw::KelvinVoigt { k, c: d }
                    } else {
                        let k = c.number_in("LN stiffness K", "> 0 N/m^n", |v| v > 0.0)?;
                        let e =
                            c.number_in("LN restitution e", "in (0, 1]", |v| v > 0.0 && v <= 1.0)?;
                        ContactLaw::LankaraniNikravesh {
                            k,
                            exponent: 1.5,
                            restitution: e,
                        }
                    });
                }
                "EXPONENT" => {
                    let (v, s, t) = c.number("EXPONENT (Hertz exponent n)")?;
                    if v <= 0.0 {
                        return Err(out_of_range("EXPONENT (Hertz exponent n)", t, "> 0", s));
                    }
                    exponent = Some((v, s, t.to_string(), ks));
                }
                "MU" => mu = c.number_in("MU (friction coefficient)", ">= 0", |v| v >= 0.0)?,
                "VREG" => vreg = c.number_in("VREG (friction speed)", "> 0 m/s", |v| v > 0.0)?,
                "VMIN" => {
                    vmin = c.number_in("VMIN (least approach speed)", "> 0 m/s", |v| v > 0.0)?
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
        let axis = axis.ok_or_else(|| miss("AXIS <x> <y> <z>"))?;
        let radius = radius.ok_or_else(|| miss("RADIUS <bearing radius>"))?;
        let (clr, cs, ct) = clearance.ok_or_else(|| miss("CLEARANCE <radial clearance>"))?;
        if !(clr > 0.0 && clr < radius) {
            let range = format!("> 0 m and < RADIUS ({radius:?} m)");
            return Err(out_of_range("CLEARANCE (radial clearance)", ct, &range, cs));
        }
        let mut law = law.ok_or_else(|| miss("LAW KV <k> <c> or LAW LN <K> <e>"))?;
        if let Some((n, ns, nt, kws)) = exponent {
            match &mut law {
                ContactLaw::LankaraniNikravesh { k, exponent, .. } => {
                    let (lo, hi) = exponent_range(*k, clr);
                    if !(n >= lo && n <= hi) {
                        let range = format!(
                            "in [{lo:.3}, {hi:.3}]: the range where K δⁿ and its slope n K δⁿ⁻¹ are normal doubles for every penetration δ from the gap's round-off ε·c to the clearance c (K = {k:e} N/mⁿ, c = {clr:e} m; beyond it the law underflows to no force or overflows)"
                        );
                        return Err(out_of_range("EXPONENT (Hertz exponent n)", &nt, &range, ns));
                    }
                    *exponent = n
                }
                ContactLaw::KelvinVoigt { .. } => {
                    return Err(DeckError::new(
                        K::UnknownKeyword {
                            found: "EXPONENT".into(),
                            context: c.ctx.clone(),
                            expected: "EXPONENT only with LAW LN (the KV law is linear)".into(),
                        },
                        kws,
                    ));
                }
            }
        }
        Ok(ClearanceData {
            axis,
            radius,
            clearance: clr,
            law,
            friction: mu,
            friction_speed: vreg,
            min_approach: vmin,
            impact_steps: steps,
        })
    }
}

/// The Hertz exponents `n` for which the law `K δⁿ` of a clearance `c` is a usable double:
/// over the penetrations `δ ∈ [δ₀, c]`, `δ₀ = ε c` (the round-off of the gap, a difference
/// of lengths of size `c`: a smaller penetration is noise), the force and its slope must be
/// normal (`≥ f64::MIN_POSITIVE`) and finite (`≤ f64::MAX`). With `δ < 1` (a clearance
/// below a metre) `K δⁿ` falls with `n` and is smallest at `δ₀`:
/// `n ≤ ln(K/MIN_POSITIVE)/ln(1/δ₀)`; its slope `n K δⁿ⁻¹` is largest at `δ₀` when `n < 1`:
/// `n ≥ 1 − ln(MAX/K)/ln(1/δ₀)`; with `c ≥ 1` the force at `c` must not overflow,
/// `n ≤ ln(MAX/K)/ln c`. (K = 6.6e10 N/m^1.5, c = 0.5 mm: n in [0, 16.8]; the issue's
/// `EXPONENT 1e308` let the journal 0.7 mm past its clearance with a force of 0.)
fn exponent_range(k: f64, c: f64) -> (f64, f64) {
    let d0 = f64::EPSILON * c;
    let (ln_min, ln_max) = (f64::MIN_POSITIVE.ln(), f64::MAX.ln());
    let mut hi = f64::INFINITY;
    let mut lo = 0.0f64;
    if d0 < 1.0 {
        let l = -d0.ln();
        hi = hi.min((k.ln() - ln_min) / l);
        lo = lo.max(1.0 - (ln_max - k.ln()) / l);
    }
    if c > 1.0 {
        hi = hi.min((ln_max - k.ln()) / c.ln());
    }
    (lo, hi)
}
