//! Stage 2 (meaning): cards → [`Model`]. References resolved, defaults applied,
//! every value checked; all errors are gathered.

use super::cards::{Card, Section};
use super::error::{DeckError, DeckErrorKind as K, line_col};
use super::lex::Token;
use crate::model::{
    Adaptive, Analysis, CameData, Element, ElementId, ElementKind, Fixity, Function, FunctionDef,
    FunctionId, InitialVelocity, Material, MaterialId, Model, NewtonSettings, NodalLoad, Node,
    NodeId, OutputRequest, PlacedProfile, Profile, Section as Sec, SectionId, Selection, Span,
};
use indexmap::IndexMap;
use nalgebra::{Matrix3, Vector3};

type R<T> = Result<T, DeckError>;

/// Normalises `v`; `None` when zero or not finite. A vector already of unit length (to
/// 1e-12) is kept as written so that writing and re-reading a model is exact.
pub(crate) fn unit(v: Vector3<f64>) -> Option<Vector3<f64>> {
    let n = v.norm();
    if !n.is_finite() || n == 0.0 || !v.iter().all(|c| c.is_finite()) {
        return None;
    }
    if (n - 1.0).abs() <= 1e-12 {
        Some(v)
    } else {
        Some(v / n)
    }
}

/// A read-only walk over the tokens of one card.
struct Cursor<'t, 'a> {
    toks: &'t [Token<'a>],
    pos: usize,
    ctx: String,
}

impl<'t, 'a> Cursor<'t, 'a> {
    fn new(card: &'t Card<'a>, ctx: impl Into<String>) -> Self {
        Cursor {
            toks: &card.tokens,
            pos: 0,
            ctx: ctx.into(),
        }
    }

    fn peek(&self) -> Option<&'t Token<'a>> {
        self.toks.get(self.pos)
    }

    /// An empty span just after the card's last token.
    fn end_span(&self) -> Span {
        let e = self.toks.last().map_or(0, |t| t.span.end);
        Span::new(e, e)
    }

    fn missing(&self, what: &str) -> DeckError {
        DeckError::new(
            K::MissingField {
                expected: format!("{what} in {}", self.ctx),
            },
            self.end_span(),
        )
    }

    fn next(&mut self, what: &str) -> R<&'t Token<'a>> {
        let t = self.toks.get(self.pos).ok_or_else(|| self.missing(what))?;
        self.pos += 1;
        Ok(t)
    }

    fn skip(&mut self) {
        self.pos += 1;
    }

    /// A finite number.
    fn number(&mut self, what: &str) -> R<(f64, Span, &'a str)> {
        let t = self.next(what)?;
        match t.number {
            Some(v) if v.is_finite() => Ok((v, t.span, t.text)),
            Some(_) => Err(DeckError::new(
                K::NonFinite {
                    expected: what.to_string(),
                    found: t.text.to_string(),
                },
                t.span,
            )),
            None => Err(DeckError::new(
                K::ExpectedNumber {
                    expected: what.to_string(),
                    found: t.text.to_string(),
                },
                t.span,
            )),
        }
    }

    /// A number, checked by `ok`, else an [`K::OutOfRange`] error stating `range`.
    fn number_in(&mut self, what: &str, range: &str, ok: impl Fn(f64) -> bool) -> R<f64> {
        let (v, span, text) = self.number(what)?;
        if ok(v) {
            Ok(v)
        } else {
            Err(out_of_range(what, text, range, span))
        }
    }

