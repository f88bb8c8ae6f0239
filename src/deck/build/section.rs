//! Stage 2, SECTIONS given by their properties per unit length (`PROPERTIES`), and the
//! insertion of a section into the model.

use super::cursor::*;
use super::*;
use crate::model::{BeamProperties, SectionData};

/// The stiffness keywords of a `PROPERTIES` section: `C_N = (EA, GA2, GA3)`,
/// `C_M = (GJ, EI2, EI3)` (N, N·m²), each required and > 0 on a flexible section.
const STIFFNESS: [&str; 6] = ["EA", "GA2", "GA3", "GJ", "EI2", "EI3"];
/// The inertia keywords: `ρA` (kg/m) and `(ρJ, ρI2, ρI3)` (kg·m), each ≥ 0; required on a
/// flexible section, `RHOA` alone on a rigid one (the rotary inertias default to 0).
const INERTIA: [&str; 4] = ["RHOA", "RHOJ", "RHOI2", "RHOI3"];

/// Reads the fields after `<id> [RIGID] PROPERTIES`: every keyword of [`STIFFNESS`] and
/// [`INERTIA`] and an optional `DAMPING η` (s, ≥ 0) on a flexible section; `RHOA` and
/// optionally `RHOJ`, `RHOI2`, `RHOI3` on a rigid one (no stiffness: the bar keeps its
/// shape). Keywords in any order, each at most once.
pub(super) fn section_properties(c: &mut Cursor<'_, '_>, id: u32, rigid: bool) -> R<SectionData> {
    let kws: Vec<&'static str> = if rigid {
        INERTIA.to_vec()
    } else {
        STIFFNESS
            .iter()
            .chain(&INERTIA)
            .chain(&["DAMPING"])
            .copied()
            .collect()
    };
    let mut seen = Seen::default();
    let mut values = [None; 10];
    let mut damping = 0.0;
    while let Some(t) = c.peek() {
        let Some((kw, ks)) = c.keyword(&kws) else {
            return Err(c.unexpected(t, &expected_list(&kws)));
        };
        seen.add(kw, ks, &c.ctx)?;
        if kw == "DAMPING" {
            damping = c.number_in("DAMPING (stiffness-proportional)", ">= 0 s", |v| v >= 0.0)?;
        } else if let Some(i) = STIFFNESS.iter().position(|k| *k == kw) {
            let unit = if i < 3 { "> 0 N" } else { "> 0 N·m²" };
            values[i] = Some(c.number_in(kw, unit, |v| v > 0.0)?);
        } else {
            let i = INERTIA
                .iter()
                .position(|k| *k == kw)
                .expect("an inertia keyword");
            let unit = if i == 0 { ">= 0 kg/m" } else { ">= 0 kg·m" };
            values[6 + i] = Some(c.number_in(kw, unit, |v| v >= 0.0)?);
        }
    }
    let end = c.end_span();
    let missing = |kw: &str| {
        DeckError::new(
            K::MissingKeyword {
                context: format!("section {id}"),
                expected: format!("{kw} <value>"),
            },
            end,
        )
    };
    let names = STIFFNESS.iter().chain(&INERTIA);
    let mut v = [0.0; 10];
    for ((slot, given), kw) in v.iter_mut().zip(values).zip(names) {
        // A rigid section has no stiffness and its rotary inertias default to zero.
        let optional = rigid && *kw != "RHOA";
        *slot = match given {
            Some(x) => x,
            None if optional => 0.0,
            None => return Err(missing(kw)),
        };
    }
    Ok(SectionData::Properties {
        props: BeamProperties {
            cn: Vector3::new(v[0], v[1], v[2]),
            cm: Vector3::new(v[3], v[4], v[5]),
            mass: v[6],
            inertia: Vector3::new(v[7], v[8], v[9]),
        },
        damping,
    })
}

impl Builder<'_> {
    /// Adds section `id` to the model, or reports a duplicate number.
    pub(super) fn add_section(
        &mut self,
        id: u32,
        id_span: Span,
        data: SectionData,
        rigid: bool,
        span: Span,
    ) {
        if let Some(first) = self.sections.get(&SectionId(id)).map(|s| s.span) {
            self.duplicate("section", id, first, id_span);
            return;
        }
        let id = SectionId(id);
        let section = Sec {
            id,
            data,
            rigid,
            span,
        };
        self.sections.insert(id, section);
    }
}
