//! The deck halves of the element kinds (`crate::kinds`, the registry): one `CARD` per
//! kind, in `<family>/<kind>.rs` — the element types it reads, the keywords it documents,
//! the parse of its card and the canonical writer of it. The element loop
//! (`build/elements.rs`), the writer (`deck/write.rs`) and `KEYWORDS` go through [`CARDS`].

use super::cursor::Cursor;
use super::{Builder, R};
use crate::deck::KeywordDoc;
use crate::model::{Element, ElementKind, Model, Span};
use std::fmt::Write;

mod beams;
mod bodies;
mod contact;
mod forces;
mod joints;

/// What a card gives to the element loop: its nodes (numbers, spans) and kind.
pub(super) type Parsed = (Vec<(u32, Span)>, ElementKind);

/// The deck half of an element kind.
pub(super) struct Card {
    /// The element types it reads (the word after the element number), upper case.
    pub(super) types: &'static [&'static str],
    /// The keywords it alone uses, with their documentation: rows of `KEYWORDS` (section
    /// `ELEMENTS`), hence of `grammar.md`. Keywords several kinds share (`K`, `C`, `AXIS`,
    /// …) stay in `deck/keywords.rs`.
    pub(super) rows: &'static [KeywordDoc],
    /// Reads the card after its type word.
    pub(super) parse: Parse,
    /// Writes the card after `<number> <TYPE> `: its nodes and fields, as `parse` reads
    /// them back (`parse ∘ write = id`).
    pub(super) write: fn(&Model, &Element, &mut String),
}

/// How a card is read after its type word.
#[derive(Clone, Copy)]
pub(super) enum Parse {
    /// One element, `(builder, cursor, element number, type)` → its nodes and kind; the
    /// element loop checks and adds it. A `TO` generation is refused for it.
    One(fn(&mut Builder<'_>, &mut Cursor<'_, '_>, u32, &'static str) -> R<Parsed>),
    /// A card that adds its own elements: the `first TO last` generation (`last = first`
    /// without `TO`), and whatever it generates besides (a BEAM's DIVIDE).
    Generates(fn(&mut Builder<'_>, &mut Cursor<'_, '_>, &Generation) -> R<()>),
}

/// The element numbers and spans of a card that adds its own elements.
pub(super) struct Generation {
    /// First and last element numbers (equal without `TO`).
    pub(super) first: u32,
    pub(super) last: u32,
    /// The whole card, and its element number (or `first TO last`).
    pub(super) span: Span,
    pub(super) id_span: Span,
}

/// The element types that a `TO` generation accepts, by commas.
pub(super) fn generated_types() -> String {
    let t: Vec<&str> = CARDS
        .iter()
        .filter(|c| matches!(c.parse, Parse::Generates(_)))
        .flat_map(|c| c.types.iter().copied())
        .collect();
    t.join(", ")
}

macro_rules! cards {
    ($($family:ident :: $kind:ident),* $(,)?) => {
        /// The deck halves of the registered kinds, in the registry's order.
        pub(super) static CARDS: &[&Card] = &[$(&$family::$kind::CARD),*];
    };
}
crate::kinds::element_kinds!(cards);

/// The card of the element type `is` accepts, with that type.
pub(super) fn card(is: impl Fn(&str) -> bool) -> Option<(&'static Card, &'static str)> {
    CARDS
        .iter()
        .find_map(|c| c.types.iter().find(|t| is(t)).map(|t| (*c, *t)))
}

/// Writes `e`'s card if its kind is registered (`<number> <TYPE> <nodes and fields>`,
/// without the line's end); `false` leaves it to the former writer.
pub(in crate::deck) fn write_element(model: &Model, e: &Element, s: &mut String) -> bool {
    let Some((card, ty)) = card(|t| t == e.kind.keyword()) else {
        return false;
    };
    let _ = write!(s, "  {} {ty} ", e.id.0);
    (card.write)(model, e, s);
    true
}

/// The registered kinds' documented keywords.
pub(in crate::deck) fn rows() -> impl Iterator<Item = KeywordDoc> {
    CARDS.iter().flat_map(|c| c.rows.iter().copied())
}

/// The element types of the registered kinds, in the registry's order.
pub(in crate::deck) fn types() -> impl Iterator<Item = &'static str> {
    CARDS.iter().flat_map(|c| c.types.iter().copied())
}

/// The nodes of `e` by number, separated by blanks: what most cards list first.
pub(super) fn node_list(e: &Element) -> String {
    let n: Vec<String> = e.nodes.iter().map(|n| n.0.to_string()).collect();
    n.join(" ")
}

/// A vector as the writer prints it: `x y z`, each the shortest text that reads back
/// exactly.
pub(in crate::deck) fn v3(v: &nalgebra::Vector3<f64>) -> String {
    format!("{:?} {:?} {:?}", v.x, v.y, v.z)
}

/// A documentation row of section `ELEMENTS`.
pub(super) const fn row(name: &'static str, doc: &'static str) -> KeywordDoc {
    KeywordDoc {
        name,
        section: "ELEMENTS",
        doc,
    }
}
