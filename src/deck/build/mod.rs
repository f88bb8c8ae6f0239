//! Stage 2 (meaning): cards → [`Model`]. References resolved, defaults applied,
//! every value checked; all errors are gathered.

mod analysis;
mod checks;
mod control;
mod cursor;
mod drives;
mod elements;
mod functions;
mod kinds;
mod nodes;
mod properties;
mod section;
mod springs;

pub(super) use kinds::{rows, types, v3, write_element};

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
    /// `ANALYSIS MODES n`.
    modes: Option<u32>,
    /// `ANALYSIS MODES n ROTATING`.
    modes_rotating: bool,
    /// `ANALYSIS MODES n STATIC`.
    modes_static: bool,
    /// The `ANALYSIS MODES` card.
    modes_span: Span,
    output: Option<(OutputRequest, Span)>,
    /// Beams to divide (`DIVIDE n`, n > 1), in deck order, with their cards' spans.
    divide: Vec<(ElementId, u32, Span)>,
    /// RSPRING elements' hinges (element, hinge number, its span), resolved after ELEMENTS.
    hinge_refs: Vec<(ElementId, u32, Span)>,
    /// Driven joints (`DRIVE` on a HINGE or PRISMATIC card).
    drives: IndexMap<ElementId, crate::model::Drive>,
    /// The parameters in force (for the expressions of `t` of EXPR functions).
    parameters: IndexMap<String, f64>,
    /// Free nodal degrees of freedom of the nodes so far (the model's unknowns, for the
    /// memory a generation would take: [`Builder::fits`]).
    free_dofs: u64,
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
}

impl Builder<'_> {
    /// Whether `nodes` more free nodes and `elements` more elements fit in the memory the
    /// process may take (model::budget), checked before a generation (`a TO b`) makes
    /// them; else a located error with the figure.
    fn fits(&self, nodes: u64, elements: u64, first: u32, last: u32, span: Span) -> R<()> {
        let f = crate::model::budget::Footprint {
            nodes: self.nodes.len() as u64 + nodes,
            elements: self.elements.len() as u64 + elements,
            unknowns: self.free_dofs + 6 * nodes,
        };
        crate::model::budget::check(f, "the model with this generation").map_err(|e| {
            DeckError::new(
                K::ModelTooLarge {
                    request: format!("{first} TO {last}"),
                    reason: e.to_string(),
                },
                span,
            )
        })
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
    parameters: IndexMap<String, f64>,
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
        modes: None,
        modes_rotating: false,
        modes_static: false,
        modes_span: Span::default(),
        output: None,
        divide: Vec::new(),
        hinge_refs: Vec::new(),
        drives: IndexMap::new(),
        parameters,
        free_dofs: 0,
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
    b.resolve_hinges();
    b.check_drive_fights();
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
    b.check_functions(&analysis);
    b.check_controls(&analysis);
    if !b.errors.is_empty() {
        return Err(b.errors);
    }
    let mut model = Model {
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
        modes: b.modes,
        modes_rotating: b.modes_rotating,
        modes_static: b.modes_static,
        modes_span: b.modes_span,
        output: b.output.map(|o| o.0).unwrap_or_default(),
        divisions: IndexMap::new(),
        parameters: b.parameters,
        order_nodes: IndexMap::new(),
        drives: b.drives,
    };
    // Generated numbers start past every user number: divide once all are known, and
    // once the model they make is known to fit in memory (model::budget; located at the
    // largest DIVIDE).
    let list: Vec<(ElementId, u32)> = b.divide.iter().map(|(e, n, _)| (*e, *n)).collect();
    if let Err((i, e)) = model.divide_each(&list) {
        let (beam, n, span) = b.divide[i];
        let kind = match e {
            e @ (crate::model::MeshError::TooLarge(_)
            | crate::model::MeshError::OutOfMemory { .. }) => K::ModelTooLarge {
                request: format!("DIVIDE {n}"),
                reason: e.to_string(),
            },
            e => K::BadGeneration {
                first: beam.0,
                last: beam.0,
                reason: e.to_string(),
            },
        };
        return Err(vec![DeckError::new(kind, span)]);
    }
    let mut numbering = crate::model::Numbering::after(&model);
    // Interior nodes of beams of ORDER p, after the divisions' (model/order.rs). The arcs
    // were validated card by card: this cannot fail on a parsed deck, but says so if it does.
    // A generation that fails on a parsed deck has no card to point at.
    let unplaced = |reason: String| {
        vec![DeckError::new(
            K::BadGeneration {
                first: 0,
                last: 0,
                reason,
            },
            Span::default(),
        )]
    };
    model
        .raise_orders(&mut numbering)
        .map_err(|e| unplaced(e.to_string()))?;
    // The superelements' modal nodes, past every other number (model/superelement.rs).
    model
        .add_modal_nodes(&mut numbering)
        .map_err(|e| unplaced(e.to_string()))?;
    Ok(model)
}