    /// A whole number in `0..=u32::MAX`.
    fn uint(&mut self, what: &str) -> R<(u32, Span)> {
        let t = self.next(what)?;
        let digits = t.text.strip_prefix('+').unwrap_or(t.text);
        let ok = !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit());
        match digits.parse::<u32>() {
            Ok(v) if ok => Ok((v, t.span)),
            _ => Err(DeckError::new(
                K::ExpectedInteger {
                    expected: what.to_string(),
                    found: t.text.to_string(),
                },
                t.span,
            )),
        }
    }

    fn next_is_number(&self) -> bool {
        self.peek().is_some_and(|t| t.number.is_some())
    }

    fn vec3(&mut self, what: &str) -> R<(Vector3<f64>, Span, [&'a str; 3])> {
        let (x, s0, tx) = self.number(&format!("{what} x component"))?;
        let (y, _, ty) = self.number(&format!("{what} y component"))?;
        let (z, s1, tz) = self.number(&format!("{what} z component"))?;
        Ok((
            Vector3::new(x, y, z),
            Span::new(s0.start, s1.end),
            [tx, ty, tz],
        ))
    }

    /// A direction: a non-zero finite vector, normalised.
    fn axis(&mut self, what: &str) -> R<(Vector3<f64>, Vector3<f64>, Span)> {
        let (v, span, t) = self.vec3(what)?;
        match unit(v) {
            Some(u) => Ok((u, v, span)),
            None => Err(DeckError::new(
                K::BadAxis {
                    what: what.to_string(),
                    x: t[0].into(),
                    y: t[1].into(),
                    z: t[2].into(),
                },
                span,
            )),
        }
    }

    /// If the next token is one of `kws`, consumes it and returns the canonical keyword.
    fn keyword(&mut self, kws: &[&'static str]) -> Option<(&'static str, Span)> {
        let t = self.peek()?;
        let k = kws.iter().find(|k| t.is_kw(k))?;
        self.pos += 1;
        Some((k, t.span))
    }

    /// The next token must be one of `kws`.
    fn expect_keyword(&mut self, kws: &[&'static str], what: &str) -> R<(&'static str, Span)> {
        if let Some(k) = self.keyword(kws) {
            return Ok(k);
        }
        let t = self.next(what)?;
        Err(self.unexpected(t, what))
    }

    fn unexpected(&self, t: &Token<'_>, expected: &str) -> DeckError {
        DeckError::new(
            K::UnknownKeyword {
                found: t.text.to_string(),
                context: self.ctx.clone(),
                expected: expected.to_string(),
            },
            t.span,
        )
    }

    /// No tokens may remain.
    fn finish(&self) -> R<()> {
        match self.peek() {
            None => Ok(()),
            Some(t) => Err(DeckError::new(
                K::ExtraToken {
                    found: t.text.to_string(),
                    context: self.ctx.clone(),
                },
                t.span,
            )),
        }
    }
}

/// Most items one `a TO b` generation may produce: far beyond any model this solver can
/// run, and small enough that a typo (`2 TO 4294967295`) is an error, not an exhausted memory.
pub const MAX_GENERATION: u32 = 1_000_000;

fn generation_size(first: u32, last: u32, span: Span) -> R<()> {
    if last - first >= MAX_GENERATION {
        return Err(DeckError::new(
            K::BadGeneration {
                first,
                last,
                reason: format!(
                    "{} items, more than the {MAX_GENERATION} one generation may produce",
                    u64::from(last - first) + 1
                ),
            },
            span,
        ));
    }
    Ok(())
}

fn out_of_range(what: &str, text: &str, range: &str, span: Span) -> DeckError {
    DeckError::new(
        K::OutOfRange {
            field: what.to_string(),
            found: text.to_string(),
            range: range.to_string(),
        },
        span,
    )
}

/// Records keywords met in one card to reject repeats.
#[derive(Default)]
struct Seen(Vec<&'static str>);

impl Seen {
    fn add(&mut self, kw: &'static str, span: Span, ctx: &str) -> R<()> {
        if self.0.contains(&kw) {
            return Err(DeckError::new(
                K::RepeatedKeyword {
                    keyword: kw.to_string(),
                    context: ctx.to_string(),
                },
                span,
            ));
        }
        self.0.push(kw);
        Ok(())
    }
    fn has(&self, kw: &str) -> bool {
        self.0.contains(&kw)
    }
}

fn expected_list(kws: &[&str]) -> String {
    format!("one of {}", kws.join(", "))
}

/// Builds the model, collecting every error.
struct Builder<'s> {
    src: &'s str,
    errors: Vec<DeckError>,
    title: Option<(String, Span)>,
    materials: IndexMap<MaterialId, Material>,
    sections: IndexMap<SectionId, Sec>,
    functions: IndexMap<FunctionId, FunctionDef>,
    nodes: IndexMap<NodeId, Node>,
    elements: IndexMap<ElementId, Element>,
    loads: Vec<NodalLoad>,
    gravity: Option<(Vector3<f64>, Span)>,
    initial: Vec<InitialVelocity>,
    analysis: Option<(Analysis, Span)>,
    output: Option<(OutputRequest, Span)>,
}

impl<'s> Builder<'s> {
    fn line(&self, span: Span) -> usize {
        line_col(self.src, span.start).0
    }

    fn push<T>(&mut self, r: R<T>) -> Option<T> {
        match r {
            Ok(v) => Some(v),
            Err(e) => {
                self.errors.push(e);
                None
            }
        }
    }

    fn duplicate(&mut self, what: &'static str, id: u32, first: Span, span: Span) {
        let first_line = self.line(first);
        self.errors.push(DeckError::new(
            K::Duplicate {
                what,
                id,
                first_line,
            },
            span,
        ));
    }

    fn node_ref(&self, id: u32, span: Span) -> R<NodeId> {
        if self.nodes.contains_key(&NodeId(id)) {
            Ok(NodeId(id))
        } else {
            Err(DeckError::new(K::Undefined { what: "node", id }, span))
        }
    }

    fn function_ref(&self, id: u32, span: Span) -> R<FunctionId> {
        if self.functions.contains_key(&FunctionId(id)) {
            Ok(FunctionId(id))
        } else {
            Err(DeckError::new(
                K::Undefined {
                    what: "function",
                    id,
                },
                span,
            ))
        }
    }

    // ---------------------------------------------------------------- TITLE
    fn title(&mut self, card: &Card<'_>) {
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
    fn material(&mut self, card: &Card<'_>) -> R<()> {
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
    fn section(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "SECTIONS card");
        let (id, id_span) = c.uint("section number")?;
        c.ctx = format!("section {id}");
        let rigid = c.keyword(&["RIGID"]).is_some();
        let kws: &[&'static str] = if rigid {
            &["A", "I2", "I3", "J"]
        } else {
            &["A", "I2", "I3", "J", "K"]
        };
        let mut seen = Seen::default();
        let (mut a, mut i2, mut i3, mut j, mut k) = (None, None, None, None, 5.0 / 6.0);
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(kws) else {
                return Err(c.unexpected(t, &expected_list(kws)));
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
        if let Some(first) = self.sections.get(&SectionId(id)).map(|s| s.span) {
            self.duplicate("section", id, first, id_span);
            return Ok(());
        }
        self.sections.insert(
            SectionId(id),
            Sec {
                id: SectionId(id),
                area: a,
                i2,
                i3,
                torsion: j,
                shear_factor: k,
                rigid,
                span,
            },
        );
        Ok(())
    }

    // ---------------------------------------------------------------- FUNCTIONS
    fn function(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "FUNCTIONS card");
        let (id, id_span) = c.uint("function number")?;
        c.ctx = format!("function {id}");
        let (kw, _) = c.expect_keyword(
            &["TABLE", "CONSTANT", "HAVERSINE"],
            "TABLE, CONSTANT or HAVERSINE",
        )?;
        let function = if kw == "CONSTANT" {
            let (v, _, _) = c.number("the constant value")?;
            c.finish()?;
            Function::Constant(v)
        } else if kw == "HAVERSINE" {
            let (start, _, _) = c.number("the pulse's start time")?;
            let duration = c.number_in("the pulse's duration", "> 0 s", |v| v > 0.0)?;
            c.finish()?;
            Function::Haversine { start, duration }
        } else {
            let mut vals = Vec::new();
            while c.peek().is_some() {
                vals.push(c.number("a table value (t or f)")?);
            }
            if vals.is_empty() || vals.len() % 2 == 1 {
                return Err(DeckError::new(K::OddTable { count: vals.len() }, span));
            }
            for w in vals.chunks(2).collect::<Vec<_>>().windows(2) {
                let (prev, cur) = (w[0][0], w[1][0]);
                if cur.0 < prev.0 {
                    return Err(DeckError::new(
                        K::DecreasingTime {
                            found: cur.2.to_string(),
                            previous: prev.2.to_string(),
                        },
                        cur.1,
                    ));
                }
            }
            Function::Table(vals.chunks(2).map(|p| (p[0].0, p[1].0)).collect())
        };
        if let Some(first) = self.functions.get(&FunctionId(id)).map(|f| f.span) {
            self.duplicate("function", id, first, id_span);
            return Ok(());
        }
        self.functions.insert(
            FunctionId(id),
            FunctionDef {
                id: FunctionId(id),
                function,
                span,
            },
        );
        Ok(())
    }

    // ---------------------------------------------------------------- NODES
    fn fix_dofs(c: &mut Cursor<'_, '_>, fixed: &mut Fixity) -> R<()> {
        const DOFS: [&str; 9] = ["ALL", "TRANS", "ROT", "X", "Y", "Z", "RX", "RY", "RZ"];
        let mut any = false;
        while let Some(t) = c.peek() {
            let Some((kw, _)) = c.keyword(&DOFS) else {
                return Err(c.unexpected(t, &expected_list(&DOFS)));
            };
            any = true;
            let range = match kw {
                "ALL" => 0..6,
                "TRANS" => 0..3,
                "ROT" => 3..6,
                "X" => 0..1,
                "Y" => 1..2,
                "Z" => 2..3,
                "RX" => 3..4,
                "RY" => 4..5,
                _ => 5..6,
            };
            for f in &mut fixed[range] {
                *f = true;
            }
        }
        if any {
            Ok(())
        } else {
            Err(c.missing("degrees of freedom after FIX (ALL, TRANS, ROT, X, Y, Z, RX, RY, RZ)"))
        }
    }

    fn add_node(&mut self, id: u32, position: Vector3<f64>, fixed: Fixity, span: Span, at: Span) {
        if let Some(first) = self.nodes.get(&NodeId(id)).map(|n| n.span) {
            self.duplicate("node", id, first, at);
            return;
        }
        self.nodes.insert(
            NodeId(id),
            Node {
                id: NodeId(id),
                position,
                fixed,
                span,
            },
        );
    }

    fn node(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "NODES card");
        let (id, id_span) = c.uint("node number")?;
        c.ctx = format!("node {id}");
        if c.keyword(&["TO"]).is_some() {
            let (last, last_span) = c.uint("last node number of the generation")?;
            c.ctx = format!("nodes {id} TO {last}");
            c.expect_keyword(&["LINE"], "LINE")?;
            let (p1, _, _) = c.vec3("first point")?;
            let (p2, _, _) = c.vec3("last point")?;
            let mut fixed = [false; 6];
            if c.keyword(&["FIX"]).is_some() {
                Self::fix_dofs(&mut c, &mut fixed)?;
            }
            c.finish()?;
            if last <= id {
                return Err(DeckError::new(
                    K::BadGeneration {
                        first: id,
                        last,
                        reason: "the last number must be greater than the first".into(),
                    },
                    Span::new(id_span.start, last_span.end),
                ));
            }
            generation_size(id, last, Span::new(id_span.start, last_span.end))?;
            let n = last - id;
            for i in 0..=n {
                let p = if i == 0 {
                    p1
                } else if i == n {
                    p2
                } else {
                    p1 + (p2 - p1) * (f64::from(i) / f64::from(n))
                };
                self.add_node(id + i, p, fixed, span, id_span);
            }
            return Ok(());
        }
        let (p, _, _) = c.vec3("coordinates")?;
        let mut fixed = [false; 6];
        if c.keyword(&["FIX"]).is_some() {
            Self::fix_dofs(&mut c, &mut fixed)?;
        }
        c.finish()?;
        self.add_node(id, p, fixed, span, id_span);
        Ok(())
    }

    fn fix_card(&mut self, card: &Card<'_>) -> R<()> {
        let mut c = Cursor::new(card, "FIX card");
        c.skip();
        let (id, id_span) = c.uint("node number")?;
        let node = self.node_ref(id, id_span)?;
        let mut fixed = [false; 6];
        Self::fix_dofs(&mut c, &mut fixed)?;
        if let Some(n) = self.nodes.get_mut(&node) {
            for (f, add) in n.fixed.iter_mut().zip(fixed) {
                *f |= add;
            }
        }
        Ok(())
    }

    // ---------------------------------------------------------------- ELEMENTS
    fn element(&mut self, card: &Card<'_>) -> R<()> {
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
            c.ctx = format!("elements {id} TO {l}");
            last = Some(l);
        }
        const TYPES: [&str; 9] = [
            "BEAM",
            "MASS",
            "HINGE",
            "UJOINT",
            "SPHERICAL",
            "CLAMP",
            "PRISMATIC",
            "RIGID",
            "CAME",
        ];
        let t = c.next("element type (BEAM, MASS, HINGE, ...)")?;
        let Some(ty) = TYPES.iter().find(|k| t.is_kw(k)).copied() else {
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
        let (nodes, kind): (Vec<(u32, Span)>, ElementKind) = match ty {
            "BEAM" => {
                let n1 = c.uint("first node number")?;
                let n2 = c.uint("second node number")?;
                let mut seen = Seen::default();
                let (mut mat, mut sec, mut axis2) = (None, None, None);
                const KW: [&str; 3] = ["MAT", "SEC", "AXIS2"];
                while let Some(t) = c.peek() {
                    let Some((kw, ks)) = c.keyword(&KW) else {
                        return Err(c.unexpected(t, &expected_list(&KW)));
                    };
                    seen.add(kw, ks, &c.ctx)?;
                    match kw {
                        "MAT" => mat = Some(c.uint("material number")?),
                        "SEC" => sec = Some(c.uint("section number")?),
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
                let (mat, ms) = mat.ok_or_else(|| miss("MAT <material number>"))?;
                let (sec, ss) = sec.ok_or_else(|| miss("SEC <section number>"))?;
                if !self.materials.contains_key(&MaterialId(mat)) {
                    return Err(DeckError::new(
                        K::Undefined {
                            what: "material",
                            id: mat,
                        },
                        ms,
                    ));
                }
                if !self.sections.contains_key(&SectionId(sec)) {
                    return Err(DeckError::new(
                        K::Undefined {
                            what: "section",
                            id: sec,
                        },
                        ss,
                    ));
                }
                return self.beams(
                    id,
                    last.unwrap_or(id),
                    (n1, n2),
                    (MaterialId(mat), SectionId(sec)),
                    axis2.map(|(u, _, s)| (u, s)),
                    span,
                    id_span,
                );
            }
            "MASS" => {
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
                        comp[0], comp[3], comp[4], comp[3], comp[1], comp[5], comp[4], comp[5],
                        comp[2],
                    );
                }
                c.finish()?;
                (vec![n], ElementKind::Mass { mass: m, inertia })
            }
            "HINGE" | "PRISMATIC" => {
                let n1 = c.uint("first node number")?;
                let n2 = c.uint("second node number")?;
                c.expect_keyword(&["AXIS"], "AXIS <x> <y> <z>")?;
                let (axis, _, _) = c.axis(&format!("{ty} AXIS"))?;
                c.finish()?;
                let kind = if ty == "HINGE" {
                    ElementKind::Hinge { axis }
                } else {
                    ElementKind::Prismatic { axis }
                };
                (vec![n1, n2], kind)
            }
            "UJOINT" => {
                let n1 = c.uint("first node number")?;
                let n2 = c.uint("second node number")?;
                c.expect_keyword(&["AXIS1"], "AXIS1 <x> <y> <z>")?;
                let (a1, r1, s1) = c.axis("UJOINT AXIS1")?;
                c.expect_keyword(&["AXIS2"], "AXIS2 <x> <y> <z>")?;
                let (a2, r2, s2) = c.axis("UJOINT AXIS2")?;
                c.finish()?;
                let dot = r1.dot(&r2).abs() / (r1.norm() * r2.norm());
                if dot.is_nan() || dot > 1e-6 {
                    return Err(DeckError::new(
                        K::UJointNotPerpendicular { element: id, dot },
                        Span::new(s1.start, s2.end),
                    ));
                }
                (
                    vec![n1, n2],
                    ElementKind::UJoint {
                        axis1: a1,
                        axis2: a2,
                    },
                )
            }
            "SPHERICAL" | "CLAMP" => {
                let n1 = c.uint("first node number")?;
                let n2 = c.uint("second node number")?;
                c.finish()?;
                let kind = if ty == "CLAMP" {
                    ElementKind::Clamp
                } else {
                    ElementKind::Spherical
                };
                (vec![n1, n2], kind)
            }
            "RIGID" => {
                let mut ns = vec![c.uint("master node number")?, c.uint("second node number")?];
                while c.peek().is_some() {
                    ns.push(c.uint("node number")?);
                }
                (ns, ElementKind::Rigid)
            }
            _ => {
                let cam = c.uint("cam node number")?;
                let fol = c.uint("follower node number")?;
                let data = Self::came(&mut c)?;
                (vec![cam, fol], ElementKind::Came(Box::new(data)))
            }
        };
        let mut ids = Vec::with_capacity(nodes.len());
        for (n, s) in nodes {
            ids.push(self.node_ref(n, s)?);
        }
        self.add_element(id, ids, kind, span, id_span);
        Ok(())
    }

    fn add_element(
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
    fn beams(
        &mut self,
        first: u32,
        last: u32,
        ((n1, s1), (n2, s2)): ((u32, Span), (u32, Span)),
        (material, section): (MaterialId, SectionId),
        axis2: Option<(Vector3<f64>, Span)>,
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
            self.add_element(
                id,
                vec![na, nb],
                ElementKind::Beam {
                    material,
                    section,
                    axis2: axis2.map(|a| a.0),
                },
                span,
                id_span,
            );
        }
        Ok(())
    }

    fn profile(c: &mut Cursor<'_, '_>, which: &str) -> R<PlacedProfile> {
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
                for _ in 0..n {
                    let (x, _, _) = c.number("SPLINE point x")?;
                    let (y, _, _) = c.number("SPLINE point y")?;
                    points.push([x, y]);
                }
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

    fn came(c: &mut Cursor<'_, '_>) -> R<CameData> {
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
        let (mut cam, mut fol, mut k) = (None, None, None);
        let (mut damping, mut mu, mut vreg, mut clip, mut steps) = (0.0, 0.0, 1e-3, true, 10);
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(&KW) else {
                return Err(c.unexpected(t, &expected_list(&KW)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "CAM" => cam = Some(Self::profile(c, "CAM")?),
                "FOLLOWER" => fol = Some(Self::profile(c, "FOLLOWER")?),
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
        Ok(CameData {
            stiffness: k.ok_or_else(|| miss("K <contact stiffness>"))?,
            damping,
            friction: mu,
            friction_speed: vreg,
            clip_tension: clip,
            impact_steps: steps,
            cam: cam.ok_or_else(|| miss("CAM <profile>"))?,
            follower: fol.ok_or_else(|| miss("FOLLOWER <profile>"))?,
        })
    }

    // ---------------------------------------------------------------- LOADS
    fn load(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "LOADS card");
        let (kw, ks) =
            c.expect_keyword(&["GRAVITY", "FORCE", "MOMENT"], "GRAVITY, FORCE or MOMENT")?;
        c.ctx = kw.to_string();
        if kw == "GRAVITY" {
            let (g, _, _) = c.vec3("GRAVITY")?;
            c.finish()?;
            if let Some((_, first)) = self.gravity {
                let first_line = self.line(first);
                return Err(DeckError::new(
                    K::RepeatedCard {
                        keyword: "GRAVITY".into(),
                        first_line,
                    },
                    ks,
                ));
            }
            self.gravity = Some((g, span));
            return Ok(());
        }
        let (n, ns) = c.uint("node number")?;
        let (value, _, _) = c.vec3(kw)?;
        let mut function = None;
        if c.keyword(&["FUNCTION"]).is_some() {
            let (f, fs) = c.uint("function number")?;
            function = Some(self.function_ref(f, fs)?);
        }
        c.finish()?;
        let node = self.node_ref(n, ns)?;
        self.loads.push(NodalLoad {
            node,
            moment: kw == "MOMENT",
            value,
            function,
            span,
        });
        Ok(())
    }

    // ---------------------------------------------------------------- INITIAL
    /// `<n> [TO <n2>] [V vx vy vz] [W wx wy wz] [ABOUT cx cy cz]`: with ABOUT, each node
    /// gets the rigid-body velocity `V + W × (x − c)`.
    fn initial(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "INITIAL card");
        let (first, fs) = c.uint("node number")?;
        let mut last = first;
        let mut last_span = fs;
        if c.keyword(&["TO"]).is_some() {
            (last, last_span) = c.uint("last node number")?;
            if last < first {
                return Err(DeckError::new(
                    K::BadGeneration {
                        first,
                        last,
                        reason: "the last number must not be smaller than the first".into(),
                    },
                    Span::new(fs.start, last_span.end),
                ));
            }
            generation_size(first, last, Span::new(fs.start, last_span.end))?;
        }
        let mut v = Vector3::zeros();
        let mut w = Vector3::zeros();
        let mut about = None;
        if c.keyword(&["V"]).is_some() {
            v = c.vec3("V")?.0;
        }
        if c.keyword(&["W"]).is_some() {
            w = c.vec3("W")?.0;
        }
        if c.keyword(&["ABOUT"]).is_some() {
            about = Some(c.vec3("ABOUT")?.0);
        }
        c.finish()?;
        for id in first..=last {
            let s = if id == first { fs } else { last_span };
            let node = self.node_ref(id, s)?;
            let x = self
                .nodes
                .get(&node)
                .map_or_else(Vector3::zeros, |n| n.position);
            let vel = match about {
                Some(c0) => v + w.cross(&(x - c0)),
                None => v,
            };
            self.initial.push(InitialVelocity {
                node,
                velocity: vel,
                angular: w,
                span,
            });
        }
        Ok(())
    }

    // ---------------------------------------------------------------- ANALYSIS
    fn analysis(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "ANALYSIS card");
        c.skip();
        let (kind, _) = c.expect_keyword(&["DYNAMIC", "STATIC"], "DYNAMIC or STATIC")?;
        c.ctx = format!("ANALYSIS {kind}");
        let kws: &[&'static str] = if kind == "DYNAMIC" {
            &[
                "ALPHA", "STEP", "END", "MINSTEP", "MAXSTEP", "ADAPTIVE", "TOLPOS", "TOLROT",
                "GROWTH", "TOL", "TOLINC", "MAXIT", "NEWTON",
            ]
        } else {
            &["STEPS", "TOL", "TOLINC", "MAXIT", "NEWTON"]
        };
        let mut seen = Seen::default();
        let mut newton = NewtonSettings::default();
        let mut alpha = -0.1;
        let (mut step, mut end, mut min, mut max) = (None, None, None, None);
        let (mut tolpos, mut tolrot, mut growth, mut steps) = (None, None, 2.0, 1);
        let mut adaptive = None;
        let pos = |v: f64| v > 0.0;
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(kws) else {
                return Err(c.unexpected(t, &expected_list(kws)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "ALPHA" => {
                    alpha = c.number_in("ALPHA (HHT)", "-1/3 <= alpha <= 0", |v| {
                        (-1.0 / 3.0 - 1e-12..=0.0).contains(&v)
                    })?
                }
                "STEP" => step = Some(c.number("STEP (time step)")?),
                "END" => end = Some(c.number_in("END (end time)", "> 0 s", pos)?),
                "MINSTEP" => min = Some(c.number("MINSTEP (smallest step)")?),
                "MAXSTEP" => max = Some(c.number("MAXSTEP (largest step)")?),
                "ADAPTIVE" => adaptive = Some(ks),
                "TOLPOS" => tolpos = Some(c.number_in("TOLPOS", "> 0 m", pos)?),
                "TOLROT" => tolrot = Some(c.number_in("TOLROT", "> 0 rad", pos)?),
                "GROWTH" => growth = c.number_in("GROWTH", ">= 1", |v| v >= 1.0)?,
                "TOL" => newton.tol_residual = c.number_in("TOL", "> 0", pos)?,
                "TOLINC" => newton.tol_increment = c.number_in("TOLINC", "> 0", pos)?,
                "MAXIT" => {
                    let (n, s) = c.uint("MAXIT")?;
                    if n < 1 {
                        return Err(out_of_range("MAXIT", "0", ">= 1", s));
                    }
                    newton.max_iterations = n;
                }
                "NEWTON" => {
                    let (v, _) = c.expect_keyword(&["FULL", "MODIFIED"], "FULL or MODIFIED")?;
                    newton.modified = v == "MODIFIED";
                }
                _ => {
                    let (n, s) = c.uint("STEPS")?;
                    if n < 1 {
                        return Err(out_of_range("STEPS", "0", ">= 1", s));
                    }
                    steps = n;
                }
            }
        }
        let analysis = if kind == "STATIC" {
            Analysis::Static { steps, newton }
        } else {
            let miss = |what: &str| {
                DeckError::new(
                    K::MissingKeyword {
                        context: c.ctx.clone(),
                        expected: what.into(),
                    },
                    c.end_span(),
                )
            };
            let (h, hs, ht) = step.ok_or_else(|| miss("STEP <time step>"))?;
            if h <= 0.0 {
                return Err(out_of_range("STEP (time step)", ht, "> 0 s", hs));
            }
            let end = end.ok_or_else(|| miss("END <end time>"))?;
            let min_step = match min {
                None => h / 1024.0,
                Some((v, s, t)) if v <= 0.0 || v > h => {
                    return Err(out_of_range("MINSTEP", t, "0 < MINSTEP <= STEP", s));
                }
                Some((v, _, _)) => v,
            };
            let max_step = match max {
                None => h,
                Some((v, s, t)) if v < h => {
                    return Err(out_of_range("MAXSTEP", t, "MAXSTEP >= STEP", s));
                }
                Some((v, _, _)) => v,
            };
            let adaptive = match (adaptive, tolpos, tolrot) {
                (Some(_), Some(p), Some(r)) => Some(Adaptive {
                    tol_position: p,
                    tol_rotation: r,
                    max_growth: growth,
                }),
                (Some(_), None, _) => return Err(miss("TOLPOS <m> after ADAPTIVE")),
                (Some(_), _, None) => return Err(miss("TOLROT <rad> after ADAPTIVE")),
                (None, _, _) => {
                    for kw in ["TOLPOS", "TOLROT", "GROWTH"] {
                        if seen.has(kw) {
                            return Err(DeckError::new(
                                K::MissingKeyword {
                                    context: format!("{kw} in {}", c.ctx),
                                    expected: "ADAPTIVE".into(),
                                },
                                c.end_span(),
                            ));
                        }
                    }
                    None
                }
            };
            Analysis::Dynamic {
                alpha,
                step: h,
                end,
                min_step,
                max_step,
                adaptive,
                newton,
            }
        };
        if let Some((_, first)) = self.analysis {
            let first_line = self.line(first);
            return Err(DeckError::new(
                K::RepeatedCard {
                    keyword: "ANALYSIS".into(),
                    first_line,
                },
                span,
            ));
        }
        self.analysis = Some((analysis, span));
        Ok(())
    }

    // ---------------------------------------------------------------- OUTPUT
    fn output(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "OUTPUT card");
        c.skip();
        const KW: [&str; 5] = ["NODES", "ELEMENTS", "EVERY", "DIR", "VTK"];
        let mut seen = Seen::default();
        let mut out = OutputRequest::default();
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(&KW) else {
                return Err(c.unexpected(t, &expected_list(&KW)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "NODES" | "ELEMENTS" => {
                    let what = if kw == "NODES" { "node" } else { "element" };
                    let sel = if c.keyword(&["ALL"]).is_some() {
                        Selection::All
                    } else if c.keyword(&["NONE"]).is_some() {
                        Selection::None
                    } else {
                        let mut ids = Vec::new();
                        while c.next_is_number() {
                            ids.push(c.uint(&format!("{what} number"))?);
                        }
                        if ids.is_empty() {
                            let e = format!("ALL, NONE or {what} numbers after {kw}");
                            return Err(match c.peek() {
                                Some(t) => c.unexpected(t, &e),
                                None => c.missing(&e),
                            });
                        }
                        Selection::List(ids)
                    };
                    match sel {
                        Selection::List(ids) if kw == "NODES" => {
                            let mut v = Vec::new();
                            for (id, s) in ids {
                                v.push(self.node_ref(id, s)?);
                            }
                            out.nodes = Selection::List(v);
                        }
                        Selection::List(ids) => {
                            let mut v = Vec::new();
                            for (id, s) in ids {
                                if !self.elements.contains_key(&ElementId(id)) {
                                    return Err(DeckError::new(
                                        K::Undefined {
                                            what: "element",
                                            id,
                                        },
                                        s,
                                    ));
                                }
                                v.push(ElementId(id));
                            }
                            out.elements = Selection::List(v);
                        }
                        Selection::All if kw == "NODES" => out.nodes = Selection::All,
                        Selection::All => out.elements = Selection::All,
                        Selection::None if kw == "NODES" => out.nodes = Selection::None,
                        Selection::None => out.elements = Selection::None,
                    }
                }
                "EVERY" => {
                    let (n, s) = c.uint("EVERY (output interval in steps)")?;
                    if n < 1 {
                        return Err(out_of_range("EVERY", "0", ">= 1", s));
                    }
                    out.every = n;
                }
                "DIR" => out.dir = Some(c.next("directory after DIR")?.text.to_string()),
                _ => out.vtk = true,
            }
        }
        if let Some((_, first)) = self.output {
            let first_line = self.line(first);
            return Err(DeckError::new(
                K::RepeatedCard {
                    keyword: "OUTPUT".into(),
                    first_line,
                },
                span,
            ));
        }
        self.output = Some((out, span));
        Ok(())
    }
}

fn conflict(first: &str, second: &str, ctx: &str, span: Span) -> DeckError {
    DeckError::new(
        K::Conflict {
            first: first.into(),
            second: second.into(),
            context: ctx.into(),
        },
        span,
    )
}

/// Stage 2: builds the model from the cards; `errors` already holds stage-1 errors.
/// Returns the model only when no error at all was found.
pub(crate) fn build_model(
    src: &str,
    cards: &[Card<'_>],
    errors: Vec<DeckError>,
    empty: bool,
) -> Result<Model, Vec<DeckError>> {
    let mut b = Builder {
        src,
        errors,
        title: None,
        materials: IndexMap::new(),
        sections: IndexMap::new(),
        functions: IndexMap::new(),
        nodes: IndexMap::new(),
        elements: IndexMap::new(),
        loads: Vec::new(),
        gravity: None,
        initial: Vec::new(),
        analysis: None,
        output: None,
    };
    let of = |s: Section| cards.iter().filter(move |c| c.section == s);
    // Definitions first (in dependency order), references after: a deck may list its
    // sections in any order.
    for c in of(Section::Title) {
        b.title(c);
    }
    for c in of(Section::Materials) {
        let r = b.material(c);
        b.push(r);
    }
    for c in of(Section::Sections) {
        let r = b.section(c);
        b.push(r);
    }
    for c in of(Section::Functions) {
        let r = b.function(c);
        b.push(r);
    }
    let is_fix = |c: &&Card<'_>| c.tokens.first().is_some_and(|t| t.is_kw("FIX"));
    for c in of(Section::Nodes).filter(|c| !is_fix(c)) {
        let r = b.node(c);
        b.push(r);
    }
    for c in of(Section::Nodes).filter(is_fix) {
        let r = b.fix_card(c);
        b.push(r);
    }
    for c in of(Section::Elements) {
        let r = b.element(c);
        b.push(r);
    }
    for c in of(Section::Loads) {
        let r = b.load(c);
        b.push(r);
    }
    for c in of(Section::Initial) {
        let r = b.initial(c);
        b.push(r);
    }
    for c in of(Section::Analysis) {
        let r = b.analysis(c);
        b.push(r);
    }
    for c in of(Section::Output) {
        let r = b.output(c);
        b.push(r);
    }
    let Some((analysis, _)) = b.analysis.take() else {
        let kind = if empty {
            K::EmptyDeck
        } else {
            K::MissingAnalysis
        };
        let at = if kind == K::EmptyDeck { 0 } else { src.len() };
        // The analysis may exist but be malformed: then its own error says so.
        let malformed = cards.iter().any(|c| c.section == Section::Analysis);
        if !malformed {
            b.errors.push(DeckError::new(kind, Span::new(at, at)));
        }
        return Err(b.errors);
    };
    if !b.errors.is_empty() {
        return Err(b.errors);
    }
    Ok(Model {
        title: b.title.map_or_else(|| "untitled".to_string(), |t| t.0),
        nodes: b.nodes,
        materials: b.materials,
        sections: b.sections,
        functions: b.functions,
        elements: b.elements,
        loads: b.loads,
        gravity: b.gravity.map(|g| g.0),
        initial: b.initial,
        analysis,
        output: b.output.map(|o| o.0).unwrap_or_default(),
    })
}
