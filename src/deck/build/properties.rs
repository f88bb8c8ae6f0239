//! Stage 2, definitions: TITLE, MATERIALS, SECTIONS (FUNCTIONS: `functions.rs`).

use super::cursor::*;
use super::section::section_properties;
use super::*;
use crate::model::{Geometry, SectionData};

impl Builder<'_> {
    // ---------------------------------------------------------------- TITLE
    pub(super) fn title(&mut self, card: &Card<'_>) {
        let span = card.span();
        if let Some((_, first)) = &self.title {
            let first_line = self.line(*first);
            self.errors.push(DeckError::new(
                K::RepeatedCard {
                    keyword: "TITLE".into(),
                    first_line,
                },
                span,
            ));
            return;
        }
        let text = match (card.tokens.get(1), card.tokens.last()) {
            (Some(a), Some(b)) if card.tokens.len() > 1 => {
                let raw = self.src.get(a.span.start..b.span.end).unwrap_or("");
                if raw.contains('\n') {
                    let words: Vec<&str> = card.tokens[1..].iter().map(|t| t.text).collect();
                    words.join(" ")
                } else {
                    raw.to_string()
                }
            }
            _ => String::new(),
        };
        self.title = Some((text, span));
    }

    // ---------------------------------------------------------------- MATERIALS
    pub(super) fn material(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "MATERIALS card");
        let (id, id_span) = c.uint("material number")?;
        c.ctx = format!("material {id}");
        const KW: [&str; 5] = ["E", "NU", "G", "RHO", "DAMPING"];
        let mut seen = Seen::default();
        let (mut e, mut nu, mut g, mut rho, mut eta) = (None, None, None, None, 0.0);
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(&KW) else {
                return Err(c.unexpected(t, &expected_list(&KW)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "E" => e = Some(c.number_in("E (Young's modulus)", "> 0 N/m²", |v| v > 0.0)?),
                "NU" => {
                    if seen.has("G") {
                        return Err(conflict("G", "NU", &c.ctx, ks));
                    }
                    nu = Some(c.number_in("NU (Poisson's ratio)", "-1 < nu < 0.5", |v| {
                        v > -1.0 && v < 0.5
                    })?)
                }
                "G" => {
                    if seen.has("NU") {
                        return Err(conflict("NU", "G", &c.ctx, ks));
                    }
                    g = Some(c.number_in("G (shear modulus)", "> 0 N/m²", |v| v > 0.0)?)
                }
                "RHO" => rho = Some(c.number_in("RHO (density)", ">= 0 kg/m³", |v| v >= 0.0)?),
                _ => {
                    eta = c.number_in("DAMPING (stiffness-proportional)", ">= 0 s", |v| v >= 0.0)?
                }
            }
        }
        let missing = |what: &str| {
            DeckError::new(
                K::MissingKeyword {
                    context: format!("material {id}"),
                    expected: what.to_string(),
                },
                c.end_span(),
            )
        };
        let e = e.ok_or_else(|| missing("E <Young's modulus>"))?;
        let rho = rho.ok_or_else(|| missing("RHO <density>"))?;
        let shear = match (nu, g) {
            (_, Some(g)) => g,
            (Some(nu), None) => e / (2.0 * (1.0 + nu)),
            (None, None) => return Err(missing("NU <Poisson's ratio> or G <shear modulus>")),
        };
        if let Some(first) = self.materials.get(&MaterialId(id)).map(|m| m.span) {
            self.duplicate("material", id, first, id_span);
            return Ok(());
        }
        self.materials.insert(
            MaterialId(id),
            Material {
                id: MaterialId(id),
                young: e,
                shear,
                density: rho,
                damping: eta,
                span,
            },
        );
        Ok(())
    }

    // ---------------------------------------------------------------- SECTIONS
    pub(super) fn section(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "SECTIONS card");
        let (id, id_span) = c.uint("section number")?;
        c.ctx = format!("section {id}");
        let rigid = c.keyword(&["RIGID"]).is_some();
        if c.keyword(&["PROPERTIES"]).is_some() {
            let data = section_properties(&mut c, id, rigid)?;
            self.add_section(id, id_span, data, rigid, span);
            return Ok(());
        }
        let kws: &[&'static str] = if rigid {
            &["A", "I2", "I3", "J"]
        } else {
            &["A", "I2", "I3", "J", "K"]
        };
        let mut seen = Seen::default();
        let (mut a, mut i2, mut i3, mut j, mut k) = (None, None, None, None, 5.0 / 6.0);
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(kws) else {
                let also = if seen.0.is_empty() {
                    " or PROPERTIES"
                } else {
                    ""
                };
                return Err(c.unexpected(t, &format!("{}{also}", expected_list(kws))));
            };
            seen.add(kw, ks, &c.ctx)?;
            let (range, ok): (&str, fn(f64) -> bool) = match (kw, rigid) {
                ("A", _) => ("> 0 m²", |v| v > 0.0),
                ("K", _) => ("0 < k <= 1", |v| v > 0.0 && v <= 1.0),
                (_, true) => (">= 0 m⁴", |v| v >= 0.0),
                _ => ("> 0 m⁴", |v| v > 0.0),
            };
            let v = c.number_in(kw, range, ok)?;
            match kw {
                "A" => a = Some(v),
                "I2" => i2 = Some(v),
                "I3" => i3 = Some(v),
                "J" => j = Some(v),
                _ => k = v,
            }
        }
        let missing = |what: &str| {
            DeckError::new(
                K::MissingKeyword {
                    context: format!("section {id}"),
                    expected: what.to_string(),
                },
                c.end_span(),
            )
        };
        let a = a.ok_or_else(|| missing("A <area>"))?;
        let (i2, i3, j) = if rigid {
            (i2.unwrap_or(0.0), i3.unwrap_or(0.0), j.unwrap_or(0.0))
        } else {
            (
                i2.ok_or_else(|| missing("I2 <second moment>"))?,
                i3.ok_or_else(|| missing("I3 <second moment>"))?,
                j.ok_or_else(|| missing("J <torsion constant>"))?,
            )
        };
        let geometry = Geometry {
            area: a,
            i2,
            i3,
            torsion: j,
            shear_factor: k,
        };
        self.add_section(id, id_span, SectionData::Geometry(geometry), rigid, span);
        Ok(())
    }
}
